"""Reference: principal component analysis and kernel PCA."""

import numpy as np
from scipy.linalg import eigh
from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh
from scipy.spatial.distance import cdist, pdist, squareform

from pcl_course.validation import (
    as_array,
    as_points,
    check_choice,
    check_integer,
    check_positive,
    check_same_shape,
)

__all__ = ["pca", "kernel_matrix", "kernel_pca", "kernel_pca_transform"]

_KERNELS = ("linear", "polynomial", "gaussian", "laplacian")
_DISTANCES = {"gaussian": "sqeuclidean", "laplacian": "cityblock"}  # exp(-beta * distance) kernels


def pca(points, correlation=False, sort=True):
    """Principal component analysis of a point set.

    Parameters
    ----------
    points : array_like, shape (N, D)
        N samples of dimension D (for a point cloud, D = 3).
    correlation : bool, default False
        If True, divide each centred column by its population standard
        deviation first, i.e. analyse the correlation matrix instead of the
        covariance matrix. A constant column (standard deviation 0) is left
        at zero.
    sort : bool, default True
        If True, return the eigenvalues in descending order (and the
        eigenvectors in the matching order).

    Returns
    -------
    eigenvalues : ndarray of float64, shape (D,)
        Eigenvalues of ``H = X~^T X~ / N``, where ``X~`` is the centred data
        (each column minus its own mean). Note the population normalisation
        ``1 / N``, not ``1 / (N - 1)``.
    eigenvectors : ndarray of float64, shape (D, D)
        Orthonormal eigenvectors as **columns**
        (``eigenvectors.T @ eigenvectors == I``, also when eigenvalues repeat:
        H is symmetric, so use ``np.linalg.eigh``, not ``eig``) and
        ``H @ eigenvectors[:, i] == eigenvalues[i] * eigenvectors[:, i]``.
        The sign of each eigenvector is free.

    Raises
    ------
    ValueError
        If ``points`` is not 2-D or holds NaN or inf (the message names
        ``points``).

    Notes
    -----
    Inputs must not be modified in place. Outputs are plain real
    ``np.ndarray`` (float64), never complex, never lists.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[-2.0, 0.0], [2.0, 0.0], [0.0, -1.0], [0.0, 1.0]])
    >>> eigenvalues, eigenvectors = pca(points)
    >>> eigenvalues  # the variances along x and y: 8/4 and 2/4
    array([2. , 0.5])
    >>> np.abs(eigenvectors)
    array([[1., 0.],
           [0., 1.]])
    """
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
    check_same_shape(y, "y", (len(y), x.shape[1]), "the width of x:")
    return x, y


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    """Kernel (Gram) matrix between two point sets.

    Parameters
    ----------
    x : array_like, shape (N, D)
    y : array_like, shape (M, D)
    kernel : {"linear", "polynomial", "gaussian", "laplacian"}, default "gaussian"
        ``linear``: ``x . y``; ``polynomial``: ``(1 + x . y) ** degree``;
        ``gaussian``: ``exp(-beta * ||x - y||_2 ** 2)`` (the standard RBF
        kernel: note the square); ``laplacian``: ``exp(-beta * ||x - y||_1)``.
    beta : float, default 1.0
        Positive width parameter of the gaussian and laplacian kernels.
    degree : int, default 2
        Degree of the polynomial kernel.

    Returns
    -------
    K : ndarray of float64, shape (N, M)
        ``K[i, j] = k(x[i], y[j])``.

    Raises
    ------
    ValueError
        For arrays that are not 2-D, of different widths or non-finite, an
        unknown ``kernel`` or a non-positive ``beta``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0]])
    >>> kernel_matrix(x, x, kernel="gaussian", beta=1.0).round(4)  # exp(-1) off the diagonal
    array([[1.    , 0.3679],
           [0.3679, 1.    ]])
    """
    x, y = _check_pair(x, y)
    check_choice(kernel, "kernel", _KERNELS)
    if kernel == "linear":
        return x @ y.T
    if kernel == "polynomial":
        degree = check_integer(degree, "degree", low=1)
        return (1.0 + x @ y.T) ** degree
    beta = check_positive(beta, "beta")
    return _exp_kernel(cdist(x, y, metric=_DISTANCES[kernel]), beta)


def _exp_kernel(distances, beta):
    """``exp(-beta * distances)``, in place: no further N x M temporaries."""
    distances *= -beta
    return np.exp(distances, out=distances)


