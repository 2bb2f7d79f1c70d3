"""Gives a border point the cluster of its lowest-index core neighbour (a hostile review's
submission, h49d), where the contract gives it the smallest label among its core neighbours' clusters:
clusters are numbered by their smallest core, which need not be that neighbour."""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403

MISTAKE = "border_lowest_core"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _squared(x, i):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - x[i, j]) ** 2
    return s


def dbscan(points, eps, min_samples):
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
        nb = neighbours[p][is_core[neighbours[p]]]
        if len(nb):
            labels[p] = labels[nb[0]]
    return labels, is_core
