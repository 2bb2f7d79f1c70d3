"""Visits the children in plain code order, not the query's own child first."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "code_order_only"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, own_first=False)
