"""Compares the squared distance with the tolerance itself (s <= tolerance, not tolerance ** 2)."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import euclidean_clusters as _reference
from tests.mutants import _plain_components

MISTAKE = "tolerance_not_squared"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    _reference(points, tolerance, min_size, max_size)  # validation only
    return _plain_components.euclidean_clusters(points, tolerance, min_size, max_size, squared=False)
