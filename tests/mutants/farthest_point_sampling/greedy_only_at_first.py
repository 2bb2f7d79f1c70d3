"""Follows the rule for its first 128 picks only, then fills with the lowest unselected indices (a
shortcut for speed: the tests that ask for a few dozen samples cannot see it)."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import farthest_point_sampling as _reference

MISTAKE = None  # no catalogue line: the test's own message names the first wrong pick

GREEDY_PICKS = 128


def farthest_point_sampling(points, n_samples, start_index=0):
    _reference(points, n_samples, start_index)  # validation only
    head = _reference(points, min(n_samples, GREEDY_PICKS), start_index)
    rest = np.setdiff1d(np.arange(len(points)), head)[: n_samples - len(head)]
    return np.concatenate([head, rest]).astype(np.int64)
