"""Only the a-to-b direction."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.metrics import *  # noqa: F401,F403
from solutions.metrics import chamfer_distance as _reference

MISTAKE = "one_direction"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def chamfer_distance(a, b):
    _reference(a, b)  # validation only
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab, ba = cKDTree(b).query(a)[0], cKDTree(a).query(b)[0]  # noqa: F841 -- the mistake: b -> a is computed, then forgotten
    return float(np.mean(ab**2))
