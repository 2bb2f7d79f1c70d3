"""Links two points when sqrt(s) <= tolerance (a hostile review's submission, h49d): the contract's
rule in exact arithmetic, rounded otherwise for a pair the tolerance apart to the last digit."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import euclidean_clusters as _reference
from tests.mutants import _plain_components

MISTAKE = "root_against_tolerance"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    _reference(points, tolerance, min_size, max_size)  # validation only
    return _plain_components.euclidean_clusters(points, tolerance, min_size, max_size, root=True)
