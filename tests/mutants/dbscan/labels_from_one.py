"""The textbook's pseudo-code with C = 0 and C += 1 before each new cluster: the clusters are numbered
1, 2, ... (noise -1)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "labels_from_one"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    s = np.zeros((n, n))
    for j in range(x.shape[1]):
        s += (x[:, None, j] - x[None, :, j]) ** 2
    neighbours = [np.flatnonzero(row <= eps**2) for row in s]
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool)
    labels = np.full(n, -1, dtype=np.int64)
    c = 0
    for p in range(n):
        if labels[p] != -1 or not is_core[p]:
            continue
        c += 1
        labels[p] = c
        seeds = list(neighbours[p])
        while seeds:
            q = seeds.pop()
            if labels[q] != -1:
                continue
            labels[q] = c
            if is_core[q]:
                seeds.extend(neighbours[q])
    return labels, is_core
