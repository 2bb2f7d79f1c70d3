"""Radius outlier removal from the full distance matrix."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.filters import *  # noqa: F401,F403


def radius_outlier_removal(points, radius, min_neighbors):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] < 3 or not np.isfinite(p).all():
        raise ValueError("points must be a finite (N, 3) array")
    if not radius > 0:
        raise ValueError("radius must be positive")
    if len(p) == 0:
        return np.zeros(0, dtype=bool)
    near = cdist(p[:, :3], p[:, :3]) <= radius
    np.fill_diagonal(near, False)
    return near.sum(axis=1) >= min_neighbors
