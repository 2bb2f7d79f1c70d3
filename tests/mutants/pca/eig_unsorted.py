"""Uses np.linalg.eig and returns its (unsorted, possibly non-orthogonal) output."""

import numpy as np

from pcl_course.validation import as_points
from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "eig_unsorted"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = as_points(points, min_columns=1, allow_empty=False)
    xc = x - x.mean(axis=0)
    if correlation:
        std = xc.std(axis=0)
        xc = xc / np.where(std > 0, std, 1.0)
    w, v = np.linalg.eig(xc.T @ xc / len(x))
    return w, v
