"""A recursive search in a worker thread with a large stack and recursion limit (deep paths included)."""

import sys
import threading

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference


def _search(keys, left, right, query, k):
    held = []

    def visit(node):
        gap = abs(keys[node] - query)
        held.append((gap, node))
        held.sort()
        del held[k:]
        near, far = (left[node], right[node]) if query < keys[node] else (right[node], left[node])
        if near >= 0:
            visit(near)
        w = held[-1][0] if len(held) == k else np.inf
        if far >= 0 and gap <= w:
            visit(far)

    visit(0)
    return held


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    keys = np.asarray(keys, dtype=float)
    result = []
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 3 * len(keys) + 100))
    threading.stack_size(256 * 1024 * 1024)
    try:
        worker = threading.Thread(target=lambda: result.extend(_search(keys, left, right, query, k)))
        worker.start()
        worker.join()
    finally:
        threading.stack_size(0)
        sys.setrecursionlimit(limit)
    return np.array([i for _, i in result], dtype=np.int64), np.array([g for g, _ in result], dtype=float)
