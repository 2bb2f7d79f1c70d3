"""Pads the image with zeros: pixels outside count as 0."""

import math

import numpy as np

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import bilateral_filter_image as _reference

MISTAKE = "zero_padding"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bilateral_filter_image(image, sigma_s, sigma_r, radius=None):
    _reference(image, sigma_s, sigma_r, radius)  # validation only
    src = np.asarray(image, dtype=float)
    out = src.copy()
    r = math.ceil(2 * sigma_s) if radius is None else radius
    h, w = src.shape
    for y in range(h):
        for x in range(w):
            num = den = 0.0
            for qy in range(y - r, y + r + 1):
                for qx in range(x - r, x + r + 1):
                    v = src[qy, qx] if 0 <= qy < h and 0 <= qx < w else 0.0
                    wt = math.exp(-((qy - y) ** 2 + (qx - x) ** 2) / (2 * sigma_s**2)) * math.exp(
                        -((src[y, x] - v) ** 2) / (2 * sigma_r**2)
                    )
                    num, den = num + wt * v, den + wt
            out[y, x] = num / den
    return out
