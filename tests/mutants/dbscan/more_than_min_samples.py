"""Makes p core only if MORE than min_samples points lie within eps (> instead of >=). Vectorised
neighbourhood counts, then a breadth-first search per cluster."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "min_samples_off_by_one"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    s = np.zeros((n, n))
    for j in range(x.shape[1]):
        s += np.subtract.outer(x[:, j], x[:, j]) ** 2
    adjacent = s <= eps**2
    is_core = adjacent.sum(axis=1) > min_samples
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for i in np.flatnonzero(is_core):
        if labels[i] != -1:
            continue
        labels[i] = cluster
        frontier = np.array([i])
        while len(frontier):
            reached = np.flatnonzero(adjacent[frontier].any(axis=0) & (labels == -1))
            labels[reached] = cluster
            frontier = reached[is_core[reached]]
        cluster += 1
    return labels, is_core
