"""The weight exp(-s / (2 sigma)): sigma not squared."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "sigma_not_squared"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    return _plain_spectral.knn_graph(points, k, sigma, mutual, weight="sigma")
