"""Drops the point itself from its neighbourhood by distance (0 < s <= eps ** 2): its duplicates go too,
so a point with duplicates counts fewer neighbours than the contract's. Vectorised rows, a queue per
cluster."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "excludes_duplicates"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    neighbours = []
    for i in range(n):
        s = np.zeros(n)
        for j in range(x.shape[1]):
            s += (x[:, j] - x[i, j]) ** 2
        neighbours.append(np.flatnonzero((s > 0) & (s <= eps**2)))  # not itself
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool).reshape(n)
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for i in range(n):
        if labels[i] != -1 or not is_core[i]:
            continue
        labels[i] = cluster
        queue, head = [i], 0
        while head < len(queue):
            p = queue[head]
            head += 1
            for q in neighbours[p]:
                if labels[q] == -1:
                    labels[q] = cluster
                    if is_core[q]:
                        queue.append(q)
        cluster += 1
    return labels, is_core