def _self_gram(points, kernel, beta, degree):
    """``kernel_matrix(points, points, ...)``; for the distance kernels, each pair computed once.

    The Gram matrix of a cloud with itself is symmetric with ones on the
    diagonal: ``pdist`` and half the exponentials, mirrored by ``squareform``.
    """
    if kernel not in _DISTANCES:
        return kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    beta = check_positive(beta, "beta")
    gram = squareform(_exp_kernel(pdist(points, metric=_DISTANCES[kernel]), beta))
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
    """Kernel PCA.

    Parameters
    ----------
    points : array_like, shape (N, D)
    n_components : int
        Number of components, between 1 and N.
    kernel, beta, degree
        As in :func:`kernel_matrix`.

    Returns
    -------
    projections : ndarray of float64, shape (N, n_components)
        ``K~ @ alphas``.
    eigenvalues : ndarray of float64, shape (n_components,)
        The largest eigenvalues of the centred Gram matrix
        ``K~ = K - 1_N K - K 1_N + 1_N K 1_N`` (``1_N`` is the N x N matrix
        whose entries are all ``1 / N``), in descending order. Eigenvalues of
        ``K~`` itself, not divided by N.
    alphas : ndarray of float64, shape (N, n_components)
        The matching eigenvectors, scaled so that
        ``alphas[:, r] @ alphas[:, r] == 1 / eigenvalues[r]``.
        The sign of each component is free. An eigenvalue that is zero has
        no such scaling: its column is all zeros (and its projections are
        0). ``K~`` always has one (the constant vector), and more when N
        exceeds the dimension of the feature space; numerically, "zero" is
        at most ``1e-12`` times the largest eigenvalue, as in scikit-learn.

    Raises
    ------
    ValueError
        Bad ``points``; ``n_components`` not between 1 and N; an unknown
        ``kernel`` or a non-positive ``beta``.

    Notes
    -----
    The result equals scikit-learn's ``KernelPCA(...).fit_transform`` and
    ``eigenvalues_`` up to sign, but you must not call scikit-learn here.
    """
    points = as_points(points, min_columns=1, allow_empty=False)
    n = points.shape[0]
    n_components = check_integer(n_components, "n_components", low=1, high=n)
    gram = _self_gram(points, kernel, beta, degree)
    eigenvalues, eigenvectors = _top_eigenpairs(gram, n_components)
    # Zero eigenvalues (to round-off, as scikit-learn's _check_psd_eigenvalues decides) get zero alphas.
    positive = eigenvalues > 1e-12 * max(eigenvalues[0], 0.0)
    scale = np.zeros_like(eigenvalues)
    scale[positive] = 1.0 / np.sqrt(eigenvalues[positive])
    alphas = eigenvectors * scale
    # K~ alphas = K~ v / sqrt(l) = sqrt(l) v: no N x N product needed.
    projections = eigenvectors * np.sqrt(np.where(positive, eigenvalues, 0.0))
    return projections, np.ascontiguousarray(eigenvalues), np.ascontiguousarray(alphas)


def kernel_pca_transform(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2):
    """Project new points onto the components found by :func:`kernel_pca`.

    Parameters
    ----------
    new_points : array_like, shape (M, D)
    points : array_like, shape (N, D)
        The training points given to :func:`kernel_pca`.
    alphas : array_like, shape (N, n_components)
        The ``alphas`` returned by :func:`kernel_pca`.
    kernel, beta, degree
        As in :func:`kernel_matrix`.

    Returns
    -------
    projections : ndarray of float64, shape (M, n_components)
        The new kernel rows ``K_new = kernel_matrix(new_points, points)``
        centred against the training Gram matrix ``K`` (subtract the row
        means of ``K_new`` and the column means of ``K``, add the grand mean
        of ``K``), then multiplied by ``alphas``.
        ``kernel_pca_transform(points, points, alphas)`` equals the
        ``projections`` of :func:`kernel_pca`.

    Raises
    ------
    ValueError
        Bad ``new_points`` or ``points``, widths that differ, ``alphas`` whose
        row count is not N; an unknown ``kernel`` or a non-positive ``beta``.
    """
    new_points = as_points(new_points, "new_points", min_columns=1)
    points = as_points(points, min_columns=1, allow_empty=False)
    alphas = as_array(alphas, "alphas", ndim=2)
    check_same_shape(alphas, "alphas", points.shape[:1], "one row per training point:", leading=True)
    check_same_shape(new_points, "new_points", (len(new_points), points.shape[1]), "the width of points:")
    gram = kernel_matrix(points, points, kernel=kernel, beta=beta, degree=degree)
    new_rows = kernel_matrix(new_points, points, kernel=kernel, beta=beta, degree=degree)
    column_means, grand_mean = _centring_terms(gram)
    centred = new_rows - new_rows.mean(axis=1)[:, None] - column_means[None, :] + grand_mean
    return centred @ alphas
