"""Does no input validation: NaN input gives NaN output, 1-D input a confusing error."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "did_not_raise"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = np.asarray(points, dtype=float)
    xc = x - x.mean(axis=0)
    if correlation:
        std = xc.std(axis=0)
        xc = xc / np.where(std > 0, std, 1.0)
    h = xc.T @ xc / len(x)
    w, v = np.linalg.eigh(h)
    return w[::-1].copy(), v[:, ::-1].copy()
