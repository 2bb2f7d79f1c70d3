"""Computes the query's own child code from x for all three bits (a copy-and-paste slip): the search starts
in octant 0 or 7, not the query's, so its answers stay right but it reads octants its rule never reaches."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "code_from_x"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, code_from_x=True)
