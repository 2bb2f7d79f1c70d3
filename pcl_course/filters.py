"""Exercises: outlier removal and bilateral filtering."""

# What every solution needs (NumPy; SciPy's k-d tree is allowed; the course's input checks).
import numpy as np  # noqa: F401
from scipy.spatial import cKDTree  # noqa: F401

from pcl_course.validation import as_array, as_points, check_integer, check_positive, check_same_shape  # noqa: F401

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
    raise NotImplementedError("radius_outlier_removal: not implemented yet")


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
    raise NotImplementedError("statistical_outlier_removal: not implemented yet")


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
    raise NotImplementedError("bilateral_filter_image: not implemented yet")


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
    raise NotImplementedError("bilateral_filter_points: not implemented yet")


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
    raise NotImplementedError("joint_bilateral_upsample: not implemented yet")
