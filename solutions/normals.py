"""Reference: plane fitting and surface normal estimation."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_array, as_points, check_integer, check_positive


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


def _padded_covariances(points, indices, valid):
    """Covariances of neighbourhoods given as padded index arrays ``(N, K)``."""
    counts = valid.sum(axis=1)
    neighbours = points[indices] * valid[..., None]
    means = neighbours.sum(axis=1) / np.maximum(counts, 1)[:, None]
    # Two-pass: centre on the neighbourhood's own mean before multiplying, so
    # that coordinates far from the origin do not cancel catastrophically.
    centred = (points[indices] - means[:, None, :]) * valid[..., None]
    return np.einsum("nki,nkj->nij", centred, centred) / np.maximum(counts, 1)[:, None, None], counts


def _ragged_covariances(points, neighbour_lists):
    """Covariances of neighbourhoods given as one index list per point."""
    n = len(points)
    counts = np.fromiter((len(row) for row in neighbour_lists), dtype=np.int64, count=n)
    owners = np.repeat(np.arange(n), counts)
    members = np.concatenate(neighbour_lists).astype(np.int64) if n else np.empty(0, np.int64)
    sums = np.stack([np.bincount(owners, points[members, axis], minlength=n) for axis in range(3)], axis=1)
    means = sums / np.maximum(counts, 1)[:, None]
    centred = points[members] - means[owners]
    covariances = np.empty((n, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            entry = np.bincount(owners, centred[:, i] * centred[:, j], minlength=n) / np.maximum(counts, 1)
            covariances[:, i, j] = covariances[:, j, i] = entry
    return covariances, counts


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

    tree = cKDTree(points)
    if radius is None or k is not None:
        kk = min(k, n)
        distances, indices = tree.query(points, k=kk)
        distances = distances.reshape(n, kk)
        indices = indices.reshape(n, kk)
        valid = np.ones_like(indices, dtype=bool) if radius is None else distances <= radius
        covariances, counts = _padded_covariances(points, indices, valid)
    else:
        covariances, counts = _ragged_covariances(points, tree.query_ball_point(points, r=radius))

    eigenvalues, eigenvectors = np.linalg.eigh(covariances)
    normals = eigenvectors[:, :, 0].copy()
    trace = eigenvalues.sum(axis=1)
    curvature = np.divide(eigenvalues[:, 0], trace, out=np.zeros(n), where=trace > 0)
    curvature = np.clip(curvature, 0.0, None)  # eigh may return -1e-17 for a flat patch
    too_few = counts < 3
    normals[too_few] = np.nan
    curvature[too_few] = np.nan
    if viewpoint is not None:
        flip = np.einsum("ij,ij->i", normals, viewpoint - points) < 0
        normals[flip] *= -1.0
    return normals, curvature
