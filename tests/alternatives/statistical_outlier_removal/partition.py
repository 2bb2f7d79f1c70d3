"""Statistical outlier removal with np.partition on the full distance matrix."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.filters import *  # noqa: F401,F403


def statistical_outlier_removal(points, k, std_ratio):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] < 3 or not np.isfinite(p).all():
        raise ValueError("points must be a finite (N, 3) array")
    if not 1 <= k <= len(p) - 1:
        raise ValueError(f"k must be between 1 and {len(p) - 1}")
    d = cdist(p[:, :3], p[:, :3])
    np.fill_diagonal(d, np.inf)
    mean_d = np.partition(d, k - 1, axis=1)[:, :k].mean(axis=1)
    mu, sigma = mean_d.mean(), np.sqrt(np.sum((mean_d - mean_d.mean()) ** 2) / (len(p) - 1))
    return mean_d <= mu + std_ratio * sigma
