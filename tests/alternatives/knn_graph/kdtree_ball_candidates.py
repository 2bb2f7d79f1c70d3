"""The kNN graph with SciPy: a k-d tree's k + 1 nearest give each point a radius, a ball query at
slightly more than it every candidate (ties at the k-th distance included), re-ranked by the
contract's squared distance and index; the links made symmetric with sparse matrices."""

import numpy as np
from scipy.sparse import coo_array
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_bool, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def knn_graph(points, k, sigma=None, mutual=False):
    x = as_points(points, min_columns=1, allow_empty=False)
    n = len(x)
    if n < 2:
        raise ValueError("points must hold at least 2 points")
    k = check_integer(k, "k", low=1, high=n - 1)
    sigma = None if sigma is None else check_positive(sigma, "sigma")
    mutual = check_bool(mutual, "mutual")
    tree = cKDTree(x)
    reach, _ = tree.query(x, k + 1)
    heads, tails = [], []
    for i, candidates in enumerate(tree.query_ball_point(x, reach[:, -1] * (1 + 1e-9) + 1e-300)):
        candidates = np.array([j for j in candidates if j != i], dtype=np.int64)
        s = np.zeros(len(candidates))
        for c in range(x.shape[1]):
            s += (x[candidates, c] - x[i, c]) ** 2
        nearest = candidates[np.lexsort((candidates, s))[:k]]
        heads += [i] * k
        tails += nearest.tolist()
    one_way = coo_array((np.ones(len(heads)), (heads, tails)), shape=(n, n)).tocsr()
    both = one_way.multiply(one_way.T) if mutual else one_way + one_way.T
    both = both.tocsr()
    both.sort_indices()
    indptr, indices = both.indptr.astype(np.int64), both.indices.astype(np.int64)
    rows = np.repeat(np.arange(n), np.diff(indptr))
    if sigma is None:
        return indptr, indices, np.ones(len(indices))
    s = np.zeros(len(indices))
    for c in range(x.shape[1]):
        s += (x[rows, c] - x[indices, c]) ** 2
    return indptr, indices, np.exp(-0.5 * s / sigma**2)
