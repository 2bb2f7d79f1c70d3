"""Union-find over the core points, then each core writes its cluster over all its neighbours, the cores
in index order: a border touching several clusters keeps the one written last (of its highest core
neighbour), not the smallest label."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "border_last_cluster"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    neighbours = []
    for i in range(n):
        s = np.zeros(n)
        for j in range(x.shape[1]):
            s += (x[:, j] - x[i, j]) ** 2
        neighbours.append(np.flatnonzero(s <= eps * eps))
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool)
    parent = list(range(n))
    for i in np.flatnonzero(is_core):
        for q in neighbours[i]:
            if is_core[q]:
                a, b = _find(parent, i), _find(parent, q)
                parent[max(a, b)] = min(a, b)  # the root is the smallest core
    labels = np.full(n, -1, dtype=np.int64)
    roots = sorted({_find(parent, i) for i in np.flatnonzero(is_core)})
    number = {r: k for k, r in enumerate(roots)}
    for i in np.flatnonzero(is_core):
        labels[neighbours[i]] = number[_find(parent, i)]  # overwrites a border reached before
    return labels, is_core
