"""Point bilateral filter point by point, with a brute-force neighbour search."""

import numpy as np

from solutions.filters import *  # noqa: F401,F403


def bilateral_filter_points(points, normals, radius, sigma_s, sigma_r):
    p, n = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    if p.shape != n.shape or p.ndim != 2 or p.shape[1] != 3:
        raise ValueError("points and normals must be (N, 3) arrays of one shape")
    out = p.copy()
    for i in range(len(p)):
        offsets = p - p[i]
        t = np.sqrt((offsets**2).sum(axis=1))
        near = t <= radius
        h = offsets[near] @ n[i]
        w = np.exp(-(t[near] ** 2) / (2 * sigma_s**2) - h**2 / (2 * sigma_r**2))
        out[i] = p[i] + n[i] * (w * h).sum() / w.sum()
    return out
