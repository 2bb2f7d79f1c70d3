"""Visits both children of every node (no pruning): right answers on true trees, but it reads every leaf."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference

MISTAKE = "reads_unreached"  # the diagnosis this mistake must get (grading/mistakes/)


def _search(tree, points, query, k, radius):
    held = []  # (squared distance, index), sorted

    def bound():
        if k is None:
            return radius**2
        return held[-1][0] if len(held) == k else np.inf

    def visit(node):
        nonlocal held
        if tree["axis"][node] < 0:
            for index in tree["order"][tree["start"][node] : tree["stop"][node]]:
                s = float(np.sum((points[index] - query) ** 2))
                if k is not None:
                    held = sorted([*held, (s, int(index))])[:k]
                elif s <= radius**2:
                    held.append((s, int(index)))
            return
        diff = query[tree["axis"][node]] - tree["split"][node]
        near, far = (
            (tree["left"][node], tree["right"][node]) if diff <= 0 else (tree["right"][node], tree["left"][node])
        )

        visit(near)
        if True:
            visit(far)

    visit(0)
    return sorted(held)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    points = np.asarray(points, dtype=float)
    rows = [_search(tree, points, q, None, radius) for q in np.asarray(queries, dtype=float)]
    indptr = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    indices = np.array([i for row in rows for _, i in row], dtype=np.int64)
    distances = np.sqrt(np.array([s for row in rows for s, _ in row], dtype=float))
    return indptr, indices, distances
