"""Normals point by point with a brute-force neighbour search and an SVD; signs flipped."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError("points must be finite")
    if radius is not None and not radius > 0:
        raise ValueError("radius must be positive")
    if k is not None and k < 1:
        raise ValueError("k must be at least 1")
    if viewpoint is not None and np.shape(viewpoint) != (3,):
        raise ValueError("viewpoint must have shape (3,)")
    normals, curvature = np.full((len(p), 3), np.nan), np.full(len(p), np.nan)
    for i in range(len(p)):
        d = np.sqrt(((p - p[i]) ** 2).sum(axis=1))
        order = np.argsort(d, kind="stable")
        if radius is not None:
            order = order[d[order] <= radius]
        if k is not None:
            order = order[:k]
        if len(order) < 3:
            continue
        q = p[order] - p[order].mean(axis=0)
        _, s, vt = np.linalg.svd(q, full_matrices=True)
        s = np.concatenate([s, np.zeros(3 - len(s))])
        normals[i] = -vt[2]
        trace = (s**2).sum()
        curvature[i] = s[2] ** 2 / trace if trace > 0 else 0.0
        if viewpoint is not None and normals[i] @ (np.asarray(viewpoint) - p[i]) < 0:
            normals[i] = -normals[i]
    return normals, curvature
