"""Exercises: principal component analysis and kernel PCA.

Implement the functions below. Their contract (names, shapes, conventions,
errors) is written in each docstring; the autograder checks exactly that.
Use :mod:`pcl_course.validation` for input checks. Do not call scikit-learn's
``PCA`` / ``KernelPCA``, Open3D or PCL here: NumPy and SciPy are allowed.

Run the tests of one exercise with ``pytest tests/graded -k pca`` or
``python -m grading grade . -k pca``.
"""

# What every solution needs (NumPy; SciPy's k-d tree is allowed; the course's input checks).
import numpy as np  # noqa: F401

from pcl_course.validation import as_array, as_points, check_choice, check_integer, check_positive  # noqa: F401

__all__ = ["pca", "kernel_matrix", "kernel_pca", "kernel_pca_transform"]


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
    raise NotImplementedError("pca: not implemented yet")


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
    raise NotImplementedError("kernel_matrix: not implemented yet")


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
    raise NotImplementedError("kernel_pca: not implemented yet")


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
    raise NotImplementedError("kernel_pca_transform: not implemented yet")
