"""Known mistakes of ``pcl_course/metrics.py``: Chamfer distance, depth metrics."""

import numpy as np
from scipy.spatial import cKDTree

from grading.instructors.mistakes import Mistake, Model


def _nearest(a, b):
    """Distance from each point of ``a`` to its nearest point of ``b`` (xyz)."""
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    if a.ndim != 2 or b.ndim != 2 or a.shape[1] != b.shape[1] or not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise ValueError("not a valid pair of clouds")
    if len(a) == 0 or len(b) == 0:
        raise ValueError("empty cloud")
    return cKDTree(b).query(a)[0]


def chamfer(a, b, power=2, reduce=np.mean, directions=2, factor=1.0):
    forward = reduce(_nearest(a, b) ** power)
    backward = reduce(_nearest(b, a) ** power) if directions == 2 else 0.0
    return float(factor * (forward + backward))


CHAMFER_DISTANCE = Model(
    truth=lambda a, b: chamfer(a, b),
    mistakes=(
        Mistake(
            "halved",
            "your distance is half the contract's: sum the two directions' means, without a factor 1/2",
            lambda a, b: chamfer(a, b, factor=0.5),
        ),
        Mistake(
            "max_not_mean",
            "average the squared nearest distances (np.mean): the largest one (a Hausdorff-like distance) "
            "is another measure",
            lambda a, b: chamfer(a, b, reduce=np.max),
        ),
        Mistake(
            "one_direction",
            "add both directions: the mean over a of the nearest distance to b, plus the mean over b of the "
            "nearest distance to a",
            lambda a, b: chamfer(a, b, directions=1),
        ),
        Mistake(
            "unsquared",
            "the Chamfer distance averages SQUARED nearest distances: square them before the mean",
            lambda a, b: chamfer(a, b, power=1),
        ),
    ),
)


def depth(pred, gt, scale=1000.0, inverse_scale=1000.0, valid_from="gt"):
    pred, gt = np.array(pred, dtype=float), np.array(gt, dtype=float)
    if pred.shape != gt.shape or not (np.isfinite(pred).all() and np.isfinite(gt).all()):
        raise ValueError("not a valid pair of depth maps")
    valid = (gt if valid_from == "gt" else pred) > 0
    if not valid.any() or np.any(pred[gt > 0] <= 0):
        raise ValueError("no valid pixel, or a non-positive prediction")
    error = (pred[valid] - gt[valid]) * scale
    with np.errstate(divide="ignore"):
        inverse = (1.0 / pred[valid] - 1.0 / gt[valid]) * inverse_scale
    return {
        "rmse": float(np.sqrt(np.mean(error**2))),
        "mae": float(np.mean(np.abs(error))),
        "irmse": float(np.sqrt(np.mean(inverse**2))),
        "imae": float(np.mean(np.abs(inverse))),
    }


def _depth_same(a, b, arguments):
    if not isinstance(a, dict) or not isinstance(b, dict) or not set(b) <= set(a):
        return False
    return all(np.isclose(float(a[key]), float(b[key]), rtol=1e-6, atol=1e-9) for key in b)


DEPTH_METRICS = Model(
    truth=lambda pred, gt: depth(pred, gt),
    same=_depth_same,
    mistakes=(
        Mistake(
            "inverse_per_metre",
            "irmse and imae are in 1/km (the KITTI devkit's unit): multiply the inverse-depth errors, in 1/m, by 1000",
            lambda pred, gt: depth(pred, gt, inverse_scale=1.0),
        ),
        Mistake(
            "metres_not_millimetres",
            "rmse and mae are in millimetres: multiply the depth errors, in metres, by 1000",
            lambda pred, gt: depth(pred, gt, scale=1.0),
        ),
        Mistake(
            "pixels_with_a_prediction",
            "average over the pixels with ground truth (gt > 0), not over those with a prediction",
            lambda pred, gt: depth(pred, gt, valid_from="pred"),
        ),
    ),
)

MODELS = {"chamfer_distance": CHAMFER_DISTANCE, "depth_metrics": DEPTH_METRICS}
