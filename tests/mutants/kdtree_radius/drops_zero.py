"""Keeps a point only if 0 < s <= radius ** 2 (written to skip "the query itself"): the query's
duplicates, and a query that is one of the points, lose the neighbours at distance 0."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "drops_zero"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.kdtree_radius(tree, points, queries, radius, keep="0 < s <=")
