"""Reference: evaluation metrics."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_array, as_points, check_same_shape

__all__ = ["chamfer_distance", "depth_metrics"]


def chamfer_distance(a, b):
    """Chamfer distance between two point sets.

    ``mean_{x in a} min_{y in b} ||x - y||^2 + mean_{y in b} min_{x in a} ||x - y||^2``
    (squared distances, both directions summed, no 1/2).

    Parameters
    ----------
    a : array_like, shape (N, D), D >= 3
        A non-empty point set (xyz in the first three columns).
    b : array_like, shape (M, D), D >= 3
        Another non-empty point set.

    Returns
    -------
    distance : float

    Raises
    ------
    ValueError
        An empty, non-2-D or non-finite ``a`` or ``b``.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    >>> b = np.array([[0.0, 2.0, 0]])
    >>> chamfer_distance(a, b)  # (4 + 5) / 2 from a, 4 from b
    8.5
    """
    a = as_points(a, "a", allow_empty=False)[:, :3]
    b = as_points(b, "b", allow_empty=False)[:, :3]
    a_to_b = cKDTree(b).query(a)[0]
    b_to_a = cKDTree(a).query(b)[0]
    return float(np.mean(a_to_b**2) + np.mean(b_to_a**2))


def depth_metrics(pred, gt):
    """KITTI depth-completion metrics.

    Over the pixels with ``gt > 0``, depths in metres.

    Parameters
    ----------
    pred : array_like, shape (H, W)
        Predicted depths in metres, > 0 where ``gt > 0``.
    gt : array_like, shape (H, W)
        Ground-truth depths in metres, 0 where unknown.

    Returns
    -------
    metrics : dict
        ``rmse`` and ``mae`` in millimetres, ``irmse`` and ``imae`` in 1/km.

    Raises
    ------
    ValueError
        ``pred`` and ``gt`` of different shapes, non-finite values, no pixel with
        ``gt > 0``, or ``pred <= 0`` where ``gt > 0``.

    Examples
    --------
    >>> import numpy as np
    >>> gt = np.array([[10.0, 0.0], [20.0, 40.0]])
    >>> metrics = depth_metrics(gt + 0.5, gt)  # 0.5 m too far on the 3 valid pixels
    >>> round(metrics["rmse"], 6), round(metrics["mae"], 6)
    (500.0, 500.0)
    """
    pred = as_array(pred, "pred", ndim=2)
    gt = as_array(gt, "gt", ndim=2)
    check_same_shape(pred, "pred", gt.shape, "the shape of gt")
    valid = gt > 0
    if not valid.any():
        raise ValueError("gt has no valid pixel (gt > 0)")
    if np.any(pred[valid] <= 0):
        raise ValueError("pred must be positive wherever gt > 0 (its inverse is taken)")
    error_mm = (pred[valid] - gt[valid]) * 1000.0
    # Inverse depth in 1/km: 1 / (d / 1000) = 1000 / d for d in metres.
    inverse_error = 1000.0 / pred[valid] - 1000.0 / gt[valid]
    return {
        "rmse": float(np.sqrt(np.mean(error_mm**2))),
        "mae": float(np.mean(np.abs(error_mm))),
        "irmse": float(np.sqrt(np.mean(inverse_error**2))),
        "imae": float(np.mean(np.abs(inverse_error))),
    }
