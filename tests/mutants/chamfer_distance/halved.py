"""Halves the sum of the two directions."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.metrics import *  # noqa: F401,F403
from solutions.metrics import chamfer_distance as _reference

MISTAKE = "halved"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def chamfer_distance(a, b):
    _reference(a, b)  # validation only
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab, ba = cKDTree(b).query(a)[0], cKDTree(a).query(b)[0]
    return float((np.mean(ab**2) + np.mean(ba**2)) / 2)
