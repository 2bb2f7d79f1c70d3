"""The lecture's 'Gaussian' kernel exp(-beta ||x - y||_2): the square is missing."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix as _reference

MISTAKE = "gaussian_without_square"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    if kernel == "gaussian":
        return np.exp(-beta * cdist(np.asarray(x, float), np.asarray(y, float)))
    return _reference(x, y, kernel, beta, degree)
