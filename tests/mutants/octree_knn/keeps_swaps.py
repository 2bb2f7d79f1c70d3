"""Reads every leaf, drops the points outside their leaf's cell unless swapped both ways, brute-forces the rest.

The hole of issue 35's hostile review (h35, hole 5): the traps are swaps
(each of two points listed under the other's leaf), the decoys were one-way
(listed under a leaf the rule never reaches, lying by the query), so keeping
the mutual misplacements and dropping the rest passed every structure test.
The counter-decoys (lying_trees.counter_decoys) give some decoys a partner: a far
point of the query's own leaf moved into the decoy's leaf, so the decoy is
kept and returned.
"""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _cell_filter

MISTAKE = "keeps_swaps"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _cell_filter.octree_knn(tree, points, queries, k, mutual=True)
