"""Kernel PCA with the N x N matrices 1_N written out, full eigh, every component's sign flipped."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    points = np.asarray(points, dtype=float)
    n = len(points)
    if not 1 <= n_components <= n:
        raise ValueError(f"n_components must be between 1 and {n}")
    k = kernel_matrix(points, points, kernel, beta, degree)
    one = np.full((n, n), 1.0 / n)
    kc = k - one @ k - k @ one + one @ k @ one
    values, vectors = np.linalg.eigh(kc)
    order = np.argsort(values)[::-1][:n_components]
    values, vectors = values[order], -vectors[:, order]
    alphas = vectors / np.sqrt(values)
    return kc @ alphas, values, alphas
