"""Orders a node's points with np.argsort of the coordinate alone, as the course's scaffold does: equal
coordinates end up in whatever order the sort leaves them, not by index (a real students' bug)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference

MISTAKE = "argsort_ties"  # the diagnosis this mistake must get (grading/mistakes/)


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
            ranked = [indices[j] for j in np.argsort(points[indices, axis])]
            m = (len(ranked) + 1) // 2
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
