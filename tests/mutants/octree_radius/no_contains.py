"""Always descends, never reports a contained octant whole (no contains shortcut)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "no_contains"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.octree_radius(tree, points, queries, radius, contains=False)
