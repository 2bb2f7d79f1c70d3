"""Splits by value: points below the split go left, the rest right, and a node whose split leaves a side empty
becomes a leaf. With equal coordinates at the median, the halves are unequal; all-equal points make an
oversized leaf (the guard a student adds after the first endless recursion)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference

MISTAKE = "value_split"  # the diagnosis this mistake must get (grading/mistakes/)


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
            m = (len(ranked) + 1) // 2
            split = (points[ranked[m - 1], axis] + points[ranked[m], axis]) / 2
            lower = [i for i in ranked if points[i, axis] < split]
            upper = [i for i in ranked if points[i, axis] >= split]
            if not lower or not upper:
                order.extend(sorted(indices))
            else:
                nodes[node][2:4] = [axis, split]
                nodes[node][4] = grow(lower, depth + 1)
                nodes[node][5] = grow(upper, depth + 1)
        nodes[node][1] = len(order)
        return node

    grow(list(range(len(points))), 0)
    columns = [np.array(c) for c in zip(*nodes)]
    tree = {"order": np.array(order, dtype=np.int64)}
    for key, column in zip(("start", "stop", "axis", "split", "left", "right"), columns):
        tree[key] = column.astype(np.float64 if key == "split" else np.int64)
    return tree
