"""Splits by value with no guard: points below the split go left, the rest right. On equal coordinates the
lower side is empty and the upper side is the whole node, so the recursion never ends (a real student's first
build: Python stops it at its recursion limit)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "value_split"  # the diagnosis this mistake must get (grading/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, partition="value, unguarded")
