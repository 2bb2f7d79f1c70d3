"""Re-seeds an empty cluster at the point farthest from its centre (scikit-learn's relocation), where
the contract keeps an empty cluster's centre."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference
from tests.mutants import _plain_kmeans

MISTAKE = "empty_cluster_relocated"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    return _plain_kmeans.kmeans(points, init_centers, max_iter, empty="relocate")
