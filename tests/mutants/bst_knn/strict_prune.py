"""Visits the far side only if |key - query| < w (strict): a tie at the k-th distance is lost."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_prune"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    return _plain_trees.bst_knn(keys, left, right, query, k, prune="<")
