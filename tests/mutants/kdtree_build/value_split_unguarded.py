"""Splits by value with no guard: points below the split go left, the rest right. Where the lower side is empty
the node gets an empty child and the same points are split again on the next axis; where they agree on every
axis the recursion never ends, and Python stops it at its recursion limit (the build before the guard of
value_split.py)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "value_split"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, partition="value, unguarded")
