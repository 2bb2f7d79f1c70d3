"""method='random' always takes the voxel's first point."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import voxel_grid_downsample as _reference

MISTAKE = "random_first_point"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    _reference(points, voxel_size, method, rng)  # validation (and the empty case) only
    p = np.asarray(points, dtype=float)
    if len(p) == 0:
        return np.empty((0, p.shape[1]))
    rng = np.random.default_rng(rng)
    lower = p[:, :3].min(axis=0)
    h = np.floor((p[:, :3] - lower) / voxel_size).astype(np.int64)
    dims = np.floor((p[:, :3].max(axis=0) - lower) / voxel_size).astype(np.int64) + 1
    index = h[:, 0] + h[:, 1] * dims[0] + h[:, 2] * dims[0] * dims[1]
    voxels, inverse, counts = np.unique(index, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    out = np.zeros((len(voxels), p.shape[1]))
    if method == "centroid":
        np.add.at(out, inverse, p)
        return out / counts[:, None]
    order = np.argsort(inverse, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return p[order[starts]]
