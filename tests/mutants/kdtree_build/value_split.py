"""Splits by value: points below the split go left, the rest right, and a node whose split leaves a side empty
becomes a leaf. With equal coordinates at the median, the halves are unequal; all-equal points make an
oversized leaf (the guard a student adds after the first endless recursion)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "value_split"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, partition="value")
