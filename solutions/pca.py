"""Reference: principal component analysis and kernel PCA."""

import numpy as np
from scipy.linalg import eigh
from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh
from scipy.spatial.distance import cdist, pdist, squareform

from pcl_course.validation import as_array, as_points, check_choice, check_integer, check_positive

KERNELS = ("linear", "polynomial", "gaussian", "laplacian")
DISTANCES = {"gaussian": "sqeuclidean", "laplacian": "cityblock"}  # exp(-beta * distance) kernels


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
    return _exp_kernel(cdist(x, y, metric=DISTANCES[kernel]), beta)


def _exp_kernel(distances, beta):
    """``exp(-beta * distances)``, in place: no further N x M temporaries."""
    distances *= -beta
    return np.exp(distances, out=distances)


def _self_gram(points, kernel, beta, degree):
    """``kernel_matrix(points, points, ...)``; for the distance kernels, each pair computed once.

    The Gram matrix of a cloud with itself is symmetric with ones on the
    diagonal: ``pdist`` and half the exponentials, mirrored by ``squareform``.
    """
    if kernel not in DISTANCES:
        return kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    beta = check_positive(beta, "beta")
    gram = squareform(_exp_kernel(pdist(points, metric=DISTANCES[kernel]), beta))
    np.fill_diagonal(gram, 1.0)
    return gram


def _centring_terms(gram):
    return gram.mean(axis=0), gram.mean()


def _top_eigenpairs(gram, n_components):
    """The ``n_components`` largest eigenvalues of the centred Gram matrix, descending, and eigenvectors.

    A few components of a large matrix: Lanczos iterations (ARPACK), which
    only multiply by the matrix, O(N^2) each, instead of the O(N^3)
    tridiagonalisation a dense solver needs even for one eigenpair. The
    centring is applied inside each product, never to the matrix:
    ``K~ v = K v - mean(K v) - r sum(v) + mean(K) sum(v)``, ``r`` the row
    means of ``K``. The start vector is fixed, so results are reproducible.
    Many components, a small matrix or no convergence: the dense LAPACK
    solver on the centred matrix, for just those eigenpairs.
    """
    n = gram.shape[0]
    row_means, grand_mean = _centring_terms(gram)  # K is symmetric: row means are column means
    if n > 200 and n_components < min(10, n // 20):

        def centred_product(v):
            v = v.reshape(n, -1)
            kv = gram @ v
            total = v.sum(axis=0)
            return kv - kv.mean(axis=0) - row_means[:, None] * total + grand_mean * total

        operator = LinearOperator((n, n), matvec=centred_product, matmat=centred_product, dtype=np.float64)
        start = np.random.default_rng(0).uniform(-1.0, 1.0, n)
        try:
            eigenvalues, eigenvectors = eigsh(operator, k=n_components, which="LA", v0=start)
        except ArpackNoConvergence:
            pass
        else:
            order = np.argsort(eigenvalues)[::-1]
            return eigenvalues[order], eigenvectors[:, order]
    # K - 1_N K - K 1_N + 1_N K 1_N, without forming the N x N matrices 1_N.
    centred = gram - row_means[None, :] - row_means[:, None] + grand_mean
    eigenvalues, eigenvectors = eigh(centred, subset_by_index=[n - n_components, n - 1])
    return eigenvalues[::-1], eigenvectors[:, ::-1]


def kernel_pca(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    points = as_points(points, min_columns=1, allow_empty=False)
    n = points.shape[0]
    n_components = check_integer(n_components, "n_components", low=1, high=n)
    gram = _self_gram(points, kernel, beta, degree)
    eigenvalues, eigenvectors = _top_eigenpairs(gram, n_components)
    positive = eigenvalues > 0
    scale = np.zeros_like(eigenvalues)
    scale[positive] = 1.0 / np.sqrt(eigenvalues[positive])
    alphas = eigenvectors * scale
    # K~ alphas = K~ v / sqrt(l) = sqrt(l) v: no N x N product needed.
    projections = eigenvectors * np.sqrt(np.clip(eigenvalues, 0.0, None))
    return projections, np.ascontiguousarray(eigenvalues), np.ascontiguousarray(alphas)


def kernel_pca_transform(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2):
    new_points = as_points(new_points, "new_points", min_columns=1)
    points = as_points(points, min_columns=1, allow_empty=False)
    alphas = as_array(alphas, "alphas", ndim=2)
    if alphas.shape[0] != points.shape[0]:
        raise ValueError(f"alphas must have one row per training point ({points.shape[0]}), got {alphas.shape}")
    if new_points.shape[1] != points.shape[1]:
        raise ValueError(f"new_points must have the width of points ({points.shape[1]}), got {new_points.shape}")
    gram = kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    new_rows = kernel_matrix(new_points, points, kernel=kernel, beta=beta, degree=degree)
    column_means, grand_mean = _centring_terms(gram)
    centred = new_rows - new_rows.mean(axis=1)[:, None] - column_means[None, :] + grand_mean
    return centred @ alphas
