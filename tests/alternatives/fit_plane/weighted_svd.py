"""Plane by the SVD of the sqrt(w)-weighted centred points, normal negated."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403


def fit_plane(points, weights=None):
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3 or not np.isfinite(x).all():
        raise ValueError("points must be a finite (N, 3) array")
    w = np.ones(len(x)) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (len(x),) or (w < 0).any() or not w.sum() > 0:
        raise ValueError("weights must be (N,), non-negative, with a positive sum")
    c = (w[:, None] * x).sum(axis=0) / w.sum()
    _, _, vt = np.linalg.svd(np.sqrt(w)[:, None] * (x - c))
    return c, -vt[-1]
