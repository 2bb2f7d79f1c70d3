"""With a radius, uses every point within it and ignores k."""

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "hybrid_ignores_k"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    return _reference(points, None if radius is not None else k, radius, viewpoint)
