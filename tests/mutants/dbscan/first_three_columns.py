"""Measures distances on x, y, z only (points[:, :3], a lecture-1 habit): here every column is a
coordinate."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "first_three_columns"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    n = len(xyz)
    s = np.zeros((n, n))
    for j in range(xyz.shape[1]):
        s += (xyz[:, None, j] - xyz[None, :, j]) ** 2
    near = s <= eps**2
    is_core = near.sum(axis=1) >= min_samples
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for i in range(n):
        if labels[i] != -1 or not is_core[i]:
            continue
        labels[i] = cluster
        queue = [i]
        while queue:
            p = queue.pop(0)
            for q in np.flatnonzero(near[p] & (labels == -1)):
                labels[q] = cluster
                if is_core[q]:
                    queue.append(q)
        cluster += 1
    return labels, is_core
