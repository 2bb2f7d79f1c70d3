"""Exercises: outlier removal and bilateral filtering."""


def radius_outlier_removal(points, radius, min_neighbors):
    """Keep mask of the radius outlier filter.

    Returns
    -------
    keep : ndarray of bool, shape (N,)
        True where the number of **other** points at distance ``<= radius``
        is at least ``min_neighbors``.
    """
    raise NotImplementedError("radius_outlier_removal: not implemented yet")


def statistical_outlier_removal(points, k, std_ratio):
    """Keep mask of the statistical outlier filter.

    ``d_i`` = mean distance from point i to its ``k`` nearest **other**
    points (a duplicate of point i counts, at distance 0). ``mu`` = mean of
    ``d``, ``sigma`` = standard deviation of ``d`` with ``ddof=1``.

    Returns
    -------
    keep : ndarray of bool, shape (N,)
        True where ``d_i <= mu + std_ratio * sigma``. ``k`` must be between 1
        and N - 1.
    """
    raise NotImplementedError("statistical_outlier_removal: not implemented yet")


def bilateral_filter_image(image, sigma_s, sigma_r, radius=None):
    """Bilateral filter of a grey-level image.

    For every pixel p: ``sum_q w(p, q) I_q / sum_q w(p, q)`` over the
    ``(2r + 1) x (2r + 1)`` window that lies inside the image (no padding),
    ``w = exp(-||p - q||^2 / (2 sigma_s^2)) * exp(-(I_p - I_q)^2 / (2 sigma_r^2))``,
    ``r = radius`` or ``ceil(2 * sigma_s)`` when None. Every output pixel is
    computed from the input image.

    Returns
    -------
    filtered : ndarray of float64, shape (H, W)
    """
    raise NotImplementedError("bilateral_filter_image: not implemented yet")


def bilateral_filter_points(points, normals, radius, sigma_s, sigma_r):
    """Bilateral filter of a point cloud, moving points along their normals.

    Over the neighbours q with ``||q - p|| <= radius`` (p included),
    ``t = ||q - p||``, ``h = n_p . (q - p)``,
    ``w = exp(-t^2 / (2 sigma_s^2)) * exp(-h^2 / (2 sigma_r^2))``;
    ``p' = p + n_p * sum(w h) / sum(w)``, all from the input cloud.

    Returns
    -------
    filtered : ndarray of float64, shape (N, 3)
    """
    raise NotImplementedError("bilateral_filter_points: not implemented yet")


def joint_bilateral_upsample(sparse_depth, guide, sigma_s, sigma_r, radius):
    """Joint bilateral upsampling of a sparse depth map guided by an image.

    ``sparse_depth`` (H, W) with 0 for missing; ``guide`` (H, W) or
    (H, W, C). Each output pixel p is ``sum_q w d_q / sum_q w`` over the valid
    pixels q (``d_q > 0``) of its window inside the image, with
    ``w = exp(-||p - q||^2 / (2 sigma_s^2)) * exp(-||g_p - g_q||_2^2 / (2 sigma_r^2))``;
    0 where the window holds no valid pixel.

    Returns
    -------
    dense_depth : ndarray of float64, shape (H, W)
    """
    raise NotImplementedError("joint_bilateral_upsample: not implemented yet")
