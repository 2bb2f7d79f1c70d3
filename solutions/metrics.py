"""Reference: evaluation metrics."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_array, as_points


def chamfer_distance(a, b):
    a = as_points(a, "a", allow_empty=False)[:, :3]
    b = as_points(b, "b", allow_empty=False)[:, :3]
    a_to_b = cKDTree(b).query(a)[0]
    b_to_a = cKDTree(a).query(b)[0]
    return float(np.mean(a_to_b**2) + np.mean(b_to_a**2))


def depth_metrics(pred, gt):
    pred = as_array(pred, "pred", ndim=2)
    gt = as_array(gt, "gt", ndim=2)
    if pred.shape != gt.shape:
        raise ValueError(f"pred must have the shape of gt {gt.shape}, got {pred.shape}")
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
