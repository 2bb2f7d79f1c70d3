"""DBSCAN from a cloud's candidate pairs: the contract's neighbours, cores, clusters and borders (numba)."""

import numpy as np
from numba import njit

__all__ = ["density_clusters"]


@njit(cache=True, nogil=True)
def _root(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]  # path halving
        i = parent[i]
    return i


@njit(cache=True, nogil=True)
def density_clusters(points, pairs, eps_squared, min_samples):
    """Labels and cores of DBSCAN, given every pair ``i < j`` that may lie within ``eps``.

    Parameters
    ----------
    points : ndarray of float64, shape (N, D), C-contiguous
    pairs : ndarray of int64, shape (P, 2)
        Candidate pairs (a superset of the neighbours: a k-d tree's, at a
        slightly larger radius); the squared distance summed over the
        columns in increasing order decides (``s <= eps_squared``).
    eps_squared : float
    min_samples : int

    Returns
    -------
    labels : ndarray of int64, shape (N,)
        Clusters numbered by their smallest core index, a border point the
        smallest label among its core neighbours', noise -1.
    is_core : ndarray of bool, shape (N,)
    """
    n, d = points.shape
    near = np.zeros(len(pairs), dtype=np.bool_)
    counts = np.ones(n, dtype=np.int64)  # the point itself
    for p in range(len(pairs)):
        i, j = pairs[p, 0], pairs[p, 1]
        s = 0.0
        for c in range(d):
            difference = points[i, c] - points[j, c]
            s += difference * difference
        if s <= eps_squared:
            near[p] = True
            counts[i] += 1
            counts[j] += 1
    is_core = counts >= min_samples
    # Union-find of the cores, each root its component's smallest index.
    parent = np.arange(n)
    for p in range(len(pairs)):
        i, j = pairs[p, 0], pairs[p, 1]
        if near[p] and is_core[i] and is_core[j]:
            a, b = _root(parent, i), _root(parent, j)
            if a < b:
                parent[b] = a
            elif b < a:
                parent[a] = b
    labels = np.full(n, -1, dtype=np.int64)
    clusters = 0
    for i in range(n):  # in index order: a component's first core is its root, its smallest
        if is_core[i]:
            root = _root(parent, i)
            if root == i:
                labels[i] = clusters
                clusters += 1
            else:
                labels[i] = labels[root]
    border = np.full(n, np.iinfo(np.int64).max, dtype=np.int64)
    for p in range(len(pairs)):
        if near[p]:
            i, j = pairs[p, 0], pairs[p, 1]
            if is_core[i] and not is_core[j]:
                border[j] = min(border[j], labels[i])
            elif is_core[j] and not is_core[i]:
                border[i] = min(border[i], labels[j])
    for i in range(n):
        if not is_core[i] and border[i] != np.iinfo(np.int64).max:
            labels[i] = border[i]
    return labels, is_core
