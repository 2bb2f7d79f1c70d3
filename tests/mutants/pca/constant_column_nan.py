"""Divides by the standard deviation without guarding constant columns (NaN)."""

import numpy as np

from pcl_course.validation import as_points
from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "constant_column_nan"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = as_points(points, min_columns=1, allow_empty=False)
    xc = x - x.mean(axis=0)
    if correlation:
        with np.errstate(invalid="ignore", divide="ignore"):
            xc = xc / xc.std(axis=0)
    w, v = np.linalg.eigh(xc.T @ xc / len(x))
    return w[::-1].copy(), v[:, ::-1].copy()
