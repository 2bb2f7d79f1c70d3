"""Curvature l_min / trace without the contract's 0 where the trace is 0: NaN wherever the neighbours coincide."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "zero_trace_curvature"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    if radius is not None or len(points) == 0 or k < 3:
        return _reference(points, k, radius, viewpoint)
    _reference(points, k, radius, viewpoint)  # validation only
    points = np.asarray(points, dtype=float)
    _, index = cKDTree(points).query(points, k=k)
    normals, curvature = np.empty((len(points), 3)), np.empty(len(points))
    for i, row in enumerate(index.reshape(len(points), k)):
        nb = points[row]
        d = nb - nb.mean(axis=0)
        values, vectors = np.linalg.eigh(d.T @ d / len(nb))
        with np.errstate(invalid="ignore"):
            normals[i], curvature[i] = vectors[:, 0], max(values[0], 0.0) / values.sum()
    if viewpoint is not None:
        flip = np.sum(normals * (np.asarray(viewpoint) - points), axis=1) < 0
        normals[flip] *= -1
    return normals, curvature
