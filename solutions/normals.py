"""Reference: plane fitting and surface normal estimation."""

import numpy as np

from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_same_shape
from solutions._fast.eig3 import normals_from_neighbourhoods
from solutions._fast.knn import kdtree, knn_normals

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
    points = as_points(points, columns=3, allow_empty=False)
    if weights is None:
        weights = np.ones(len(points))
    weights = as_array(weights, "weights", ndim=1)
    check_same_shape(weights, "weights", (len(points),), "one value per point:")
    if np.any(weights < 0) or weights.sum() <= 0:
        raise ValueError("weights must be non-negative with a positive sum")
    centroid = weights @ points / weights.sum()
    centred = points - centroid
    scatter = (centred * weights[:, None]).T @ centred
    normal = np.linalg.eigh(scatter)[1][:, 0]
    return centroid, normal


def _radius_normals(points, k, radius):
    """Normals of the neighbourhoods within ``radius`` (the ``k`` nearest of them unless k is None)."""
    n = len(points)
    # Neighbourhoods in compressed form: point i's are members[offsets[i]:offsets[i+1]].
    tree = kdtree(points)
    if k is not None:
        kk = min(k, n)
        distances, indices = tree.query(points, k=kk, workers=-1)
        # rows are sorted by distance: the ones within the radius are a prefix
        within = distances.reshape(n, kk) <= radius
        members, counts = indices.reshape(n, kk)[within], within.sum(axis=1)
    else:
        lists = tree.query_ball_point(points, r=radius, workers=-1)
        counts = np.fromiter((len(row) for row in lists), dtype=np.int64, count=n)
        members = np.concatenate(lists)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return normals_from_neighbourhoods(points, members.astype(np.int64), offsets)


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
    points = as_points(points, columns=3)
    n = len(points)
    if radius is None:
        if k is None:
            raise ValueError("k must be given when radius is None")
        k = check_integer(k, "k", low=1, high=n if n else None)
    else:
        radius = check_positive(radius, "radius")
        if k is not None:
            k = check_integer(k, "k", low=1)
    if viewpoint is not None:
        viewpoint = as_array(viewpoint, "viewpoint", ndim=1)
        check_same_shape(viewpoint, "viewpoint", (3,), "shape")
    if n == 0:
        return np.empty((0, 3)), np.empty(0)

    if radius is None:
        if k < 3:  # every neighbourhood is too small for a plane
            return np.full((n, 3), np.nan), np.full(n, np.nan)
        # k nearest: search and plane fit fused, on both cores.
        normals, curvature = knn_normals(points, k)
    else:
        normals, curvature = _radius_normals(points, k, radius)
    if viewpoint is not None:
        flip = np.einsum("ij,ij->i", normals, viewpoint - points) < 0
        normals[flip] *= -1.0
    return normals, curvature
