"""Curvature from the largest eigenvalue, l_max / trace."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "curvature_from_largest"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    if radius is not None or len(points) == 0:
        return _reference(points, k, radius, viewpoint)
    _reference(points, k, radius, viewpoint)  # validation only
    points = np.asarray(points, dtype=float)
    _, index = cKDTree(points).query(points, k=k)
    index = index.reshape(len(points), k)
    normals, curvature = np.full((len(points), 3), np.nan), np.full(len(points), np.nan)
    for i, row in enumerate(index):
        if len(row) < 3:
            continue
        nb = points[row]
        d = nb - nb.mean(axis=0)
        values, vectors = np.linalg.eigh(d.T @ d / len(nb))
        normals[i], curvature[i] = vectors[:, 0], (values[-1] / values.sum() if values.sum() > 0 else 0.0)
    if viewpoint is not None:
        flip = np.sum(normals * (np.asarray(viewpoint) - points), axis=1) < 0
        normals[flip] *= -1
    return normals, curvature
