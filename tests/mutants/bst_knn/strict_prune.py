"""Visits the far side only if |key - query| < w (strict): a tie at the k-th distance is lost."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference

MISTAKE = "strict_prune"  # the diagnosis this mistake must get (grading/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    keys = np.asarray(keys, dtype=float)
    held = []  # (gap, index), sorted

    def worst():
        return held[-1][0] if len(held) == k else np.inf

    stack = [(0, False)]
    while stack:
        node, near_done = stack.pop()
        gap = abs(keys[node] - query)
        go_left = query < keys[node]
        if not near_done:
            held = sorted([*held, (gap, node)])[:k]
            stack.append((node, True))
            near = left[node] if go_left else right[node]
            if near >= 0:
                stack.append((near, False))
            continue
        far = right[node] if go_left else left[node]
        if far >= 0 and gap < worst():
            stack.append((far, False))
    return np.array([i for _, i in held], dtype=np.int64), np.array([g for g, _ in held])
