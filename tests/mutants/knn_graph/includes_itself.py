"""A point counted among its own neighbours (a k-d tree query of k returns the point itself first):
each point keeps k - 1 others."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "includes_itself"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    return _plain_spectral.knn_graph(points, k, sigma, mutual, itself=True)
