"""Measures a point's distance over every column of the cloud, not its xyz: an intensity in the fourth column
counts as a coordinate. Right on (N, 3) clouds; on wider ones it returns the wrong neighbours."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "every_column"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, every_column=True)
