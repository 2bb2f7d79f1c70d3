"""Recursive build with boolean masks per child (NumPy), children collected in code order."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_build as _reference


def octree_build(points, leaf_size=8, min_extent=1e-3):
    _reference(points, leaf_size, min_extent)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = []  # [start, stop, center, extent, children]
    order = []

    def build(indices, center, extent):
        node = len(rows)
        rows.append([len(order), 0, center, extent, np.full(8, -1, dtype=np.int64)])
        if len(indices) <= leaf_size or extent <= min_extent:
            order.extend(np.sort(indices).tolist())
        else:
            above = xyz[indices] > center
            codes = above[:, 0] * 1 + above[:, 1] * 2 + above[:, 2] * 4
            for code in range(8):
                members = indices[codes == code]
                if len(members):
                    offset = np.where([(code >> j) & 1 for j in range(3)], 0.5, -0.5) * extent
                    rows[node][4][code] = build(members, center + offset, extent / 2)
        rows[node][1] = len(order)
        return node

    if len(xyz):
        low, high = xyz.min(axis=0), xyz.max(axis=0)
        build(np.arange(len(xyz)), (low + high) / 2, float(((high - low) / 2).max()))
    else:
        build(np.arange(0), np.zeros(3), 0.0)
    return {
        "order": np.array(order, dtype=np.int64),
        "start": np.array([r[0] for r in rows], dtype=np.int64),
        "stop": np.array([r[1] for r in rows], dtype=np.int64),
        "center": np.array([r[2] for r in rows], dtype=np.float64).reshape(-1, 3),
        "extent": np.array([r[3] for r in rows], dtype=np.float64),
        "children": np.array([r[4] for r in rows], dtype=np.int64).reshape(-1, 8),
    }
