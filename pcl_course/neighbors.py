"""Neighbour search helpers (complete), built on ``scipy.spatial.cKDTree``.

The course allows a k-d tree for neighbour search until the nearest-neighbour
lecture, where you will write your own.
"""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive

__all__ = ["knn", "radius_neighbors", "scipy_kdtree"]


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


def scipy_kdtree(points, leaf_size=16, balanced_tree=True, compact_nodes=True):
    """SciPy's k-d tree of ``points``, in the layout of ``pcl_course.nn.kdtree_build``.

    For comparing split rules. SciPy picks a node's split axis where its box
    is widest, then cuts it:

    - ``balanced_tree=True`` (SciPy's default): at the median of the node's
      points along that axis;
    - ``balanced_tree=False, compact_nodes=True``: at the middle of the
      points' spread along that axis (both sides always hold points, so the
      cut never slides);
    - ``balanced_tree=False, compact_nodes=False``: the sliding midpoint of
      Maneewongvatana and Mount: at the middle of the node's *cell*, slid to
      the nearest point if one side would be empty.

    With ``compact_nodes=True`` the box is the node's points' bounding box,
    otherwise its cell. None of these is the course's rule (the median, the
    axes in turn).

    Parameters
    ----------
    points : array_like, shape (N, D)
    leaf_size : int, default 16
        SciPy's ``leafsize``: nodes of at most this many points are leaves.
    balanced_tree : bool, default True
    compact_nodes : bool, default True

    Returns
    -------
    dict of str to ndarray
        ``order``, ``start``, ``stop``, ``axis``, ``split``, ``left``, ``right``
        in preorder (``axis`` is -1 at a leaf), as ``kdtree_build`` returns.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or len(points) == 0:
        raise ValueError(f"points must be a non-empty (N, D) array, got shape {points.shape}")
    leaf_size = check_integer(leaf_size, "leaf_size", low=1)
    tree = cKDTree(points, leafsize=leaf_size, balanced_tree=bool(balanced_tree), compact_nodes=bool(compact_nodes))
    columns = {key: [] for key in ("start", "stop", "axis", "split", "left", "right")}
    stack = [(tree.tree, -1, "")]  # (node, parent id, which child of the parent)
    while stack:  # preorder: a node, its lesser subtree, its greater subtree
        node, parent, side = stack.pop()
        node_id = len(columns["start"])
        if parent >= 0:
            columns[side][parent] = node_id
        leaf = node.split_dim < 0
        values = (node.start_idx, node.end_idx, -1 if leaf else node.split_dim, np.nan if leaf else node.split, -1, -1)
        for key, value in zip(columns, values):
            columns[key].append(value)
        if not leaf:
            stack += [(node.greater, node_id, "right"), (node.lesser, node_id, "left")]
    order = np.array(tree.indices, dtype=np.int64)
    for start, stop, axis in zip(columns["start"], columns["stop"], columns["axis"]):
        if axis < 0:  # a leaf's points in increasing index, as in the course's layout
            order[start:stop] = np.sort(order[start:stop])
    layout = {"order": order}
    layout.update(
        {key: np.array(values, dtype=float if key == "split" else np.int64) for key, values in columns.items()}
    )
    return layout
