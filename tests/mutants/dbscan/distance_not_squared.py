"""Compares the squared distances with eps, not eps ** 2 (forgot to square eps). Vectorised: the full
matrix of squared distances, scipy's connected components of the core graph."""

import numpy as np
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "distance_not_squared"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    if n == 0:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=bool)
    s = np.zeros((n, n))
    for j in range(x.shape[1]):
        s += (x[:, None, j] - x[None, :, j]) ** 2
    adjacent = s <= eps
    is_core = adjacent.sum(axis=1) >= min_samples
    graph = csr_array(adjacent & is_core[:, None] & is_core[None, :])
    _, component = connected_components(graph, directed=False)
    labels = np.full(n, -1, dtype=np.int64)
    cores = np.flatnonzero(is_core)
    # components in the order of their first core
    _, first = np.unique(component[cores], return_index=True)
    rank = {c: r for r, c in enumerate(component[cores][np.sort(first)])}
    labels[cores] = [rank[c] for c in component[cores]]
    for p in np.flatnonzero(~is_core):
        near = np.flatnonzero(adjacent[p] & is_core)
        if len(near):
            labels[p] = labels[near].min()
    return labels, is_core
