"""Measures distances over all columns, extra attributes included."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import farthest_point_sampling as _reference

MISTAKE = "all_columns"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def farthest_point_sampling(points, n_samples, start_index=0):
    _reference(points, n_samples, start_index)  # validation only
    p = np.asarray(points, dtype=float)
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)
    chosen = [start_index]
    nearest = np.sum((p - p[start_index]) ** 2, axis=1)
    while len(chosen) < n_samples:
        candidates = nearest.copy()
        candidates[chosen] = -1.0
        nxt = int(np.argmax(candidates))
        chosen.append(nxt)
        nearest = np.minimum(nearest, np.sum((p - p[nxt]) ** 2, axis=1))
    return np.array(chosen, dtype=np.int64)
