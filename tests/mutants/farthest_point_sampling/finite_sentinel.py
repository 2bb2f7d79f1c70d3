"""Starts the nearest distances at 1e10, as much copied code does: wrong once squared distances exceed 1e10."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import farthest_point_sampling as _reference

MISTAKE = "finite_sentinel"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def farthest_point_sampling(points, n_samples, start_index=0):
    _reference(points, n_samples, start_index)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    selected = np.zeros(n_samples, dtype=np.int64)
    distance = np.ones(len(xyz)) * 1e10
    farthest = start_index
    for i in range(n_samples):
        selected[i] = farthest
        dist = np.sum((xyz - xyz[farthest]) ** 2, axis=1)
        mask = dist < distance
        distance[mask] = dist[mask]
        farthest = int(np.argmax(distance))
    return selected
