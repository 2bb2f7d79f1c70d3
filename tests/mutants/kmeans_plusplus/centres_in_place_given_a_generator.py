"""Centres the caller's points in place, on one path only: given a Generator (np.asarray makes no
copy of a float64 array). The indices drawn are right; the in-place check must look at every call,
not the last one (given the same seed as an int, the points stay as they were)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans_plusplus as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans_plusplus(points, n_clusters, rng=None):
    if isinstance(rng, np.random.Generator):
        x = np.asarray(points)
        x -= x.mean(axis=0)  # centred in place: the caller's points move
        return _reference(x, n_clusters, rng)
    return _reference(points, n_clusters, rng)
