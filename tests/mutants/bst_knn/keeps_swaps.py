"""Reads every node, drops the keys outside their node's interval unless swapped both ways, takes the k nearest.

The BST's form of issue 35's hostile review (hole 5): the traps are swaps
(each of two keys in the other's interval), the decoys were one-way, so
keeping the mutual misplacements and dropping the rest passed every
structure test. The counter-decoys (lying_keys.bst_own_swap) give a decoy a
partner: the node where the query's descent ends takes the decoy's node's
key, so the decoy is kept and returned.
"""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference
from tests.mutants import _bst_filter

MISTAKE = "keeps_swaps"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    return _bst_filter.bst_knn(keys, left, right, query, k, mutual=True)
