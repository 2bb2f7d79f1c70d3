"""Reference: outlier removal and bilateral filtering."""

import math
import numbers

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_array, as_points, check_integer, check_positive
from solutions._neighbors import grid_is_usable, grid_radius_count, kdtree, knn_mean_distance


def radius_outlier_removal(points, radius, min_neighbors):
    points = as_points(points)
    radius = check_positive(radius, "radius")
    min_neighbors = check_integer(min_neighbors, "min_neighbors", low=0)
    if len(points) == 0:
        return np.zeros(0, dtype=bool)
    xyz = points[:, :3]
    # Both count distances <= radius, the point itself included.
    if grid_is_usable(xyz, radius):
        within = grid_radius_count(xyz, radius)
    else:  # a radius tiny against the cloud's extent: too many cells for a grid
        within = kdtree(xyz).query_ball_point(xyz, r=radius, return_length=True, workers=-1)
    return within - 1 >= min_neighbors


def _check_real(value, name):
    if not isinstance(value, numbers.Real) or isinstance(value, bool) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def statistical_outlier_removal(points, k, std_ratio):
    points = as_points(points)
    std_ratio = _check_real(std_ratio, "std_ratio")
    if len(points) == 0:
        check_integer(k, "k", low=1)
        return np.zeros(0, dtype=bool)
    k = check_integer(k, "k", low=1, high=len(points) - 1)
    mean_distance = knn_mean_distance(points[:, :3], k)
    threshold = mean_distance.mean() + std_ratio * mean_distance.std(ddof=1)
    return mean_distance <= threshold


def _window_offsets(radius):
    steps = np.arange(-radius, radius + 1)
    return [(dy, dx) for dy in steps for dx in steps]


def _shifted(array, dy, dx):
    """Views pairing each pixel p with q = p + (dy, dx), where both are inside."""
    h, w = array.shape[:2]
    p = (slice(max(0, -dy), h - max(0, dy)), slice(max(0, -dx), w - max(0, dx)))
    q = (slice(max(0, dy), h - max(0, -dy)), slice(max(0, dx), w - max(0, -dx)))
    return p, q


def bilateral_filter_image(image, sigma_s, sigma_r, radius=None):
    image = as_array(image, "image", ndim=2)
    sigma_s = check_positive(sigma_s, "sigma_s")
    sigma_r = check_positive(sigma_r, "sigma_r")
    radius = math.ceil(2 * sigma_s) if radius is None else check_integer(radius, "radius", low=0)
    numerator = np.zeros_like(image)
    denominator = np.zeros_like(image)
    # Loop over the window's offsets, vectorised over pixels: every output
    # reads only the input image, and pixels outside the image never count.
    for dy, dx in _window_offsets(radius):
        p, q = _shifted(image, dy, dx)
        spatial = math.exp(-(dy * dy + dx * dx) / (2 * sigma_s**2))
        weight = spatial * np.exp(-((image[p] - image[q]) ** 2) / (2 * sigma_r**2))
        numerator[p] += weight * image[q]
        denominator[p] += weight
    return numerator / denominator


def bilateral_filter_points(points, normals, radius, sigma_s, sigma_r):
    points = as_points(points, columns=3)
    normals = as_points(normals, "normals", columns=3)
    if normals.shape != points.shape:
        raise ValueError(f"normals must have the shape of points {points.shape}, got {normals.shape}")
    radius = check_positive(radius, "radius")
    sigma_s = check_positive(sigma_s, "sigma_s")
    sigma_r = check_positive(sigma_r, "sigma_r")
    n = len(points)
    if n == 0:
        return np.empty((0, 3))
    lists = cKDTree(points).query_ball_point(points, r=radius)
    counts = np.fromiter((len(row) for row in lists), dtype=np.int64, count=n)
    owners = np.repeat(np.arange(n), counts)
    members = np.concatenate(lists).astype(np.int64)
    offsets = points[members] - points[owners]
    t2 = np.sum(offsets**2, axis=1)
    h = np.sum(offsets * normals[owners], axis=1)
    w = np.exp(-t2 / (2 * sigma_s**2)) * np.exp(-(h**2) / (2 * sigma_r**2))
    shift = np.bincount(owners, w * h, minlength=n) / np.bincount(owners, w, minlength=n)
    return points + normals * shift[:, None]


def joint_bilateral_upsample(sparse_depth, guide, sigma_s, sigma_r, radius):
    depth = as_array(sparse_depth, "sparse_depth", ndim=2)
    guide = as_array(guide, "guide", ndim=(2, 3))
    if guide.shape[:2] != depth.shape:
        raise ValueError(f"guide must have the height and width of sparse_depth {depth.shape}, got {guide.shape}")
    if guide.ndim == 2:
        guide = guide[:, :, None]
    sigma_s = check_positive(sigma_s, "sigma_s")
    sigma_r = check_positive(sigma_r, "sigma_r")
    radius = check_integer(radius, "radius", low=0)
    valid = (depth > 0).astype(np.float64)
    numerator = np.zeros_like(depth)
    denominator = np.zeros_like(depth)
    for dy, dx in _window_offsets(radius):
        p, q = _shifted(depth, dy, dx)
        spatial = math.exp(-(dy * dy + dx * dx) / (2 * sigma_s**2))
        range_weight = np.exp(-np.sum((guide[p] - guide[q]) ** 2, axis=2) / (2 * sigma_r**2))
        weight = spatial * range_weight * valid[q]
        numerator[p] += weight * depth[q]
        denominator[p] += weight
    return np.divide(numerator, denominator, out=np.zeros_like(depth), where=denominator > 0)
