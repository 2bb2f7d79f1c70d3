"""Counts neighbours at distance < radius instead of <= radius."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import radius_outlier_removal as _reference

MISTAKE = "strict_radius"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def radius_outlier_removal(points, radius, min_neighbors):
    _reference(points, radius, min_neighbors)
    xyz = np.asarray(points, float)[:, :3]
    return (cdist(xyz, xyz) < radius).sum(axis=1) - 1 >= min_neighbors
