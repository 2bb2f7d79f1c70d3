"""Keeps the course scaffold's overlap test, distance to the cube < r (strict): a point on a centre
plane lies on the lower octant's face, and at exactly r from a query across it that octant is skipped."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_overlap"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, strict=True)
