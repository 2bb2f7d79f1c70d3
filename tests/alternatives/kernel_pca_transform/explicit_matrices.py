"""Centring of new kernel rows written with the matrices 1_M (M x N) and 1_N, as in Schoelkopf et al."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix


def kernel_pca_transform(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2):
    k = kernel_matrix(points, points, kernel, beta, degree)
    k_new = kernel_matrix(new_points, points, kernel, beta, degree)
    m, n = k_new.shape
    one_mn = np.full((m, n), 1.0 / n)
    one_n = np.full((n, n), 1.0 / n)
    centred = k_new - one_mn @ k - k_new @ one_n + one_mn @ k @ one_n
    return centred @ np.asarray(alphas, dtype=float)
