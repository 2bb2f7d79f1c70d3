"""Unpacks x_max, y_max, z_max = np.amax(points, axis=0): crashes on clouds with extra columns."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import voxel_grid_downsample as _reference

MISTAKE = "extra_columns"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    points = np.asarray(points, dtype=float)
    if len(points):
        x_max, y_max, z_max = np.amax(points, axis=0)
        x_min, y_min, z_min = np.amin(points, axis=0)
    return _reference(points, voxel_size, method, rng)
