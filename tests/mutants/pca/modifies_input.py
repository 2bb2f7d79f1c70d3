"""Centres the caller's array in place."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = np.asarray(points, dtype=float)
    x -= x.mean(axis=0)
    if correlation:
        std = x.std(axis=0)
        x /= np.where(std > 0, std, 1.0)
    w, v = np.linalg.eigh(x.T @ x / len(x))
    return w[::-1].copy(), v[:, ::-1].copy()
