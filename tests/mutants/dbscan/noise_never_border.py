"""The textbook's pseudo-code with one visited flag: a point found not core when the loop reaches it is
marked visited as noise, and a cluster reached later skips it (it only takes unvisited points), so a
border point with a lower index than its cluster's first core stays noise."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "noise_never_border"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _region_query(x, i, eps):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - x[i, j]) ** 2
    return list(np.flatnonzero(s <= eps * eps))


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    visited = np.zeros(n, dtype=bool)
    is_core = np.zeros(n, dtype=bool)
    labels = np.full(n, -1, dtype=np.int64)
    c = -1
    for p in range(n):
        if visited[p]:
            continue
        visited[p] = True
        seeds = _region_query(x, p, eps)
        if len(seeds) < min_samples:
            continue  # noise
        is_core[p] = True
        c += 1
        labels[p] = c
        k = 0
        while k < len(seeds):
            q = seeds[k]
            k += 1
            if visited[q]:
                continue
            visited[q] = True
            labels[q] = c
            found = _region_query(x, q, eps)
            if len(found) >= min_samples:
                is_core[q] = True
                seeds += found
    return labels, is_core
