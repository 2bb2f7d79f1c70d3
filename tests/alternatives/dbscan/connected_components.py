"""DBSCAN with SciPy: candidate pairs from a k-d tree's sparse distance matrix (a slightly larger
radius), kept by the contract's squared distance, the core graph's connected components
(scipy.sparse.csgraph), renumbered by their smallest core; borders by a vectorised minimum."""

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def dbscan(points, eps, min_samples):
    x = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    n = len(x)
    labels = np.full(n, -1, dtype=np.int64)
    if n == 0:
        return labels, np.zeros(0, dtype=bool)
    tree = cKDTree(x)
    candidates = tree.sparse_distance_matrix(tree, eps * (1 + 1e-9), output_type="ndarray")
    i, k = candidates["i"].astype(np.int64), candidates["j"].astype(np.int64)
    s = np.zeros(len(i))
    for j in range(x.shape[1]):
        s += (x[i, j] - x[k, j]) ** 2
    keep = s <= eps * eps
    i, k = i[keep], k[keep]
    is_core = np.bincount(i, minlength=n) >= min_samples  # the "ndarray" output lists (p, p) too
    both = is_core[i] & is_core[k]
    graph = coo_array((np.ones(int(both.sum())), (i[both], k[both])), shape=(n, n))
    _, component = connected_components(graph, directed=False)
    cores = np.flatnonzero(is_core)
    first = np.full(n, n)
    np.minimum.at(first, component[cores], cores)
    ranked = np.argsort(first, kind="stable")
    number = np.empty(n, dtype=np.int64)
    number[ranked] = np.arange(n)
    labels[cores] = number[component[cores]]
    reach = is_core[k] & ~is_core[i]
    best = np.full(n, n, dtype=np.int64)
    np.minimum.at(best, i[reach], labels[k[reach]])
    labels[best < n] = best[best < n]
    return labels, is_core
