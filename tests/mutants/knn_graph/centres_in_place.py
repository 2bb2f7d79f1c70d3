"""Centres the caller's points in place "for precision" (np.asarray makes no copy of float64
points). The graph is right: distances do not move with the points."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import knn_graph as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_graph(points, k, sigma=None, mutual=False):
    x = np.asarray(points, dtype=float)
    if x.ndim == 2 and np.isfinite(x).all():
        x -= x.mean(axis=0)  # the caller's points move
    return _reference(x, k, sigma, mutual)
