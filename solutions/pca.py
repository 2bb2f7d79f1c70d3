"""Reference: principal component analysis and kernel PCA."""

import numpy as np
from scipy.linalg import eigh
from scipy.spatial.distance import cdist

from pcl_course.validation import as_array, as_points, check_choice, check_integer, check_positive

KERNELS = ("linear", "polynomial", "gaussian", "laplacian")


def pca(points, correlation=False, sort=True):
    points = as_points(points, min_columns=1, allow_empty=False)
    centred = points - points.mean(axis=0)
    if correlation:
        # Test constancy on the data, not on the centred column: the mean of
        # equal floats can differ from them by an ulp, and dividing that
        # rounding error by its own tiny std would give +-1, not 0.
        varying = np.ptp(points, axis=0) > 0
        std = centred.std(axis=0)
        centred = np.divide(centred, std, out=np.zeros_like(centred), where=varying)
    covariance = centred.T @ centred / points.shape[0]
    eigenvalues, eigenvectors = np.linalg.eigh(covariance)
    if sort:
        eigenvalues, eigenvectors = eigenvalues[::-1], eigenvectors[:, ::-1]
    return np.ascontiguousarray(eigenvalues), np.ascontiguousarray(eigenvectors)


def _check_pair(x, y):
    x = as_array(x, "x", ndim=2)
    y = as_array(y, "y", ndim=2)
    if x.shape[1] != y.shape[1]:
        raise ValueError(f"x and y must have the same width, got {x.shape} and {y.shape}")
    return x, y


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    x, y = _check_pair(x, y)
    check_choice(kernel, "kernel", KERNELS)
    if kernel == "linear":
        return x @ y.T
    if kernel == "polynomial":
        degree = check_integer(degree, "degree", low=1)
        return (1.0 + x @ y.T) ** degree
    beta = check_positive(beta, "beta")
    metric = "sqeuclidean" if kernel == "gaussian" else "cityblock"
    return np.exp(-beta * cdist(x, y, metric=metric))


def _centring_terms(gram):
    return gram.mean(axis=0), gram.mean()


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    points = as_points(points, min_columns=1, allow_empty=False)
    n = points.shape[0]
    n_components = check_integer(n_components, "n_components", low=1, high=n)
    gram = kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    column_means, grand_mean = _centring_terms(gram)
    # K - 1_N K - K 1_N + 1_N K 1_N, without forming the N x N matrices 1_N.
    centred = gram - column_means[None, :] - gram.mean(axis=1)[:, None] + grand_mean
    # Only the top eigenpairs are needed: ask LAPACK for just those.
    eigenvalues, eigenvectors = eigh(centred, subset_by_index=[n - n_components, n - 1])
    eigenvalues, eigenvectors = eigenvalues[::-1], eigenvectors[:, ::-1]
    positive = eigenvalues > 0
    scale = np.zeros_like(eigenvalues)
    scale[positive] = 1.0 / np.sqrt(eigenvalues[positive])
    alphas = eigenvectors * scale
    projections = centred @ alphas
    return projections, np.ascontiguousarray(eigenvalues), np.ascontiguousarray(alphas)


def kernel_pca_transform(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2):
    new_points = as_points(new_points, "new_points", min_columns=1)
    points = as_points(points, min_columns=1, allow_empty=False)
    alphas = as_array(alphas, "alphas", ndim=2)
    if alphas.shape[0] != points.shape[0]:
        raise ValueError(
            f"alphas must have one row per training point ({points.shape[0]}), got {alphas.shape}"
        )
    if new_points.shape[1] != points.shape[1]:
        raise ValueError(
            f"new_points must have the width of points ({points.shape[1]}), got {new_points.shape}"
        )
    gram = kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    new_rows = kernel_matrix(new_points, points, kernel=kernel, beta=beta, degree=degree)
    column_means, grand_mean = _centring_terms(gram)
    centred = new_rows - new_rows.mean(axis=1)[:, None] - column_means[None, :] + grand_mean
    return centred @ alphas
