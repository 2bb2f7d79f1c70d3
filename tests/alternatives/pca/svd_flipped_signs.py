"""PCA by the SVD of the centred data, with every eigenvector's sign flipped."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403


def pca(points, correlation=False, sort=True):
    x = np.array(points, dtype=float)
    if x.ndim != 2 or not np.isfinite(x).all():
        raise ValueError("points must be a finite 2-D array")
    xc = x - x.mean(axis=0)
    if correlation:
        std = xc.std(axis=0)
        xc = xc / np.where(np.ptp(x, axis=0) > 0, std, np.inf)
    _, s, vt = np.linalg.svd(xc, full_matrices=True)
    eigenvalues = np.zeros(x.shape[1])
    eigenvalues[: len(s)] = s**2 / len(x)
    return eigenvalues, -vt.T
