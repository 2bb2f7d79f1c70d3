"""A plain DBSCAN for the lecture-3 mutants that differ in the border rule only.

The cores' components by a depth-first search over brute-force neighbourhoods,
then each border point labelled from its core neighbours, apart from the
grader's catalogue (``grading/instructors/mistakes/_density.py``): a mutant
and its diagnosis are two independent codings of one mistake. The other
DBSCAN mutants are written each in its own style, as students write them.
Trusted code: only the project's tests import it.
"""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_positive

__all__ = ["dbscan"]


def _squared(x, i):
    """The squared distances from point ``i`` to every point, summed over every column."""
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - x[i, j]) ** 2
    return s


def dbscan(points, eps, min_samples, *, border="smallest"):
    """The contract's DBSCAN with the border rule ``border``: ``"smallest"`` (the contract's: the
    smallest label among the core neighbours' clusters), ``"lowest_core"`` (the cluster of the
    lowest-index core neighbour) or ``"nearest_core"`` (the cluster of the nearest one)."""
    x = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    n = len(x)
    neighbours = [np.flatnonzero(_squared(x, i) <= eps * eps) for i in range(n)]
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool).reshape(n)
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for seed in np.flatnonzero(is_core):
        if labels[seed] >= 0:
            continue
        labels[seed] = cluster
        stack = [seed]
        while stack:
            p = stack.pop()
            for q in neighbours[p]:
                if is_core[q] and labels[q] < 0:
                    labels[q] = cluster
                    stack.append(q)
        cluster += 1
    for p in np.flatnonzero(~is_core):
        cores = neighbours[p][is_core[neighbours[p]]]
        if not len(cores):
            continue
        if border == "lowest_core":
            labels[p] = labels[cores[0]]
        elif border == "nearest_core":
            labels[p] = labels[cores[np.argmin(_squared(x, p)[cores])]]
        else:
            labels[p] = labels[cores].min()
    return labels, is_core
