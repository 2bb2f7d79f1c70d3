"""The slides' centring K - 2 (1/N) K + (1/N) K (1/N), read as matrices: K - 2 1_N K + 1_N K 1_N.

Not symmetric, so np.linalg.eigh reads its lower triangle only. (Symmetrised,
(M + M^T) / 2, it would be the right centring.)
"""

import numpy as np

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix
from solutions.pca import kernel_pca as _reference

MISTAKE = "lecture_centring"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    _reference(points, n_components, kernel, beta, degree)  # validation only
    k = kernel_matrix(points, points, kernel, beta, degree)
    one = np.full_like(k, 1.0 / len(k))
    kc = k - 2 * one @ k + one @ k @ one
    values, vectors = np.linalg.eigh(kc)
    values, vectors = values[::-1][:n_components], vectors[:, ::-1][:, :n_components]
    alphas = vectors / np.sqrt(np.abs(values))
    return kc @ alphas, values, alphas
