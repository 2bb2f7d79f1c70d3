"""Visits the far child only if (q[axis] - split) ** 2 < w2 (strict): a tie across a split is lost."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_prune"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.kdtree_knn(tree, points, queries, k, prune="<")
