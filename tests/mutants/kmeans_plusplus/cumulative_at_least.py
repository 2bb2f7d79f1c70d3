"""np.searchsorted with its default side='left': the smallest i with cum[i] >= u * cum[-1], not >. Wrong
only when u * cum[-1] equals a cumulative sum exactly (u == 0 with a chosen point first: it is drawn again)."""

import numpy as np

from pcl_course.validation import check_rng
from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans_plusplus as _reference

MISTAKE = "cumulative_at_least"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _squared_to(x, c):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - c[j]) ** 2
    return s


def kmeans_plusplus(points, n_clusters, rng=None):
    _reference(points, n_clusters, 0)  # validation only (not the caller's rng: it would consume it)
    x = np.asarray(points, dtype=float)
    rng = check_rng(rng)  # the contract's np.random.default_rng(rng), a bad rng refused
    chosen = [int(rng.integers(len(x)))]
    nearest = _squared_to(x, x[chosen[0]])
    for _ in range(n_clusters - 1):
        cum = np.cumsum(nearest)
        chosen.append(int(np.searchsorted(cum, rng.random() * cum[-1])))
        nearest = np.minimum(nearest, _squared_to(x, x[chosen[-1]]))
    return np.array(chosen, dtype=np.int64)
