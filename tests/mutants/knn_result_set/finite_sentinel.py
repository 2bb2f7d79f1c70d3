"""Starts the worst distance at 1e10 instead of inf, as much copied scaffold code does."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import knn_result_set as _reference

MISTAKE = "finite_sentinel"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_result_set(distances, indices, k):
    held_i, held_d, worst = _reference(distances, indices, k)
    return held_i, held_d, np.where(np.isinf(worst), 1e10, worst)
