"""Always returns k entries, padding with index -1 and distance inf when fewer than k were offered."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import knn_result_set as _reference

MISTAKE = "padded"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_result_set(distances, indices, k):
    held_i, held_d, worst = _reference(distances, indices, k)
    missing = k - len(held_i)
    if missing > 0:
        held_i = np.concatenate([held_i, np.full(missing, -1, dtype=np.int64)])
        held_d = np.concatenate([held_d, np.full(missing, np.inf)])
    return held_i, held_d, worst
