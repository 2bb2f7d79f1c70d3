"""Takes a neighbour only strictly within eps (s < eps ** 2, Open3D's rule): two points exactly eps apart
are not neighbours. A queue per cluster, the neighbourhoods by brute force."""

from collections import deque

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "strict_eps"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _region(x, i, eps):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - x[i, j]) ** 2
    return np.flatnonzero(s < eps**2)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    neighbours = [_region(x, i, eps) for i in range(n)]
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool)
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for i in range(n):
        if labels[i] != -1 or not is_core[i]:
            continue
        labels[i] = cluster
        queue = deque([i])
        while queue:
            p = queue.popleft()
            for q in neighbours[p]:
                if labels[q] == -1:
                    labels[q] = cluster
                    if is_core[q]:
                        queue.append(q)
        cluster += 1
    return labels, is_core
