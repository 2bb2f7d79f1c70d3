"""Ignores correlation=True and always analyses the covariance."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401
from pcl_course.validation import as_points


def pca(points, correlation=False, sort=True):
    return _reference(points, False, sort)
