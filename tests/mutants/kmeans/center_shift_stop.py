"""Stops when the centres moved less than 1e-4 (np.linalg.norm of the move) instead of when no label
changed: one iteration too many at convergence, and too early where a move is small but changes labels."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference
from tests.mutants import _plain_kmeans

MISTAKE = "center_shift_stop"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    return _plain_kmeans.kmeans(points, init_centers, max_iter, stop="shift")
