"""k-means++ drawing the target with rng.uniform(0, total) (the same single draw as rng.random() * total),
the nearest distances from one (N, K) matrix of the chosen points."""

import numpy as np
from scipy.spatial.distance import cdist

from pcl_course.validation import as_points, check_integer, check_rng
from solutions.cluster import *  # noqa: F401,F403


def kmeans_plusplus(points, n_clusters, rng=None):
    x = as_points(points, min_columns=1, allow_empty=False)
    n_clusters = check_integer(n_clusters, "n_clusters", low=1)
    if n_clusters > len(np.unique(x, axis=0)):
        raise ValueError("n_clusters exceeds the number of distinct points")
    rng = check_rng(rng)
    chosen = [int(rng.integers(len(x)))]
    for _ in range(n_clusters - 1):
        w = cdist(x, x[chosen], "sqeuclidean").min(axis=1)
        cum = np.cumsum(w)
        chosen.append(int(np.flatnonzero(cum > rng.uniform(0.0, cum[-1]))[0]))
    return np.array(chosen, dtype=np.int64)
