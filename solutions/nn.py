"""Reference: nearest-neighbour search with a BST, a k-d tree and an octree.

The trees and their searches are compiled (``solutions/_fast/kdtree.py`` and
``octree.py``); queries run on every core. The docstrings are the stubs'
(``pcl_course/nn.py``), which state the contract.
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from pcl_course import nn as _contract
from pcl_course.validation import (
    as_array,
    as_points,
    check_bst,
    check_integer,
    check_kdtree,
    check_octree,
    check_radius,
    check_scalar,
)
from solutions._fast import bst as _bst
from solutions._fast import kdtree as _kdtree
from solutions._fast import octree as _octree
from solutions._fast.order import morton_order
from solutions._fast.rows import place_rows
from solutions._fast.threads import in_threads, map_slices, slice_bounds, threshold, worker_count

# Above this many queries, a search takes them in an order that keeps neighbours together
# (_search_order): consecutive queries then walk the same nodes, which stay in cache.
_LOCALITY_QUERIES = 20_000
# Queries per slice of a search on every core.
_QUERY_GRAIN = 1024

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


def _documented(function):
    # The stub's text; none where this file is itself the module (a reference uploaded as a
    # student's pcl_course/, the project's tests): the contract is then half imported.
    function.__doc__ = getattr(_contract, function.__name__, function).__doc__
    return function


# -- result set and binary search tree --------------------------------------------------------


@_documented
def knn_result_set(distances, indices, k):
    distances = as_array(distances, "distances", ndim=1)
    if np.any(distances < 0):
        raise ValueError("distances must be >= 0")
    values = as_array(indices, "indices", ndim=1)
    if values.shape != distances.shape or not np.array_equal(values, np.round(values)):
        raise ValueError(f"indices must be {len(distances)} integers, one per distance, got shape {values.shape}")
    values = values.astype(np.int64)
    if len(np.unique(values)) != len(values):
        raise ValueError("indices must be distinct")
    k = check_integer(k, "k", low=1)
    return _bst.result_set(distances, values, k)


@_documented
def bst_build(keys):
    keys = as_array(keys, "keys", ndim=1)
    return _bst.insert_all(keys)


@_documented
def bst_knn(keys, left, right, query, k):
    keys = as_array(keys, "keys", ndim=1)
    left, right = check_bst(left, right, len(keys))
    query = check_scalar(query, "query")
    k = check_integer(k, "k", low=1, high=len(keys))
    return _bst.search(keys, left, right, query, k)


# -- k-d tree ----------------------------------------------------------------------------------

_KDTREE_KEYS = ("order", "start", "stop", "axis", "split", "left", "right")


def _cloud_and_queries(points, queries, min_columns):
    points = as_points(points, min_columns=min_columns)
    queries = as_points(queries, "queries", columns=points.shape[1])
    return np.ascontiguousarray(points), np.ascontiguousarray(queries)


@_documented
def kdtree_build(points, leaf_size=16):
    points = np.ascontiguousarray(as_points(points, min_columns=1))
    leaf_size = check_integer(leaf_size, "leaf_size", low=1)
    return _kdtree_in_threads(points, leaf_size)


_PARALLEL_BUILD_POINTS = 50_000


def _kdtree_in_threads(points, leaf_size):
    """The contract's tree, its top levels split here and the subtrees below built on every core.

    A subtree's node count depends on its size only (``node_count``), so
    every subtree's preorder ids are known before it is built.
    """
    n = len(points)
    nodes = _kdtree.node_count(n, leaf_size)
    order = np.arange(n)
    start, stop = np.empty(nodes, dtype=np.int64), np.empty(nodes, dtype=np.int64)
    axis, split = np.full(nodes, -1, dtype=np.int64), np.full(nodes, np.nan)
    left, right = np.full(nodes, -1, dtype=np.int64), np.full(nodes, -1, dtype=np.int64)
    arrays = (order, start, stop, axis, split, left, right)
    cores = worker_count()
    serial = n < threshold(_PARALLEL_BUILD_POINTS)
    subtrees, pending = [], [(0, n, 0, 0)]  # (lo, hi, depth, node id)
    while pending:
        lo, hi, depth, node = pending.pop()
        if serial or hi - lo <= leaf_size or len(subtrees) + len(pending) >= 4 * cores - 1:
            subtrees.append((lo, hi, depth, node))
            continue
        start[node], stop[node], axis[node] = lo, hi, depth % points.shape[1]
        m, split[node] = _kdtree.split_node(points, order, lo, hi, axis[node], np.empty(hi - lo))
        left[node], right[node] = node + 1, node + 1 + _kdtree.node_count(m - lo, leaf_size)
        pending += [(m, hi, depth + 1, right[node]), (lo, m, depth + 1, left[node])]
    if len(subtrees) == 1:
        _kdtree.build_range(points, leaf_size, *arrays, *subtrees[0])
    else:
        with ThreadPoolExecutor(cores) as pool:
            jobs = [pool.submit(_kdtree.build_range, points, leaf_size, *arrays, *subtree) for subtree in subtrees]
            for job in jobs:
                job.result()
    return dict(zip(_KDTREE_KEYS, arrays))


def _kdtree_arrays(tree, points):
    """The tree's arrays for the kernels, and the size of a search's stack."""
    arrays = check_kdtree(tree, len(points), points.shape[1])
    return (*(arrays[key] for key in _KDTREE_KEYS), _kdtree.stack_size(arrays["left"], arrays["right"]))


@_documented
def kdtree_knn(tree, points, queries, k):
    points, queries = _cloud_and_queries(points, queries, 1)
    arrays = _kdtree_arrays(tree, points)
    k = check_integer(k, "k", low=1, high=len(points))
    return _knn_in_locality_order(_kdtree.knn, arrays, points, queries, k)


def _search_order(points, queries, order):
    """The order in which a search takes the queries: along a Z-order curve when there are many, so
    that consecutive queries walk the same nodes, which stay in cache (the answers are the same in
    any order); the tree's own ``order`` when the queries are its points (its leaves, one after the
    other: as local, and already there)."""
    n = len(queries)
    if n < threshold(_LOCALITY_QUERIES) or queries.shape[1] < 3:
        return np.arange(n)
    if _same_array(points, queries):
        return order
    return morton_order(queries[:, :3])


def _same_array(a, b):
    """Whether two arrays are views of the same memory with the same layout."""
    return (
        a.shape == b.shape
        and a.strides == b.strides
        and a.dtype == b.dtype
        and a.__array_interface__["data"][0] == b.__array_interface__["data"][0]
    )


def _knn_in_locality_order(kernel, arrays, points, queries, k):
    """Run a kNN kernel over every core, on the queries in Z-order when there are many.

    The kernel reads the queries in that order and writes each answer to its query's own row:
    neither the queries nor the answers are copied into Z-order and back (at 1e6 queries, putting
    the answers back took a sixth of the search)."""
    rows = _search_order(points, queries, arrays[0])
    indices = np.empty((len(queries), k), dtype=np.int64)
    distances = np.empty((len(queries), k))
    in_threads(kernel, len(queries), (*arrays, points, queries, rows, k), (indices, distances), grain=_QUERY_GRAIN)
    return indices, distances


def _csr_in_locality_order(rows_kernel, arrays, points, queries, r2):
    """A radius search into CSR arrays, on the queries in Z-order when there are many.

    Each thread computes the rows of its slice of queries, in the order searched, into arrays of
    its own; once every row's length is known, each thread copies its rows to their places in the
    final arrays. Neither the queries nor the answers are copied into Z-order and back as a whole
    (a concatenation of the slices, then a permutation of the rows, was a quarter of the search
    at 1e5 queries of 25 neighbours)."""
    n = len(queries)
    rows = _search_order(points, queries, arrays[0])
    parts = map_slices(rows_kernel, n, (*arrays, points, queries, rows, r2), grain=_QUERY_GRAIN)
    counts = np.empty(n, dtype=np.int64)
    counts[rows] = np.concatenate([part[0] for part in parts])
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    indices, distances = np.empty(indptr[-1], dtype=np.int64), np.empty(indptr[-1])
    by_first = dict(zip(slice_bounds(n, _QUERY_GRAIN)[:-1].tolist(), parts))

    def place(first, last):  # the slices of the search: each one's part, by its first query
        part = by_first[int(first)]
        place_rows(part[0], part[1], part[2], rows[first:last], indptr, indices, distances)

    map_slices(place, n, (), grain=_QUERY_GRAIN)
    return indptr, indices, distances


@_documented
def kdtree_radius(tree, points, queries, radius):
    points, queries = _cloud_and_queries(points, queries, 1)
    arrays = _kdtree_arrays(tree, points)
    radius = check_radius(radius)
    return _csr_in_locality_order(_kdtree.radius_rows, arrays, points, queries, radius**2)


# -- octree ------------------------------------------------------------------------------------

_OCTREE_KEYS = ("order", "start", "stop", "center", "extent", "children")


@_documented
def octree_build(points, leaf_size=8, min_extent=1e-3):
    xyz = np.ascontiguousarray(as_points(points)[:, :3])
    leaf_size = check_integer(leaf_size, "leaf_size", low=1)
    min_extent = check_scalar(min_extent, "min_extent", low=0, include_low=False)
    return dict(zip(_OCTREE_KEYS, _octree.build(xyz, leaf_size, min_extent)))


def _octree_inputs(tree, points, queries):
    points, queries = _cloud_and_queries(points, queries, 3)
    arrays = check_octree(tree, len(points))
    xyz = np.ascontiguousarray(points[:, :3])
    stack_size = _octree.stack_size(arrays["children"])
    return (*(arrays[key] for key in _OCTREE_KEYS), stack_size), xyz, np.ascontiguousarray(queries[:, :3])


@_documented
def octree_radius(tree, points, queries, radius):
    arrays, xyz, queries = _octree_inputs(tree, points, queries)
    radius = check_radius(radius)
    return _csr_in_locality_order(_octree.radius_rows, arrays, xyz, queries, radius**2)


@_documented
def octree_knn(tree, points, queries, k):
    arrays, xyz, queries = _octree_inputs(tree, points, queries)
    k = check_integer(k, "k", low=1, high=len(xyz))
    return _knn_in_locality_order(_octree.knn, arrays, xyz, queries, k)
