"""Computes the query's own child code with q >= c instead of q > c: a query on a centre plane starts in the
upper child, not the lower one the build put such points in. Its answers stay right; it reads nodes in
another order than the rule, so nodes the rule does not reach."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "upper_on_plane"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, upper_on_plane=True)
