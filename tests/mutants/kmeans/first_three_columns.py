"""Measures distances on x, y, z only (points[:, :3], a lecture-1 habit): here every column is a
coordinate. The means are over all columns."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference
from tests.mutants import _plain_kmeans

MISTAKE = "first_three_columns"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    return _plain_kmeans.kmeans(points, init_centers, max_iter, columns=3)
