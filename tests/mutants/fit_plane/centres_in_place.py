"""Centres the caller's array in place (``x -= c`` on ``np.asarray(points)``, which is no copy)."""

import numpy as np

from solutions.normals import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.normals import fit_plane as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def fit_plane(points, weights=None):
    _reference(points, weights)  # its input checks
    x = np.asarray(points, dtype=float)
    w = np.ones(len(x)) if weights is None else np.asarray(weights, dtype=float)
    c = w @ x / w.sum()
    x -= c
    return c, np.linalg.eigh((x * w[:, None]).T @ x)[1][:, 0]
