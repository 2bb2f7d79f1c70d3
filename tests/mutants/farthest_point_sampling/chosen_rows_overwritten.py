"""Uses the caller's array as scratch: once the sample is drawn, each chosen row is overwritten
with +inf, the way a student "removes" chosen points (np.asarray makes no copy of float64). The
indices are right; the caller's cloud is not."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import farthest_point_sampling as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def farthest_point_sampling(points, n_samples, start_index=0):
    chosen = _reference(points, n_samples, start_index)
    x = np.asarray(points)
    if x.dtype == np.float64 and x.flags.writeable:
        x[chosen] = np.inf  # the caller's points are gone
    return chosen
