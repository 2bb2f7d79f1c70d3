"""Builds every child but never stores its id: the children list is rebound (children = [...]) instead of
filled, so the array written out has -1 everywhere, and the root looks like a leaf of all the points."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "children_unlinked"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_build(points, leaf_size=8, min_extent=1e-3):
    _reference(points, leaf_size, min_extent)  # validation only
    return _plain_trees.octree_build(points, leaf_size, min_extent, linked=False)
