"""Gives the left child n // 2 points instead of ceil(n / 2)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference

MISTAKE = "floor_median"  # the diagnosis this mistake must get (grading/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    points = np.asarray(points, dtype=float)
    nodes, order = [], []

    def grow(indices, depth):
        node = len(nodes)
        nodes.append([len(order), 0, -1, np.nan, -1, -1])
        if len(indices) <= leaf_size:
            order.extend(sorted(indices))
        else:
            axis = depth % points.shape[1]
            ranked = sorted(indices, key=lambda i: (points[i, axis], i))
            m = len(ranked) // 2
            nodes[node][2:4] = [axis, (points[ranked[m - 1], axis] + points[ranked[m], axis]) / 2]
            nodes[node][4] = grow(ranked[:m], depth + 1)
            nodes[node][5] = grow(ranked[m:], depth + 1)
        nodes[node][1] = len(order)
        return node

    grow(list(range(len(points))), 0)
    columns = [np.array(c) for c in zip(*nodes)]
    tree = {"order": np.array(order, dtype=np.int64)}
    for key, column in zip(("start", "stop", "axis", "split", "left", "right"), columns):
        tree[key] = column.astype(np.float64 if key == "split" else np.int64)
    return tree
