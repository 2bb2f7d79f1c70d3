"""Neighbour search helpers (complete), built on ``scipy.spatial.cKDTree``.

The course allows a k-d tree for neighbour search until the nearest-neighbour
lecture, where you will write your own.
"""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive

__all__ = ["knn", "radius_neighbors"]


def knn(points, k, queries=None, include_self=True, workers=1):
    """The ``k`` nearest neighbours of every query point.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    k : int
        Number of neighbours, ``1 <= k <= N`` (``N - 1`` without self).
    queries : array_like, shape (M, 3), optional
        Query points; the points themselves when None.
    include_self : bool, default True
        With ``queries=None``: whether a point is its own first neighbour.
        Without it, the point's own index is removed (a duplicate of the point
        still counts, at distance 0).
    workers : int, default 1
        Threads for the query (-1: all cores).

    Returns
    -------
    distances : ndarray of float64, shape (M, k)
        Euclidean distances, ascending along each row.
    indices : ndarray of int64, shape (M, k)
    """
    points = as_points(points)[:, :3]
    n = len(points)
    self_query = queries is None
    drop_self = self_query and not include_self
    k = check_integer(k, "k", low=1, high=n - 1 if drop_self else n)
    queries = points if self_query else as_points(queries, "queries")[:, :3]
    tree = cKDTree(points)
    distances, indices = tree.query(queries, k=k + drop_self, workers=workers)
    distances = np.asarray(distances).reshape(len(queries), -1)
    indices = np.asarray(indices, dtype=np.int64).reshape(len(queries), -1)
    if drop_self:
        # Remove each row's own index (not just column 0: with duplicates the
        # point itself need not come first).
        own = indices == np.arange(n)[:, None]
        own[~own.any(axis=1), -1] = True
        keep = ~own
        distances = distances[keep].reshape(n, k)
        indices = indices[keep].reshape(n, k)
    return distances, indices


def radius_neighbors(points, radius, queries=None, workers=1):
    """Indices of the points within ``radius`` (distance ``<= radius``) of each query.

    Returns
    -------
    neighbours : list of ndarray of int64
        One sorted index array per query point (the point itself included
        when ``queries`` is None).
    """
    points = as_points(points)[:, :3]
    radius = check_positive(radius, "radius")
    queries = points if queries is None else as_points(queries, "queries")[:, :3]
    lists = cKDTree(points).query_ball_point(queries, r=radius, workers=workers, return_sorted=True)
    return [np.asarray(row, dtype=np.int64) for row in lists]
