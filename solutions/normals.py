"""Reference: plane fitting and surface normal estimation."""

import numpy as np

from pcl_course.validation import as_array, as_points, check_integer, check_positive
from solutions._kernels import normals_from_neighbourhoods
from solutions._neighbors import kdtree, knn_normals


def fit_plane(points, weights=None):
    points = as_points(points, columns=3, allow_empty=False)
    if weights is None:
        weights = np.ones(len(points))
    weights = as_array(weights, "weights", ndim=1)
    if weights.shape != (len(points),):
        raise ValueError(f"weights must have shape ({len(points)},), got {weights.shape}")
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
        if viewpoint.shape != (3,):
            raise ValueError(f"viewpoint must have shape (3,), got {viewpoint.shape}")
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
