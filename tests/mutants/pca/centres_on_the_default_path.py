"""Centres the caller's array in place on the default path only (correlation=False): the
standardising path copies first. The eigenpairs are right; the in-place verdict must read every
call of the grading, not the in-place test's own (a test calling with correlation=True alone
would see nothing)."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    if correlation:
        return _reference(points, correlation=True, sort=sort)
    x = np.asarray(points, dtype=float)  # no copy of a float64 array
    x -= x.mean(axis=0)
    return _reference(x, sort=sort)
