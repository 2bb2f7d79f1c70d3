"""Reference: outlier removal and bilateral filtering."""

import math

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_same_shape, check_scalar
from solutions._fast.grid import grid_is_usable, grid_radius_count
from solutions._fast.knn import kdtree, knn_mean_distance

__all__ = [
    "radius_outlier_removal",
    "statistical_outlier_removal",
    "bilateral_filter_image",
    "bilateral_filter_points",
    "joint_bilateral_upsample",
]


def radius_outlier_removal(points, radius, min_neighbors):
    """Keep mask of the radius outlier filter.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns.
    radius : float
        Neighbourhood radius, > 0; a neighbour at exactly ``radius`` counts.
    min_neighbors : int
        Fewest **other** points within ``radius`` that a kept point has, >= 0.

    Returns
    -------
    keep : ndarray of bool, shape (N,)
        True where the number of **other** points at distance ``<= radius``
        is at least ``min_neighbors``.

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``radius``; a negative ``min_neighbors``.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0, 0], [0.5, 0, 0], [1.0, 0, 0], [9.0, 0, 0]])
    >>> radius_outlier_removal(points, radius=0.5, min_neighbors=1)
    array([ True,  True,  True, False])
    """
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


def statistical_outlier_removal(points, k, std_ratio):
    """Keep mask of the statistical outlier filter.

    ``d_i`` = mean distance from point i to its ``k`` nearest **other**
    points (a duplicate of point i counts, at distance 0). ``mu`` = mean of
    ``d``, ``sigma`` = standard deviation of ``d`` with ``ddof=1``.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns.
    k : int
        Number of nearest **other** points, between 1 and N - 1.
    std_ratio : float
        How many standard deviations above the mean distance a kept point may
        lie (any finite number).

    Returns
    -------
    keep : ndarray of bool, shape (N,)
        True where ``d_i <= mu + std_ratio * sigma``. ``k`` must be between 1
        and N - 1.

    Raises
    ------
    ValueError
        Bad ``points``; ``k`` not between 1 and N - 1; a non-finite ``std_ratio``.
    """
    points = as_points(points)
    std_ratio = check_scalar(std_ratio, "std_ratio")
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
    """Bilateral filter of a grey-level image.

    For every pixel p: ``sum_q w(p, q) I_q / sum_q w(p, q)`` over the
    ``(2r + 1) x (2r + 1)`` window that lies inside the image (no padding),
    ``w = exp(-||p - q||^2 / (2 sigma_s^2)) * exp(-(I_p - I_q)^2 / (2 sigma_r^2))``,
    ``r = radius`` or ``ceil(2 * sigma_s)`` when None. Every output pixel is
    computed from the input image.

    Parameters
    ----------
    image : array_like, shape (H, W)
        A grey-level image.
    sigma_s : float
        Spatial standard deviation in pixels, > 0.
    sigma_r : float
        Range (intensity) standard deviation, > 0.
    radius : int, optional
        Half-width of the window in pixels, >= 0; ``ceil(2 * sigma_s)`` when None.

    Returns
    -------
    filtered : ndarray of float64, shape (H, W)

    Raises
    ------
    ValueError
        An ``image`` that is not 2-D or not finite; a non-positive ``sigma_s`` or
        ``sigma_r``; a negative ``radius``.
    """
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
    """Bilateral filter of a point cloud, moving points along their normals.

    Over the neighbours q with ``||q - p|| <= radius`` (p included),
    ``t = ||q - p||``, ``h = n_p . (q - p)``,
    ``w = exp(-t^2 / (2 sigma_s^2)) * exp(-h^2 / (2 sigma_r^2))``;
    ``p' = p + n_p * sum(w h) / sum(w)``, all from the input cloud.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    normals : array_like, shape (N, 3)
        Unit normals, one per point.
    radius : float
        Neighbourhood radius, > 0 (distance ``<= radius``, the point included).
    sigma_s : float
        Standard deviation of the distance weight, > 0.
    sigma_r : float
        Standard deviation of the height weight, > 0.

    Returns
    -------
    filtered : ndarray of float64, shape (N, 3)

    Raises
    ------
    ValueError
        Bad ``points``; ``normals`` of another shape or not finite; a
        non-positive ``radius``, ``sigma_s`` or ``sigma_r``.
    """
    points = as_points(points, columns=3)
    normals = as_points(normals, "normals", columns=3)
    check_same_shape(normals, "normals", points.shape, "the shape of points")
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
    """Joint bilateral upsampling of a sparse depth map guided by an image.

    ``sparse_depth`` (H, W) with 0 for missing; ``guide`` (H, W) or
    (H, W, C). Each output pixel p is ``sum_q w d_q / sum_q w`` over the valid
    pixels q (``d_q > 0``) of its window inside the image, with
    ``w = exp(-||p - q||^2 / (2 sigma_s^2)) * exp(-||g_p - g_q||_2^2 / (2 sigma_r^2))``;
    0 where the window holds no valid pixel.

    Parameters
    ----------
    sparse_depth : array_like, shape (H, W)
        Depths, 0 where missing.
    guide : array_like, shape (H, W) or (H, W, C)
        The guide image (grey or colour).
    sigma_s : float
        Spatial standard deviation in pixels, > 0.
    sigma_r : float
        Standard deviation of the guide difference, > 0.
    radius : int
        Half-width of the window in pixels, >= 0.

    Returns
    -------
    dense_depth : ndarray of float64, shape (H, W)

    Raises
    ------
    ValueError
        A ``sparse_depth`` that is not 2-D or not finite; a ``guide`` whose first
        two dimensions differ from it; a non-positive ``sigma_s`` or ``sigma_r``;
        a negative ``radius``.
    """
    depth = as_array(sparse_depth, "sparse_depth", ndim=2)
    guide = as_array(guide, "guide", ndim=(2, 3))
    check_same_shape(guide, "guide", depth.shape, "the height and width of sparse_depth", leading=True)
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
