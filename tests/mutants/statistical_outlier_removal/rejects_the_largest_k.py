"""A range check one short, 1 <= k < N - 1: refuses k = N - 1, which the contract allows."""

from solutions.filters import *  # noqa: F401,F403
from solutions.filters import statistical_outlier_removal as _reference

MISTAKE = "rejects_the_largest_k"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def statistical_outlier_removal(points, k, std_ratio):
    if not 1 <= k < len(points) - 1:
        raise ValueError(f"k must be between 1 and N - 1, got {k}")
    return _reference(points, k, std_ratio)
