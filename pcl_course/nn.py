"""Exercises of lecture 2: nearest-neighbour search with a BST, a k-d tree and an octree.

The rules of this module (the course's contract, on top of the general rules):

Points and distances
    For the BST, the keys are scalars. For the k-d tree every column of
    ``points`` (N, D), D >= 1, is a coordinate. The octree uses the first
    three columns (D >= 3). Everything is computed in float64 (float32 input,
    as read from KITTI, is converted). The squared distance of a point p to a
    query q is ``s = sum_j (p_j - q_j) ** 2`` over the coordinate columns, in
    increasing j; the reported distance is ``sqrt(s)``.

Order and ties
    Neighbours are ordered by ``(s, index)``: **ties go to the lower index**,
    at the k-th place too. Radius membership is inclusive: ``s <= radius ** 2``.

Outputs
    kNN: ``(indices (M, k) int64, distances (M, k) float64)``, each row
    ascending. Radius: CSR ``(indptr (M + 1,) int64, indices (nnz,) int64,
    distances (nnz,) float64)``; row i is ``indices[indptr[i]:indptr[i + 1]]``,
    ascending by ``(s, index)``.

Arguments
    ``k`` is an integer with ``1 <= k <= N``. ``radius`` is finite and
    ``>= 0``: 0 is allowed and finds the exact duplicates of the query (an
    exception to lecture 1, where radii are > 0). ``queries`` is (M, D) with
    the width of ``points``; M = 0 gives empty results. Anything else is a
    ``ValueError`` naming the argument.

Trees
    A tree is exactly the dict its build returns, checked by
    :func:`pcl_course.validation.check_kdtree` or ``check_octree`` (structure
    only). A search works on any valid tree, not only its own module's, and
    **reads the points of a node only if the stated rule reaches that node**.
    It may prune more than the rule (a tighter test on a node's cell; for
    the k-d tree, best-bin-first order), never less: the grader checks this
    with trees whose unreached nodes hold decoys (the book proves why every
    search this contract allows passes). Do not check that the points lie in
    their nodes' cells.

Forbidden here
    ``scipy.spatial``, scikit-learn, Open3D, pykdtree, pynanoflann, faiss,
    hnswlib, annoy and the course's own ``pcl_course.neighbors``: this
    lecture is about writing the search. NumPy (and numba) are yours.
"""

# What every solution needs (NumPy; the course's input checks).
import numpy as np  # noqa: F401

from pcl_course.validation import (  # noqa: F401
    as_array,
    as_points,
    check_integer,
    check_kdtree,
    check_octree,
    check_radius,
)

__all__ = [
    "knn_result_set",
    "bst_build",
    "bst_knn",
    "kdtree_build",
    "kdtree_knn",
    "kdtree_radius",
    "octree_build",
    "octree_radius",
    "octree_knn",
]


def knn_result_set(distances, indices, k):
    """Offer candidates, one at a time, to a k-nearest-neighbour result set.

    The candidates ``(distances[j], indices[j])``, j = 0, 1, ..., n-1, are
    offered in turn to an empty set of capacity ``k``. A candidate enters if
    fewer than k are held, or if ``(distance, index)`` is lexicographically
    smaller than the worst held pair, which it then evicts.

    Parameters
    ----------
    distances : array_like, shape (n,)
        Candidate distances, finite and >= 0.
    indices : array_like of int, shape (n,)
        Candidate indices, distinct.
    k : int
        Capacity, >= 1 (it may exceed n).

    Returns
    -------
    indices : ndarray of int64, shape (min(k, n),)
        The held candidates, ascending by (distance, index); never padded.
    distances : ndarray of float64, shape (min(k, n),)
        Their distances.
    worst : ndarray of float64, shape (n,)
        The worst held distance after each offer: ``inf`` while fewer than k
        are held.

    Raises
    ------
    ValueError
        ``distances`` not 1-D, not finite or negative; ``indices`` not
        integers, of another length or repeated; ``k`` not an integer >= 1.

    Examples
    --------
    >>> idx, dist, worst = knn_result_set([3.0, 1.0, 2.0, 1.0], [10, 11, 12, 9], k=2)
    >>> idx, dist, worst
    (array([ 9, 11]), array([1., 1.]), array([inf,  3.,  2.,  1.]))
    """
    raise NotImplementedError("knn_result_set: not implemented yet")


