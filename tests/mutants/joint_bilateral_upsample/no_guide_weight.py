"""Ignores the guide image: a plain Gaussian interpolation of the valid pixels."""

import math

import numpy as np

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import joint_bilateral_upsample as _reference

MISTAKE = "no_guide_weight"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def joint_bilateral_upsample(sparse_depth, guide, sigma_s, sigma_r, radius):
    _reference(sparse_depth, guide, sigma_s, sigma_r, radius)  # validation only
    d = np.asarray(sparse_depth, float)
    g = np.asarray(guide, float).reshape(d.shape[0], d.shape[1], -1)  # noqa: F841 -- the mistake: the guide is never used
    h, w = d.shape
    out = np.zeros_like(d)
    for y in range(h):
        for x in range(w):
            num = den = 0.0
            for qy in range(max(0, y - radius), min(h, y + radius + 1)):
                for qx in range(max(0, x - radius), min(w, x + radius + 1)):
                    if d[qy, qx] <= 0:
                        continue
                    wt = math.exp(-((qy - y) ** 2 + (qx - x) ** 2) / (2 * sigma_s**2)) * 1.0
                    num, den = num + wt * d[qy, qx], den + wt
            out[y, x] = num / den if den > 0 and num > 0 else 0.0
    return out
