"""Gives the left child n // 2 points instead of ceil(n / 2)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "floor_median"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, median="floor")
