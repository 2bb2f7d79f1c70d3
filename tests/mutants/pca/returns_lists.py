"""Returns Python lists instead of arrays."""

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401


def pca(points, correlation=False, sort=True):
    w, v = _reference(points, correlation, sort)
    return w.tolist(), v.tolist()
