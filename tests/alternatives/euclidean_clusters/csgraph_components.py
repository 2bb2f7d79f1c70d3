"""SciPy's connected components of a k-d tree's pairs (the contract's distance deciding at the
tolerance), the sizes filtered with np.bincount and the order by np.lexsort."""

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    x = as_points(points, min_columns=1)
    tolerance = check_positive(tolerance, "tolerance")
    min_size = check_integer(min_size, "min_size", low=1)
    if max_size is not None:
        max_size = check_integer(max_size, "max_size", low=min_size)
    n = len(x)
    if n == 0:
        return np.empty(0, dtype=np.int64)
    pairs = cKDTree(x).query_pairs(tolerance * 1.000001, output_type="ndarray").reshape(-1, 2)
    s = ((x[pairs[:, 0]] - x[pairs[:, 1]]) ** 2).sum(axis=1)
    pairs = pairs[s <= tolerance**2]
    graph = coo_array((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    count, component = connected_components(graph, directed=False)
    sizes = np.bincount(component, minlength=count)
    first = np.full(count, n)
    np.minimum.at(first, component, np.arange(n))
    kept = np.flatnonzero((sizes >= min_size) & (sizes <= (n if max_size is None else max_size)))
    ranked = kept[np.lexsort((first[kept], -sizes[kept]))]
    label = np.full(count, -1, dtype=np.int64)
    label[ranked] = np.arange(len(ranked))
    return label[component]
