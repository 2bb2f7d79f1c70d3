"""Takes (points, method, voxel_size, rng): the contract's voxel_size comes second."""

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import voxel_grid_downsample as _reference

MISTAKE = "signature"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def voxel_grid_downsample(points, method="centroid", voxel_size=0.1, rng=None):
    return _reference(points, voxel_size, method, rng)
