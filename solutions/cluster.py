"""Reference: k-means (Lloyd's algorithm), the k-means++ seeding and DBSCAN. The docstrings are the
stubs' (``pcl_course/cluster.py``: the contract)."""

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from pcl_course import cluster as _contract
from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_rng
from solutions._fast.lloyd import assign, cluster_sums

__all__ = ["kmeans", "kmeans_plusplus", "dbscan"]


def _documented(function):
    # The stub's text; none where this file is itself the module (a reference uploaded as a
    # student's pcl_course/, the project's tests): the contract is then half imported.
    function.__doc__ = getattr(_contract, function.__name__, function).__doc__
    return function


def _squared_distances(points, centers):
    """Squared distances ``s`` (N, K) of every point to every centre, summed over the columns in
    increasing order (the contract's order: a tie is a tie in every correct submission)."""
    s = np.zeros((len(points), len(centers)))
    for j in range(points.shape[1]):
        s += np.square(points[:, j, None] - centers[None, :, j])
    return s


def _means(points, labels, centers):
    """Each centre moved to the mean of its points (summed in index order); an empty one kept."""
    sums, counts = cluster_sums(points, labels, len(centers))
    filled = counts > 0
    moved = centers.copy()
    moved[filled] = sums[filled] / counts[filled, None]
    return moved


@_documented
def kmeans(points, init_centers, max_iter=300):
    points = np.ascontiguousarray(as_points(points, min_columns=1, allow_empty=False))
    centers = as_array(init_centers, "init_centers", ndim=2)
    if centers.shape[1] != points.shape[1]:
        raise ValueError(f"init_centers must have {points.shape[1]} columns (the width of points), got {centers.shape}")
    if not 1 <= len(centers) <= len(points):
        raise ValueError(f"init_centers must hold 1 to {len(points)} centres (N), got {len(centers)}")
    max_iter = check_integer(max_iter, "max_iter", low=1)
    centers = np.ascontiguousarray(centers, dtype=np.float64).copy()
    columns = np.ascontiguousarray(points.T)  # the assignment reads a column at a time
    labels, previous = np.empty(len(points), dtype=np.int64), np.empty(len(points), dtype=np.int64)
    distances = np.empty(len(points))
    inertia = []
    for t in range(1, max_iter + 1):
        assign(columns, centers, labels, distances)
        inertia.append(float(distances.sum()))
        if t > 1 and np.array_equal(labels, previous):
            break
        centers = _means(points, labels, centers)
        labels, previous = previous, labels
        if t == max_iter:
            assign(columns, centers, labels, distances)
    return labels, centers, np.array(inertia), len(inertia)


@_documented
def kmeans_plusplus(points, n_clusters, rng=None):
    points = as_points(points, min_columns=1, allow_empty=False)
    distinct = len(np.unique(points, axis=0))
    n_clusters = check_integer(n_clusters, "n_clusters", low=1)
    if n_clusters > distinct:
        raise ValueError(f"n_clusters must be at most the number of distinct points ({distinct}), got {n_clusters}")
    rng = check_rng(rng)
    chosen = [int(rng.integers(len(points)))]
    nearest = _squared_distances(points, points[chosen])[:, 0]
    for _ in range(n_clusters - 1):
        cumulative = np.cumsum(nearest)
        chosen.append(int(np.searchsorted(cumulative, rng.random() * cumulative[-1], side="right")))
        nearest = np.minimum(nearest, _squared_distances(points, points[chosen[-1:]])[:, 0])
    return np.array(chosen, dtype=np.int64)


def _neighbour_pairs(points, eps):
    """Every pair ``(i, j)``, i < j, with ``s(x_i, x_j) <= eps ** 2``: shape (P, 2), int64.

    A k-d tree proposes the pairs within a slightly larger radius (its own
    rounding never decides); the contract's ``s``, summed over the columns in
    increasing order, decides which are neighbours.
    """
    if len(points) < 2:
        return np.empty((0, 2), dtype=np.int64)
    reach = eps * (1 + 1e-9)
    pairs = cKDTree(points).query_pairs(reach, output_type="ndarray").astype(np.int64).reshape(-1, 2)
    s = np.zeros(len(pairs))
    for j in range(points.shape[1]):
        s += np.square(points[pairs[:, 0], j] - points[pairs[:, 1], j])
    return pairs[s <= eps * eps]


def _numbered_by_smallest_member(component, members, n):
    """Each member's component renumbered 0, 1, ... by the component's smallest member index."""
    smallest = np.full(component.max(initial=-1) + 1, n, dtype=np.int64)
    np.minimum.at(smallest, component[members], members)
    present = np.flatnonzero(smallest < n)
    rank = np.empty(len(smallest), dtype=np.int64)
    rank[present[np.argsort(smallest[present], kind="stable")]] = np.arange(len(present))
    return rank[component[members]]


@_documented
def dbscan(points, eps, min_samples):
    points = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    n = len(points)
    pairs = _neighbour_pairs(points, eps)
    is_core = 1 + np.bincount(pairs.ravel(), minlength=n) >= min_samples  # itself included
    labels = np.full(n, -1, dtype=np.int64)
    cores = np.flatnonzero(is_core)
    if len(cores) == 0:
        return labels, is_core
    linked = pairs[is_core[pairs[:, 0]] & is_core[pairs[:, 1]]]
    graph = coo_array((np.ones(len(linked)), (linked[:, 0], linked[:, 1])), shape=(n, n))
    _, component = connected_components(graph, directed=False)
    labels[cores] = _numbered_by_smallest_member(component, cores, n)
    # A border point takes the smallest label among its core neighbours' clusters.
    unset = np.iinfo(np.int64).max
    border = np.full(n, unset, dtype=np.int64)
    for core_end, other_end in ((0, 1), (1, 0)):
        reach = is_core[pairs[:, core_end]] & ~is_core[pairs[:, other_end]]
        np.minimum.at(border, pairs[reach, other_end], labels[pairs[reach, core_end]])
    labels[border < unset] = border[border < unset]
    return labels, is_core
