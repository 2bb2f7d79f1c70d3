"""Numbers the clusters with numpy's default argsort of the negated sizes (a hostile review's
submission, h49d): not stable, so equal sizes are not ordered by their smallest index."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import euclidean_clusters as _reference
from tests.mutants import _plain_components

MISTAKE = "size_ties_unordered"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    _reference(points, tolerance, min_size, max_size)  # validation only
    return _plain_components.euclidean_clusters(points, tolerance, min_size, max_size, order="argsort")
