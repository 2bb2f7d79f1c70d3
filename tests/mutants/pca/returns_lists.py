"""Returns Python lists instead of arrays."""

from solutions.pca import *  # noqa: F401,F403  (the rest of the module is right)
from solutions.pca import pca as _reference  # noqa: F401

MISTAKE = "returns_list"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    w, v = _reference(points, correlation, sort)
    return w.tolist(), v.tolist()
