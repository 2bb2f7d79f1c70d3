"""Counts the point itself among its neighbours (as Open3D's legacy filter does)."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import radius_outlier_removal as _reference

MISTAKE = "counts_itself"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def radius_outlier_removal(points, radius, min_neighbors):
    _reference(points, radius, min_neighbors)
    xyz = np.asarray(points, float)[:, :3]
    return cKDTree(xyz).query_ball_point(xyz, r=radius, return_length=True) >= min_neighbors
