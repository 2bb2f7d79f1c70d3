"""Replaces the worst held candidate on an equal distance (<=), so ties go to the later offer."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import knn_result_set as _reference

MISTAKE = "ties_to_the_later"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def knn_result_set(distances, indices, k):
    _reference(distances, indices, k)  # validation only
    held, worst = [], []
    for d, i in zip(np.asarray(distances, dtype=float).tolist(), np.asarray(indices).tolist()):
        if len(held) < k:
            held.append([d, i])
        elif d <= held[-1][0]:
            held[-1] = [d, i]
        held.sort(key=lambda pair: pair[0])  # distance only: a stable sort keeps the offer order of ties
        worst.append(held[-1][0] if len(held) == k else np.inf)
    return (
        np.array([i for _, i in held], dtype=np.int64),
        np.array([d for d, _ in held], dtype=float),
        np.array(worst, dtype=float),
    )
