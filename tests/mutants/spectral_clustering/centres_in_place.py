"""Centres the caller's points in place before the graph (np.asarray makes no copy of float64
points; float32 points are copied, so a test calling with float32 alone sees nothing). The
clustering is right: the k-nearest-neighbour graph does not move with the points."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import spectral_clustering as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    x = np.asarray(points, dtype=float)
    if x.ndim == 2:
        x -= x.mean(axis=0)  # the caller's points move
    return _reference(x, n_clusters, k, sigma)
