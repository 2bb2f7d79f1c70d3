"""k-means' own numbers (the order of the starting rows), not renumbered by first appearance."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "not_renumbered"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    return _plain_spectral.spectral_clustering(points, n_clusters, k, sigma, renumber=False)
