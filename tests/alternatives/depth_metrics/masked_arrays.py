"""KITTI metrics with NumPy masked arrays, depths converted to mm and km first."""

import numpy as np

from solutions.metrics import *  # noqa: F401,F403


def depth_metrics(pred, gt):
    pred, gt = np.asarray(pred, dtype=float), np.asarray(gt, dtype=float)
    if pred.shape != gt.shape:
        raise ValueError("pred and gt must have the same shape")
    mask = gt <= 0
    pred_mm, gt_mm = np.ma.masked_array(pred * 1000, mask), np.ma.masked_array(gt * 1000, mask)
    pred_km, gt_km = pred_mm / 1e6, gt_mm / 1e6
    err, ierr = pred_mm - gt_mm, 1 / pred_km - 1 / gt_km
    return {
        "rmse": float(np.sqrt((err**2).mean())),
        "mae": float(np.abs(err).mean()),
        "irmse": float(np.sqrt((ierr**2).mean())),
        "imae": float(np.abs(ierr).mean()),
    }