def bst_build(keys):
    """Build a binary search tree by inserting ``keys[0], keys[1], ...`` in order.

    Node i holds ``keys[i]``; node 0 is the root. At node j a key goes left
    if ``key < keys[j]`` and right otherwise: **equal keys go right**.

    Parameters
    ----------
    keys : array_like, shape (N,)
        Finite keys.

    Returns
    -------
    left, right : ndarray of int64, shape (N,)
        The child node ids of each node, -1 for none. N = 0 gives two empty
        arrays.

    Raises
    ------
    ValueError
        ``keys`` not 1-D or not finite.

    Notes
    -----
    Sorted keys make a path of depth N - 1: the build must handle more
    than a thousand of them, so it cannot recurse once per level (Python's
    recursion limit is 1,000). The same holds for :func:`bst_knn`.

    Examples
    --------
    >>> left, right = bst_build([5.0, 3.0, 8.0, 5.0])
    >>> left, right  # the second 5.0 goes right of the root, then left of 8.0
    (array([ 1, -1,  3, -1]), array([ 2, -1, -1, -1]))
    """
    raise NotImplementedError("bst_build: not implemented yet")


def bst_knn(keys, left, right, query, k):
    """The ``k`` keys nearest a scalar query, searched in a binary search tree.

    The search starts at the root. At node j it offers ``(|keys[j] - query|,
    j)`` to a result set (as :func:`knn_result_set`), goes first to the
    query's side (``query < keys[j]``: left, else right), then to the other
    side if and only if ``|keys[j] - query| <= w``, where ``w`` is the worst
    held distance (inf until k are held).

    Parameters
    ----------
    keys : array_like, shape (N,)
        Finite keys.
    left, right : array_like of int, shape (N,)
        A tree on the N nodes rooted at node 0, as :func:`bst_build` returns:
        every other node is the child of exactly one node with a smaller id
        (the nodes are numbered in insertion order).
    query : float
        The query key, finite: a Python or NumPy scalar, or a 0-d array.
    k : int
        Number of neighbours, ``1 <= k <= N``.

    Returns
    -------
    indices : ndarray of int64, shape (k,)
        Node ids (= key indices), ascending by (distance, index).
    distances : ndarray of float64, shape (k,)
        ``|keys[i] - query|``.

    Raises
    ------
    ValueError
        Bad ``keys`` or ``query``; ``left``/``right`` that are not such a
        tree; ``k`` outside ``1..N``.

    Examples
    --------
    >>> keys = [5.0, 3.0, 8.0, 4.0]
    >>> left, right = bst_build(keys)
    >>> bst_knn(keys, left, right, 4.5, k=2)
    (array([0, 3]), array([0.5, 0.5]))
    """
    raise NotImplementedError("bst_knn: not implemented yet")


def kdtree_build(points, leaf_size=16):
    """Build a k-d tree by the median rule with round-robin axes.

    A node of n <= ``leaf_size`` points is a leaf; its points are in
    increasing index. Otherwise its axis is ``depth % D`` (the root has depth
    0); its points are ordered by (coordinate on the axis, index); the first
    ``m = ceil(n / 2)`` go to the left child and the rest to the right; and
    ``split = (c[m - 1] + c[m]) / 2`` of the ordered coordinates c (equal
    coordinates may lie on both sides). Nodes are numbered in preorder: a
    node, its left subtree, then its right subtree.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 1
        Finite coordinates.
    leaf_size : int, default 16
        Largest number of points of a leaf, >= 1.

    Returns
    -------
    tree : dict
        Exactly these keys, of M nodes (node 0 is the root):

        ``order`` : ndarray of int64, shape (N,)
            A permutation of the point indices; node i holds the points
            ``order[start[i]:stop[i]]``.
        ``start``, ``stop`` : ndarray of int64, shape (M,)
        ``axis`` : ndarray of int64, shape (M,)
            -1 at leaves.
        ``split`` : ndarray of float64, shape (M,)
            NaN at leaves.
        ``left``, ``right`` : ndarray of int64, shape (M,)
            Child node ids, -1 at leaves.

        N = 0 gives one empty leaf.

    Raises
    ------
    ValueError
        Bad ``points``; ``leaf_size`` not an integer >= 1.

    Examples
    --------
    >>> tree = kdtree_build([[0.0, 0.0], [4.0, 1.0], [2.0, 5.0]], leaf_size=1)
    >>> tree["axis"], tree["split"]
    (array([ 0,  1, -1, -1, -1]), array([3. , 2.5, nan, nan, nan]))
    >>> tree["left"], tree["right"]  # preorder: root, its left subtree (nodes 1-3), then node 4
    (array([ 1,  2, -1, -1, -1]), array([ 4,  3, -1, -1, -1]))
    >>> tree["order"], tree["start"], tree["stop"]
    (array([0, 2, 1]), array([0, 0, 0, 1, 2]), array([3, 2, 1, 2, 3]))
    """
    raise NotImplementedError("kdtree_build: not implemented yet")


