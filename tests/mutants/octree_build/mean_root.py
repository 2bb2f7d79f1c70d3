"""Centres the root cube at the mean of the points (the bounding box's half side): a skewed cloud escapes it."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "mean_root"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_build(points, leaf_size=8, min_extent=1e-3):
    _reference(points, leaf_size, min_extent)  # validation only
    return _plain_trees.octree_build(points, leaf_size, min_extent, root="mean")
