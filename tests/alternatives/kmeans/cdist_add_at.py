"""Vectorised Lloyd's algorithm: scipy's cdist(..., "sqeuclidean") for the distances, np.add.at for the
sums and np.bincount for the counts and the inertia (other summation orders than the reference's)."""

import numpy as np
from scipy.spatial.distance import cdist

from pcl_course.validation import as_array, as_points, check_integer
from solutions.cluster import *  # noqa: F401,F403


def kmeans(points, init_centers, max_iter=300):
    x = as_points(points, min_columns=1, allow_empty=False)
    c = as_array(init_centers, "init_centers", ndim=2)
    if c.ndim != 2 or c.shape[1] != x.shape[1] or not 1 <= len(c) <= len(x):
        raise ValueError(f"init_centers must be (K, {x.shape[1]}) with 1 <= K <= {len(x)}, got {c.shape}")
    max_iter = check_integer(max_iter, "max_iter", low=1)
    k = len(c)
    centers = np.array(c, dtype=np.float64)  # a copy: the caller's array is never touched
    inertia = np.zeros(max_iter)
    labels, previous, n_iter = None, None, 0
    for it in range(max_iter):
        d = cdist(x, centers, "sqeuclidean")
        labels = d.argmin(axis=1)
        inertia[it] = np.bincount(labels, weights=d[np.arange(len(x)), labels], minlength=k).sum()
        n_iter = it + 1
        if previous is not None and (labels == previous).all():
            break
        sums = np.zeros_like(centers)
        np.add.at(sums, labels, x)
        counts = np.bincount(labels, minlength=k)
        has = counts > 0
        centers[has] = sums[has] / counts[has][:, None]
        previous = labels
    else:
        labels = cdist(x, centers, "sqeuclidean").argmin(axis=1)
    return labels.astype(np.int64), centers, inertia[:n_iter].copy(), n_iter
