"""Returns the 0-based loop counter as n_iter: one less than the iterations run (and len(inertia))."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference
from tests.mutants import _plain_kmeans

MISTAKE = "n_iter_off_by_one"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    return _plain_kmeans.kmeans(points, init_centers, max_iter, zero_based_n_iter=True)
