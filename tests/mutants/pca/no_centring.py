"""Forgets to centre: uses X^T X / N, the second moment about the origin."""

import numpy as np

from pcl_course.validation import as_points
from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "no_centring"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = as_points(points, min_columns=1, allow_empty=False)
    h = x.T @ x / len(x)
    w, v = np.linalg.eigh(h)
    return w[::-1].copy(), v[:, ::-1].copy()
