"""Returns a normal even for neighbourhoods of fewer than 3 points."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "no_nan_for_small_neighbourhoods"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    normals, curvature = _reference(points, k, radius, viewpoint)
    missing = np.isnan(curvature)
    normals[missing] = [0.0, 0.0, 1.0]
    curvature[missing] = 0.0
    return normals, curvature
