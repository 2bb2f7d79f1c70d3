"""The interval-filter cheat of lecture 2's BST search: read every node, drop the keys outside their node's interval.

A node's interval comes from its ancestors' keys (left of a key: below it;
right: at or above it, equal keys go right). On a true tree no key is
dropped; on the structure tests' lying trees every decoy is, which let this
cheat pass before the trap swaps (issue 35). Trusted code: only the
project's tests import it, in the grading process.
"""

import numpy as np

__all__ = ["bst_knn"]


def bst_knn(keys, left, right, query, k):
    keys = np.asarray(keys, dtype=float)
    kept = []
    stack = [(0, -np.inf, np.inf)]
    while stack:
        node, lo, hi = stack.pop()
        if lo <= keys[node] <= hi:
            kept.append(node)
        if left[node] >= 0:
            stack.append((int(left[node]), lo, min(hi, keys[node])))
        if right[node] >= 0:
            stack.append((int(right[node]), max(lo, keys[node]), hi))
    kept = np.array(sorted(kept), dtype=np.int64)
    gaps = np.abs(keys[kept] - query)
    rank = np.lexsort((kept, gaps))[:k]
    return kept[rank], gaps[rank]
