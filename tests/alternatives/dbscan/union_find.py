"""DBSCAN by union-find: the core points joined along every core-core neighbour pair (brute-force
squared distances, a row at a time), the sets numbered by their smallest core, then each border given
the smallest label among its core neighbours."""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def dbscan(points, eps, min_samples):
    x = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    n = len(x)
    neighbours = []
    for i in range(n):
        s = np.zeros(n)
        for j in range(x.shape[1]):
            s += (x[:, j] - x[i, j]) ** 2
        neighbours.append(np.flatnonzero(s <= eps * eps))
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool).reshape(n)
    parent = np.arange(n)

    def find(i):
        root = i
        while parent[root] != root:
            root = parent[root]
        while parent[i] != root:  # path compression
            parent[i], i = root, parent[i]
        return root

    for i in np.flatnonzero(is_core):
        for q in neighbours[i]:
            if is_core[q]:
                a, b = find(i), find(q)
                if a != b:
                    parent[max(a, b)] = min(a, b)  # every root is its set's smallest index
    labels = np.full(n, -1, dtype=np.int64)
    roots = np.array([find(i) for i in range(n)], dtype=np.int64)
    core_roots = np.unique(roots[is_core])  # sorted: the smallest core of each cluster, increasing
    labels[is_core] = np.searchsorted(core_roots, roots[is_core])
    for p in np.flatnonzero(~is_core):
        near = neighbours[p][is_core[neighbours[p]]]
        if len(near):
            labels[p] = labels[near].min()
    return labels, is_core
