"""A leaf's scan keeps a point only if 0 < s <= radius ** 2 (written to skip "the query itself"): the
query's duplicates in a leaf are lost (a contained octant's points are still reported untested)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "drops_zero"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.octree_radius(tree, points, queries, radius, drop_zero=True)
