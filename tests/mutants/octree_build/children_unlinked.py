"""Builds every child but never stores its id: the children list is rebound (children = [...]) instead of
filled, so the array written out has -1 everywhere, and the root looks like a leaf of all the points."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_build as _reference

MISTAKE = "children_unlinked"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_build(points, leaf_size=8, min_extent=1e-3):
    _reference(points, leaf_size, min_extent)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    nodes, order = [], []

    def grow(indices, center, extent):
        node = len(nodes)
        children = [-1] * 8
        nodes.append([len(order), 0, center, extent, children])
        if len(indices) <= leaf_size or extent <= min_extent:
            order.extend(sorted(indices))
        else:
            groups = {}
            for i in indices:
                code = sum(1 << j for j in range(3) if xyz[i, j] > center[j])
                groups.setdefault(code, []).append(i)
            for code in sorted(groups):
                signs = np.array([1.0 if code >> j & 1 else -1.0 for j in range(3)])
                child = grow(groups[code], center + signs * extent / 2, extent / 2)
                children = [*children[:code], child, *children[code + 1 :]]  # a new list: the node keeps the old
        nodes[node][1] = len(order)
        return node

    if len(xyz):
        lower, upper = xyz.min(axis=0), xyz.max(axis=0)
        grow(list(range(len(xyz))), (lower + upper) / 2, float(np.max((upper - lower) / 2)))
    else:
        grow([], np.zeros(3), 0.0)
    return {
        "order": np.array(order, dtype=np.int64),
        "start": np.array([n[0] for n in nodes], dtype=np.int64),
        "stop": np.array([n[1] for n in nodes], dtype=np.int64),
        "center": np.array([n[2] for n in nodes], dtype=np.float64).reshape(-1, 3),
        "extent": np.array([n[3] for n in nodes], dtype=np.float64),
        "children": np.array([n[4] for n in nodes], dtype=np.int64).reshape(-1, 8),
    }
