"""Counts the point itself (distance 0) among its k nearest neighbours."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import statistical_outlier_removal as _reference

MISTAKE = "includes_itself"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def statistical_outlier_removal(points, k, std_ratio):
    _reference(points, k, std_ratio)  # validation only
    xyz = np.asarray(points, float)[:, :3]
    d, _ = cKDTree(xyz).query(xyz, k=k + 1)
    d = d[:, 1:]
    d = cKDTree(xyz).query(xyz, k=k)[0].reshape(len(xyz), k)
    m = d.mean(axis=1)
    return m <= m.mean() + std_ratio * m.std(ddof=1)
