"""Sends a point on a centre plane to the upper child (x >= cx)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "upper_on_plane"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_build(points, leaf_size=8, min_extent=1e-3):
    _reference(points, leaf_size, min_extent)  # validation only
    return _plain_trees.octree_build(points, leaf_size, min_extent, on_plane="upper")
