"""k-means started from the first n_clusters rows of Y, not farthest first. No diagnosis is promised:
where two of the first rows lie in one cluster, the rows of Y there nearly coincide and rounding (the
eigensolver's basis) decides how k-means splits it, so no replay predicts this code's labels."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = None  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    return _plain_spectral.spectral_clustering(points, n_clusters, k, sigma, start="first")
