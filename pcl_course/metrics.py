"""Exercises: evaluation metrics."""

# What every solution needs (NumPy; SciPy's k-d tree is allowed; the course's input checks).
import numpy as np  # noqa: F401
from scipy.spatial import cKDTree  # noqa: F401

from pcl_course.validation import as_array, as_points, check_same_shape  # noqa: F401

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
    raise NotImplementedError("chamfer_distance: not implemented yet")


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
    raise NotImplementedError("depth_metrics: not implemented yet")
