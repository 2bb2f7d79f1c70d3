"""k-means++ with rng.choice(N, p=w / w.sum()), the draw the contract names as equivalent."""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_rng
from solutions.cluster import *  # noqa: F401,F403


def kmeans_plusplus(points, n_clusters, rng=None):
    x = as_points(points, min_columns=1, allow_empty=False)
    n_clusters = check_integer(n_clusters, "n_clusters", low=1, high=len(np.unique(x, axis=0)))
    rng = check_rng(rng)
    n = len(x)
    chosen = [int(rng.integers(n))]
    w = np.zeros(n)
    for j in range(x.shape[1]):
        w += (x[:, j] - x[chosen[0], j]) ** 2
    while len(chosen) < n_clusters:
        chosen.append(int(rng.choice(n, p=w / w.sum())))
        s = np.zeros(n)
        for j in range(x.shape[1]):
            s += (x[:, j] - x[chosen[-1], j]) ** 2
        w = np.minimum(w, s)
    return np.array(chosen, dtype=np.int64)
