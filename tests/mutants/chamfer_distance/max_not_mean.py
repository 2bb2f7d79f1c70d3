"""Takes the largest nearest distance (Hausdorff-like) instead of the mean."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.metrics import *  # noqa: F401,F403
from solutions.metrics import chamfer_distance as _reference

MISTAKE = "max_not_mean"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def chamfer_distance(a, b):
    _reference(a, b)  # validation only
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab, ba = cKDTree(b).query(a)[0], cKDTree(a).query(b)[0]
    return float(np.max(ab**2) + np.max(ba**2))
