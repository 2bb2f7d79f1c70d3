"""PCA with the covariance summed in plain Python loops, unsorted when asked."""

import math

import numpy as np

from solutions.pca import *  # noqa: F401,F403


def pca(points, correlation=False, sort=True):
    rows = np.asarray(points, dtype=float)
    if rows.ndim != 2:
        raise ValueError(f"points must be 2-D, got {rows.ndim}-D")
    if not np.all(np.isfinite(rows)):
        raise ValueError("points contains NaN or inf")
    n, d = rows.shape
    mean = [sum(rows[i, j] for i in range(n)) / n for j in range(d)]
    centred = [[rows[i, j] - mean[j] for j in range(d)] for i in range(n)]
    if correlation:
        for j in range(d):
            std = math.sqrt(sum(centred[i][j] ** 2 for i in range(n)) / n)
            for i in range(n):
                centred[i][j] = centred[i][j] / std if std > 1e-12 * (abs(mean[j]) + 1) else 0.0
    h = np.zeros((d, d))
    for a in range(d):
        for b in range(d):
            h[a, b] = sum(centred[i][a] * centred[i][b] for i in range(n)) / n
    eigenvalues, eigenvectors = np.linalg.eigh(h)
    if sort:
        order = np.argsort(eigenvalues)[::-1]
        eigenvalues, eigenvectors = eigenvalues[order], eigenvectors[:, order]
    else:  # any order is allowed: return it rotated
        eigenvalues, eigenvectors = np.roll(eigenvalues, 1), np.roll(eigenvectors, 1, axis=1)
    return eigenvalues, eigenvectors
