"""Weights the scatter matrix but centres on the plain mean."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import fit_plane as _reference

MISTAKE = "unweighted_centroid"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def fit_plane(points, weights=None):
    _reference(points, weights)
    x = np.asarray(points, float)
    w = np.ones(len(x)) if weights is None else np.asarray(weights, float)
    c = x.mean(axis=0)
    d = x - c
    return c, np.linalg.eigh((d * w[:, None]).T @ d)[1][:, 0]
