"""Exercises: plane fitting and surface normal estimation.

Use :mod:`pcl_course.neighbors` for neighbour search and
:mod:`pcl_course.validation` for input checks. Do not call Open3D or PCL here.
"""

# What every solution needs (NumPy; SciPy's k-d tree is allowed; the course's input checks).
import numpy as np  # noqa: F401
from scipy.spatial import cKDTree  # noqa: F401

from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_same_shape  # noqa: F401

__all__ = ["fit_plane", "estimate_normals"]


def fit_plane(points, weights=None):
    """Weighted least-squares plane through a point set.

    Solves ``min sum_i w_i ((x_i - c) . n) ** 2`` subject to ``||n|| = 1``.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    weights : array_like, shape (N,), optional
        Non-negative weights with a positive sum; all ones when None.

    Returns
    -------
    centroid : ndarray of float64, shape (3,)
        The (weighted) mean of the points.
    normal : ndarray of float64, shape (3,)
        Unit eigenvector of the smallest eigenvalue of
        ``sum_i w_i (x_i - c)(x_i - c)^T``. Its sign is free.

    Raises
    ------
    ValueError
        Bad ``points``; ``weights`` of the wrong shape, negative, non-finite
        or summing to zero.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0.0, 0, 2], [1, 0, 2], [0, 1, 2], [1, 1, 2]])
    >>> centroid, normal = fit_plane(square)
    >>> centroid
    array([0.5, 0.5, 2. ])
    >>> np.abs(normal)  # the plane z = 2
    array([0., 0., 1.])
    """
    raise NotImplementedError("fit_plane: not implemented yet")


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    """Normal and curvature of every point from its neighbourhood.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    k : int or None, default 30
        With ``radius=None``: the neighbourhood is the ``k`` nearest points
        **including the point itself**. With ``radius`` set: keep only the
        ``k`` nearest of the points within ``radius`` (``k=None``: all).
    radius : float, optional
        Neighbourhood radius (distance ``<= radius``, the point included).
    viewpoint : array_like, shape (3,), optional
        If given, flip every normal so that ``normal . (viewpoint - point) >= 0``.

    Returns
    -------
    normals : ndarray of float64, shape (N, 3)
        Unit eigenvector of the smallest eigenvalue of the neighbourhood's
        covariance (centred on the neighbourhood's own mean). Sign free
        unless ``viewpoint`` is given. NaN where the neighbourhood has fewer
        than 3 points.
    curvature : ndarray of float64, shape (N,)
        Surface variation ``l_min / (l_1 + l_2 + l_3)``; 0 where the trace is
        0; NaN where the neighbourhood has fewer than 3 points.

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``radius``; ``k`` < 1; ``k`` larger than
        N with ``radius=None``; both ``k`` and ``radius`` None; a ``viewpoint``
        that is not 3 finite numbers.

    Notes
    -----
    Must stay accurate for clouds far from the origin (coordinates around
    1e6): centre before you multiply. An empty cloud gives empty results.
    """
    raise NotImplementedError("estimate_normals: not implemented yet")
