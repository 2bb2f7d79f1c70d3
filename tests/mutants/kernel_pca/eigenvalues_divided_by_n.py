"""Solves the eigenproblem of K~ / N (the covariance-style normalisation)."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix

MISTAKE = "eigenvalues_divided_by_n"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    k = kernel_matrix(points, points, kernel, beta, degree)
    n = len(k)
    kc = k - k.mean(axis=0) - k.mean(axis=1)[:, None] + k.mean()
    values, vectors = np.linalg.eigh(kc / n)
    values, vectors = values[::-1][:n_components], vectors[:, ::-1][:, :n_components]
    alphas = vectors / np.sqrt(values)
    return kc @ alphas, values, alphas
