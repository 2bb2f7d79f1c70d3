"""Takes the first columns of eigh's ascending output: the smallest components."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix

MISTAKE = "ascending_order"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    k = kernel_matrix(points, points, kernel, beta, degree)
    kc = k - k.mean(axis=0) - k.mean(axis=1)[:, None] + k.mean()
    values, vectors = np.linalg.eigh(kc)
    values, vectors = values[:n_components], vectors[:, :n_components]
    alphas = vectors / np.sqrt(np.abs(values) + 1e-300)
    return kc @ alphas, values, alphas
