"""Reference: k-means (Lloyd's algorithm), the k-means++ seeding, DBSCAN and Euclidean cluster
extraction. The docstrings are the stubs' (``pcl_course/cluster.py``: the contract)."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course import cluster as _contract
from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_rng
from solutions._fast.density import density_clusters
from solutions._fast.lloyd import assign, cluster_sums

__all__ = ["kmeans", "kmeans_plusplus", "dbscan", "euclidean_clusters"]


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


def _candidate_pairs(points, eps):
    """Every pair ``(i, j)``, i < j, a k-d tree finds within a slightly larger radius than ``eps``
    (its own rounding never decides: :func:`density_clusters` keeps those with the contract's
    ``s <= eps ** 2``): shape (P, 2), int64."""
    if len(points) < 2:
        return np.empty((0, 2), dtype=np.int64)
    pairs = cKDTree(points).query_pairs(eps * (1 + 1e-9), output_type="ndarray")
    return np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)


@_documented
def dbscan(points, eps, min_samples):
    points = np.ascontiguousarray(as_points(points, min_columns=1))
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    return density_clusters(points, _candidate_pairs(points, eps), eps * eps, min_samples)


@_documented
def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    points = np.ascontiguousarray(as_points(points, min_columns=1))
    tolerance = check_positive(tolerance, "tolerance")
    min_size = check_integer(min_size, "min_size", low=1)
    if max_size is not None:
        max_size = check_integer(max_size, "max_size", low=min_size)
    # Every point core: the components, numbered by their smallest index.
    components, _ = density_clusters(points, _candidate_pairs(points, tolerance), tolerance * tolerance, 1)
    sizes = np.bincount(components, minlength=0)
    kept = (sizes >= min_size) & (sizes <= (len(points) if max_size is None else max_size))
    order = np.flatnonzero(kept)[np.argsort(-sizes[kept], kind="stable")]  # largest first, then smallest index
    renumbered = np.full(len(sizes), -1, dtype=np.int64)
    renumbered[order] = np.arange(len(order))
    return renumbered[components]
