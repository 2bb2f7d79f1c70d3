"""Gives a border point the cluster of its nearest core neighbour (a hostile review's submission,
h49d), where the contract gives it the smallest label among its core neighbours' clusters."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_dbscan

MISTAKE = "border_nearest_core"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    return _plain_dbscan.dbscan(points, eps, min_samples, border="nearest_core")
