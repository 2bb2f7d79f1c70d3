"""Tests each axis alone (|q_j - c_j| <= e + r): the ball's bounding box, a weaker test than the cube's distance."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "box_overlap"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.octree_radius(tree, points, queries, radius, box=True)
