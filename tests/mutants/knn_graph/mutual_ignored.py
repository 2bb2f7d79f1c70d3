"""The union of the two directions whatever ``mutual``: mutual=True links one-way neighbours too."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "mutual_ignored"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    return _plain_spectral.knn_graph(points, k, sigma, mutual, mutual_rule=False)
