"""The homework's result set: k slots of (1e10, 0) to start with, so that the worst distance is 1e10, not
infinity, while fewer than k are held: a query whose k-th neighbour lies beyond 1e10 gets the padding, and
a far side beyond 1e10 is pruned before k neighbours are held."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "finite_sentinel"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.kdtree_knn(tree, points, queries, k, sentinel=1e10**2)  # squared: 1e10 on the distance
