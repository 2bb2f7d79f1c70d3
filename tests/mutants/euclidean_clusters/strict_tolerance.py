"""Links points only if s < tolerance ** 2 (the contract, like PCL's radius search, is inclusive):
points exactly the tolerance apart fall in different clusters."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import euclidean_clusters as _reference
from tests.mutants import _plain_components

MISTAKE = "strict_tolerance"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    _reference(points, tolerance, min_size, max_size)  # validation only
    return _plain_components.euclidean_clusters(points, tolerance, min_size, max_size, linked="<")
