"""Uses np.cov's default N - 1 normalisation instead of N."""

import numpy as np

from pcl_course.validation import as_points
from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "sample_covariance"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = as_points(points, min_columns=1, allow_empty=False)
    h = np.corrcoef(x.T) if correlation else np.cov(x.T)
    w, v = np.linalg.eigh(np.atleast_2d(h))
    return w[::-1].copy(), v[:, ::-1].copy()
