"""Visits the far child if |q[axis] - split| <= w2: a distance compared with a squared distance, so it prunes
too much where w2 < 1 (units below a metre) and too little above."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "unsquared_bound"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.kdtree_knn(tree, points, queries, k, prune="|d| <= w2")
