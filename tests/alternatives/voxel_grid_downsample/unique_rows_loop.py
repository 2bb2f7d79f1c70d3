"""Exact voxel grid with np.unique over (h_z, h_y, h_x) rows, and a per-voxel loop drawing with rng.choice."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] < 3 or not np.isfinite(p).all():
        raise ValueError("points must be a finite (N, D >= 3) array")
    if not (isinstance(voxel_size, (int, float)) and voxel_size > 0):
        raise ValueError("voxel_size must be positive")
    if method not in ("centroid", "random"):
        raise ValueError("method must be 'centroid' or 'random'")
    rng = np.random.default_rng(rng)
    if len(p) == 0:
        return np.empty((0, p.shape[1]))
    h = np.floor((p[:, :3] - p[:, :3].min(axis=0)) / voxel_size).astype(np.int64)
    _, inverse = np.unique(h[:, ::-1], axis=0, return_inverse=True)
    inverse = inverse.ravel()
    rows = []
    for voxel in range(inverse.max() + 1):
        members = np.flatnonzero(inverse == voxel)
        rows.append(p[members].mean(axis=0) if method == "centroid" else p[rng.choice(members)])
    return np.array(rows)
