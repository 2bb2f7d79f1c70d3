"""The contains shortcut reports a contained octant's points at distance r (the ball's radius), not at
their own distances: the right neighbours, with wrong distances and so in the wrong order."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "contained_at_radius"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.octree_radius(tree, points, queries, radius, contained_at_radius=True)
