"""Forgets the range weight on h: a Gaussian-weighted shift along the normal."""

import numpy as np
from scipy.spatial.distance import cdist

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import bilateral_filter_points as _reference

MISTAKE = "no_range_weight"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bilateral_filter_points(points, normals, radius, sigma_s, sigma_r):
    _reference(points, normals, radius, sigma_s, sigma_r)
    p, n = np.asarray(points, float), np.asarray(normals, float)
    d = cdist(p, p)
    out = np.empty_like(p)
    for i in range(len(p)):
        near = d[i] <= radius
        h = (p[near] - p[i]) @ n[i]
        w = np.exp(-(d[i, near] ** 2) / (2 * sigma_s**2))
        out[i] = p[i] + n[i] * (w @ h) / w.sum()
    return out
