"""Accepts weights and ignores them."""

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import fit_plane as _reference

MISTAKE = "weights_ignored"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def fit_plane(points, weights=None):
    if weights is not None:
        _reference(points, weights)  # validates them, then forgets them
    return _reference(points)
