"""Right rows, returned as float32 (a student's array built with dtype=np.float32)."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import approximate_voxel_downsample as _reference

MISTAKE = "dtype"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    return _reference(points, voxel_size, n_containers, method, rng).astype(np.float32)
