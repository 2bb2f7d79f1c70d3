"""Splits on the axis of largest spread (Friedman, Bentley and Finkel) instead of depth % D."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "axis_by_spread"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, axis_rule="spread")
