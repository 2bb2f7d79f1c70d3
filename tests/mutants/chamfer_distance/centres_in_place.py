"""Moves both clouds in place to the first one's centroid "for precision" (np.asarray makes no copy
of float64 arrays). The distance is right to rounding: only the caller's arrays have changed."""

import numpy as np

from solutions.metrics import *  # noqa: F401,F403
from solutions.metrics import chamfer_distance as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def chamfer_distance(a, b):
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if x.ndim == 2 and y.ndim == 2 and len(x) and x.shape[1:] == y.shape[1:] and np.isfinite(x).all():
        centre = x.mean(axis=0)
        x -= centre  # the caller's arrays move
        y -= centre
    return _reference(x, y)
