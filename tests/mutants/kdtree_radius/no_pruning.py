"""Visits both children of every node (no pruning): right answers on true trees, but it reads every leaf."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "reads_unreached"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.kdtree_radius(tree, points, queries, radius, prune="none")
