"""Leaves the eigenvectors at unit norm: projections off by sqrt(eigenvalue)."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_pca as _reference

MISTAKE = "unit_eigenvectors"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    projections, values, alphas = _reference(points, n_components, kernel, beta, degree)
    alphas = alphas * np.sqrt(values)  # back to unit norm
    return projections * np.sqrt(values), values, alphas  # K~ v = lambda v
