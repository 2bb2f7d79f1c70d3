"""Row i holds only i's own k neighbours: the graph is left directed, W not symmetric."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "not_symmetric"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    return _plain_spectral.knn_graph(points, k, sigma, mutual, directed=True)
