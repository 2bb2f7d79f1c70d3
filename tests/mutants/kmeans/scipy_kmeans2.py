"""Calls scipy.cluster.vq.kmeans2 from the given centres: scipy.cluster is forbidden in this lecture."""

import numpy as np
from scipy.cluster.vq import kmeans2

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    x = np.asarray(points, dtype=float)
    c, labels = kmeans2(x, np.array(init_centers, dtype=float), iter=max_iter, minit="matrix", missing="warn")
    s = ((x - c[labels]) ** 2).sum()
    return labels.astype(np.int64), c, np.array([s]), 1
