"""A real student's search (a published homework of the course), in this API: for a query left of a node
(query < key), the branch that should visit the far side visits the left child again, so the right subtree of
such a node is never searched (a copy-and-paste slip)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "near_side_twice"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    return _plain_trees.bst_knn(keys, left, right, query, k, far_when_left="left")
