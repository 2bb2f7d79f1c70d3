"""Reads every node, drops the keys that lie outside their node's interval, and takes the k nearest of the rest.

Exact on a true tree and blind to every decoy of a lying tree, but it reads
every node: the traps (keys swapped between two childless nodes the rule
reads) make it drop an answer.
"""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference
from tests.mutants import _bst_filter

MISTAKE = "filters_by_cell"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    return _bst_filter.bst_knn(keys, left, right, query, k)
