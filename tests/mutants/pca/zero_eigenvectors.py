"""Right eigenvalues, all-zero eigenvectors: the eigen-equation H @ 0 = 0 * lambda holds, orthonormality does not."""

import numpy as np

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference

MISTAKE = "zero_eigenvectors"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    eigenvalues, eigenvectors = _reference(points, correlation=correlation, sort=sort)
    return eigenvalues, np.zeros_like(eigenvectors)
