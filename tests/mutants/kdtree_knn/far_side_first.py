"""Searches the far child first, then the near one (if the plane test allows)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "far_side_first"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.kdtree_knn(tree, points, queries, k, far_first=True)
