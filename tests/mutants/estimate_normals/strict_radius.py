"""Uses distance < radius instead of <= radius."""

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "strict_radius"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    return _reference(points, k, None if radius is None else radius * (1 - 1e-12), viewpoint)
