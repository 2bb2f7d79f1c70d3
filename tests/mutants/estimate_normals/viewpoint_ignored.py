"""Ignores the viewpoint: normals keep eigh's arbitrary signs."""

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "viewpoint_ignored"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    return _reference(points, k, radius, None)
