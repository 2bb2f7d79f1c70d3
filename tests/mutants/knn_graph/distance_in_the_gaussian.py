"""The weight exp(-d / (2 sigma ** 2)) with d the distance, not its square."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "distance_not_squared"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    return _plain_spectral.knn_graph(points, k, sigma, mutual, weight="distance")