def kdtree_knn(tree, points, queries, k):
    """The ``k`` nearest points of each query, searched in a k-d tree.

    Depth first from the root. At an internal node with ``a = axis[i]`` and
    ``s = split[i]``: first the child on the query's side (``q[a] <= s``:
    left, else right), then the other child if and only if
    ``(q[a] - s) ** 2 <= w2``, where ``w2`` is the worst held squared
    distance (inf until k are held). At a leaf, its points are offered in
    their order in the tree to a result set as in :func:`knn_result_set`.

    Parameters
    ----------
    tree : dict
        A k-d tree of ``points``, as :func:`kdtree_build` returns.
    points : array_like, shape (N, D)
        The cloud the tree was built on.
    queries : array_like, shape (M, D)
        Query points.
    k : int
        Number of neighbours, ``1 <= k <= N``.

    Returns
    -------
    indices : ndarray of int64, shape (M, k)
    distances : ndarray of float64, shape (M, k)
        Each row ascending by (squared distance, index).

    Raises
    ------
    ValueError
        Bad ``points`` or ``queries``; a ``tree`` that is not a k-d tree of
        N points; ``k`` outside ``1..N``.
    """
    raise NotImplementedError("kdtree_knn: not implemented yet")


def kdtree_radius(tree, points, queries, radius):
    """Every point within ``radius`` of each query, searched in a k-d tree.

    As :func:`kdtree_knn`, with the far child visited if and only if
    ``(q[a] - s) ** 2 <= radius ** 2``; a point of a reached leaf is kept if
    its squared distance is ``<= radius ** 2``.

    Parameters
    ----------
    tree : dict
        A k-d tree of ``points``, as :func:`kdtree_build` returns.
    points : array_like, shape (N, D)
        The cloud the tree was built on.
    queries : array_like, shape (M, D)
        Query points.
    radius : float
        Search radius, finite and >= 0 (inclusive).

    Returns
    -------
    indptr : ndarray of int64, shape (M + 1,)
    indices : ndarray of int64, shape (nnz,)
    distances : ndarray of float64, shape (nnz,)
        Row i is ``indices[indptr[i]:indptr[i + 1]]``, ascending by
        (squared distance, index).

    Raises
    ------
    ValueError
        Bad ``points`` or ``queries``; a ``tree`` that is not a k-d tree of
        N points; a negative or non-finite ``radius``.
    """
    raise NotImplementedError("kdtree_radius: not implemented yet")


def octree_build(points, leaf_size=8, min_extent=1e-3):
    """Build a bucket PR octree on the xyz columns.

    The root's cube is centred at ``(min + max) / 2`` per axis, with extent
    (half its side) ``max((max - min) / 2)`` over the three axes. A node of
    n <= ``leaf_size`` points, or of extent <= ``min_extent``, is a leaf; its
    points are in increasing index. Otherwise a point's child code is
    ``(x > cx) + 2 * (y > cy) + 4 * (z > cz)``, so a point on a centre plane
    goes to the lower side. A child's centre is ``c +- extent / 2`` per axis
    (+ where its bit is set) and its extent ``extent / 2``; empty children are
    not created. Nodes are numbered in preorder with children in code order,
    so the ranges of a node's children follow each other in code order.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns.
    leaf_size : int, default 8
        Largest number of points of a leaf (unless ``min_extent`` stops first), >= 1.
    min_extent : float, default 1e-3
        A node this small (half side, in the points' unit) is a leaf, > 0:
        duplicates cannot be split forever.

    Returns
    -------
    tree : dict
        Exactly these keys, of M nodes (node 0 is the root):

        ``order`` : ndarray of int64, shape (N,)
            A permutation of the point indices; node i holds the points
            ``order[start[i]:stop[i]]``.
        ``start``, ``stop`` : ndarray of int64, shape (M,)
        ``center`` : ndarray of float64, shape (M, 3)
        ``extent`` : ndarray of float64, shape (M,)
            Half the side of the node's cube.
        ``children`` : ndarray of int64, shape (M, 8)
            Child node id by code, -1 where absent; a leaf has none.

        N = 0 gives one empty leaf of centre 0 and extent 0.

    Raises
    ------
    ValueError
        Bad ``points``; ``leaf_size`` not an integer >= 1; ``min_extent``
        not finite and > 0.

    Examples
    --------
    >>> tree = octree_build([[0.0, 0, 0], [2.0, 2, 2], [1.0, 0, 0]], leaf_size=1)
    >>> tree["children"][0], tree["extent"]  # (1, 0, 0) lies on the root's plane x = 1: code 0
    (array([ 1, -1, -1, -1, -1, -1, -1,  4]), array([1.  , 0.5 , 0.25, 0.25, 0.5 ]))
    >>> tree["order"], tree["start"], tree["stop"]
    (array([0, 2, 1]), array([0, 0, 0, 1, 2]), array([3, 2, 1, 2, 3]))
    """
    raise NotImplementedError("octree_build: not implemented yet")


