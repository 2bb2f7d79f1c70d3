"""The embedding of L = D - W (unnormalised spectral clustering), not of L_sym."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "unnormalised_laplacian"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    return _plain_spectral.spectral_clustering(points, n_clusters, k, sigma, normalized=False)
