"""A cube's squared distance to the query as sum_j (|q_j - c_j| - e) ** 2, each axis's gap not clamped at 0
(max(..., 0) left out): an axis on which the query lies within the cube adds to the distance, so octants
that hold neighbours are skipped."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_knn as _reference
from tests.mutants import _plain_trees

MISTAKE = "unclamped_gap"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    return _plain_trees.octree_knn(tree, points, queries, k, unclamped=True)
