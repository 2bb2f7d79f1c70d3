"""Descends with q[a] < split instead of <=: a query on a split plane goes to the right child first. Its
answers stay right (both sides are read), but it reads nodes in another order, so nodes the rule does not reach."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_descent"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.kdtree_knn(tree, points, queries, k, descend="<")
