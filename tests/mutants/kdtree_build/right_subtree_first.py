"""Builds (so numbers, and lays out in order) the right subtree before the left: node.right = grow(...)
written above node.left = grow(...). Every node holds the right points; the ids are not in preorder."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "right_subtree_first"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, first="right")
