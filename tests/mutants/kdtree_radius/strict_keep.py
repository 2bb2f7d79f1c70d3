"""Prunes with the inclusive test but keeps a point only if s < radius ** 2 (the open ball): the points at exactly
the radius are lost."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_radius"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.kdtree_radius(tree, points, queries, radius, prune="<=", keep="<")
