"""Laplacian kernel with the Euclidean instead of the L1 norm."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix as _reference

MISTAKE = "laplacian_with_l2_norm"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    if kernel == "laplacian":
        return np.exp(-beta * cdist(np.asarray(x, float), np.asarray(y, float)))
    return _reference(x, y, kernel, beta, degree)
