"""Uses scipy.linalg.eig, whose eigenvalues are always complex, and sorts by the real part."""

import numpy as np
import scipy.linalg

from pcl_course.validation import as_points
from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "complex"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = as_points(points, min_columns=1, allow_empty=False)
    xc = x - x.mean(axis=0)
    w, v = scipy.linalg.eig(xc.T @ xc / len(x))
    order = np.argsort(-w.real)
    return w[order], v[:, order]