def octree_radius(tree, points, queries, radius):
    """Every point within ``radius`` of each query, searched in an octree.

    Per query, depth first from the root, at an octant of cube (c, e):

    1. If the ball contains the cube, ``sum_j (|q_j - c_j| + e) ** 2 <=
       radius ** 2``, every point of the octant is kept, without descending
       and without a distance test (the cube test decides: a point whose
       rounded squared distance exceeds ``radius ** 2`` by an ulp is kept).
    2. Else, at a leaf, each of its points is kept if its squared distance
       is ``<= radius ** 2``.
    3. Else, the children whose cube meets the ball,
       ``sum_j max(|q_j - c_j| - e, 0) ** 2 <= radius ** 2``, are visited in
       code order.

    The search does not end early, as :func:`octree_knn` does: it needs no
    such step, since when the ball lies strictly inside an octant no other
    octant meets it, and step 3 skips them all.

    Parameters
    ----------
    tree : dict
        An octree of ``points``, as :func:`octree_build` returns.
    points : array_like, shape (N, D), D >= 3
        The cloud the tree was built on.
    queries : array_like, shape (M, D)
        Query points, as wide as ``points`` (a cloud's own rows are queries);
        their xyz is used.
    radius : float
        Search radius, finite and >= 0 (inclusive).

    Returns
    -------
    indptr : ndarray of int64, shape (M + 1,)
    indices : ndarray of int64, shape (nnz,)
    distances : ndarray of float64, shape (nnz,)
        As :func:`kdtree_radius`; a point kept by step 1 has its true distance.

    Raises
    ------
    ValueError
        Bad ``points`` or ``queries``; a ``tree`` that is not an octree of
        N points; a negative or non-finite ``radius``.
    """
    raise NotImplementedError("octree_radius: not implemented yet")


def octree_knn(tree, points, queries, k):
    """The ``k`` nearest points of each query, searched in an octree with early termination.

    Per query, depth first from the root, with ``w2`` the worst held squared
    distance (inf until k are held) and ``w = sqrt(w2)``. At a leaf, its
    points are offered in their order in the tree (as
    :func:`knn_result_set`). At an internal octant, the child whose code the
    query has (if it exists) is visited first, then the other children in
    code order, each of them, the first included, if and only if its cube
    meets the ball, ``sum_j max(|q_j - c_j| - e, 0) ** 2 <= w2`` at that
    moment (the first always does when the query lies in the octant; an
    octant entered as another's neighbour need not hold it). **Early
    termination:** after an octant has been processed, if the ball lies
    strictly inside its cube, ``|q_j - c_j| + w < e`` for every j, the
    query's search ends.

    Parameters
    ----------
    tree : dict
        An octree of ``points``, as :func:`octree_build` returns.
    points : array_like, shape (N, D), D >= 3
        The cloud the tree was built on.
    queries : array_like, shape (M, D)
        Query points, as wide as ``points`` (a cloud's own rows are queries);
        their xyz is used.
    k : int
        Number of neighbours, ``1 <= k <= N``.

    Returns
    -------
    indices : ndarray of int64, shape (M, k)
    distances : ndarray of float64, shape (M, k)
        Each row ascending by (squared distance, index).

    Raises
    ------
    ValueError
        Bad ``points`` or ``queries``; a ``tree`` that is not an octree of
        N points; ``k`` outside ``1..N``.
    """
    raise NotImplementedError("octree_knn: not implemented yet")
