"""Polynomial kernel (x . y) ** degree, without the + 1."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix as _reference

MISTAKE = "polynomial_without_one"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    if kernel == "polynomial":
        return (np.asarray(x, float) @ np.asarray(y, float).T) ** degree
    return _reference(x, y, kernel, beta, degree)
