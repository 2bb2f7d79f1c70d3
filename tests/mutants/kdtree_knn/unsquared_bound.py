"""Visits the far child if |q[axis] - split| <= w2: a distance compared with a squared distance, so it prunes
too much where w2 < 1 (units below a metre) and too little above."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference

MISTAKE = "unsquared_bound"  # the diagnosis this mistake must get (grading/mistakes/)


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
        near, far = (
            (tree["left"][node], tree["right"][node]) if diff <= 0 else (tree["right"][node], tree["left"][node])
        )

        visit(near)
        if abs(diff) <= bound():
            visit(far)

    visit(0)
    return sorted(held)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    points = np.asarray(points, dtype=float)
    rows = [_search(tree, points, q, k, None) for q in np.asarray(queries, dtype=float)]
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    distances = np.sqrt(np.array([[s for s, _ in row] for row in rows], dtype=float).reshape(len(rows), k))
    return indices, distances
