"""A real student's search (a published homework of the course), in this API: for a query left of a node
(query < key), the branch that should visit the far side visits the left child again, so the right subtree of
such a node is never searched. A copy-and-paste slip with no one-line fix to name: the rows show it."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference

MISTAKE = None  # wrong rows, told by the tests themselves


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
        far = left[node]  # the slip: right[node] when go_left
        if far >= 0 and gap <= worst() and not go_left:
            stack.append((far, False))
    # Visiting the left child twice adds nothing new to a set of (gap, index); left out, it ends the same.
    return np.array([i for _, i in held], dtype=np.int64), np.array([g for g, _ in held])
