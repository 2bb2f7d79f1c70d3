"""k-means on U itself: the rows are not put on the unit sphere."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "rows_not_normalised"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    return _plain_spectral.spectral_clustering(points, n_clusters, k, sigma, unit_rows=False)
