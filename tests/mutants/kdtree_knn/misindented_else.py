"""A real student's search (a published homework of the course), in this API: after the left child of a
query left of the split, an outer if/else visits the right child either way, and the left child of a query
right of the split is never visited. Wrong answers, and leaves the rule never reaches."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference

MISTAKE = "misindented_else"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


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
                elif True:
                    held.append((s, int(index)))
            return
        diff = query[tree["axis"][node]] - tree["split"][node]
        if diff <= 0:
            visit(tree["left"][node])
        if diff * diff < bound():
            visit(tree["right"][node])
        else:
            visit(tree["right"][node])
            if diff * diff < bound():
                visit(tree["left"][node])

    visit(0)
    return sorted(held)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    points = np.asarray(points, dtype=float)
    rows = [_search(tree, points, q, k, None) for q in np.asarray(queries, dtype=float)]
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    distances = np.sqrt(np.array([[s for s, _ in row] for row in rows], dtype=float).reshape(len(rows), k))
    return indices, distances
