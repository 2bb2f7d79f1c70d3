r"""Reports irmse and imae in 1\/m instead of 1\/km."""

import numpy as np

from solutions.metrics import *  # noqa: F401,F403
from solutions.metrics import depth_metrics as _reference

MISTAKE = "inverse_per_metre"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def depth_metrics(pred, gt):
    _reference(pred, gt)  # validation only
    pred, gt = np.asarray(pred, float), np.asarray(gt, float)
    valid = gt > 0
    e = (pred[valid] - gt[valid]) * 1000.0
    ie = (1.0 / pred[valid] - 1.0 / gt[valid]) * 1.0
    return {
        "rmse": float(np.sqrt(np.mean(e**2))),
        "mae": float(np.mean(np.abs(e))),
        "irmse": float(np.sqrt(np.mean(ie**2))),
        "imae": float(np.mean(np.abs(ie))),
    }
