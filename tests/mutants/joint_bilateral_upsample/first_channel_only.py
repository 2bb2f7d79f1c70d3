"""Uses only the guide's first channel for the range weight."""

import math

import numpy as np

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import joint_bilateral_upsample as _reference

MISTAKE = "first_channel_only"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def joint_bilateral_upsample(sparse_depth, guide, sigma_s, sigma_r, radius):
    _reference(sparse_depth, guide, sigma_s, sigma_r, radius)  # validation only
    d = np.asarray(sparse_depth, float)
    g = np.asarray(guide, float).reshape(d.shape[0], d.shape[1], -1)
    h, w = d.shape
    out = np.zeros_like(d)
    for y in range(h):
        for x in range(w):
            num = den = 0.0
            for qy in range(max(0, y - radius), min(h, y + radius + 1)):
                for qx in range(max(0, x - radius), min(w, x + radius + 1)):
                    if d[qy, qx] <= 0:
                        continue
                    wt = math.exp(-((qy - y) ** 2 + (qx - x) ** 2) / (2 * sigma_s**2)) * math.exp(
                        -((g[y, x, 0] - g[qy, qx, 0]) ** 2) / (2 * sigma_r**2)
                    )
                    num, den = num + wt * d[qy, qx], den + wt
            out[y, x] = num / den if den > 0 and num > 0 else 0.0
    return out
