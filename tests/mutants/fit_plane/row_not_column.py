"""Takes a row of eigh's eigenvector matrix instead of a column."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import fit_plane as _reference

MISTAKE = "row_not_column"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def fit_plane(points, weights=None):
    centroid, _ = _reference(points, weights)
    w = np.ones(len(points)) if weights is None else np.asarray(weights, float)
    d = np.asarray(points, float) - centroid
    return centroid, np.linalg.eigh((d * w[:, None]).T @ d)[1][0]
