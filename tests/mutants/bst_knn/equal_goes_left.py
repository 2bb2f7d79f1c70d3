"""Descends left when query <= key: a query equal to a node's key goes to the left child first, though
equal keys were inserted to the right. Its answers stay right (both sides are read); it reads nodes in
another order than the rule, so nodes the rule does not reach."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "equal_goes_left"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    return _plain_trees.bst_knn(keys, left, right, query, k, left_if="<=")
