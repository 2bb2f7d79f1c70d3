"""Never checks for unchanged labels: always runs max_iter iterations (the answer's labels and centres
are right once converged; inertia has max_iter entries and n_iter is max_iter)."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference
from tests.mutants import _plain_kmeans

MISTAKE = "no_early_stop"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    return _plain_kmeans.kmeans(points, init_centers, max_iter, stop="never")
