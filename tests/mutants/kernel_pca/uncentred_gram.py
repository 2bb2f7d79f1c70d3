"""Uses the Gram matrix K without centring it in feature space."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix

MISTAKE = "uncentred_gram"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    k = kernel_matrix(points, points, kernel, beta, degree)
    values, vectors = np.linalg.eigh(k)
    values, vectors = values[::-1][:n_components], vectors[:, ::-1][:, :n_components]
    alphas = vectors / np.sqrt(values)
    return k @ alphas, values, alphas
