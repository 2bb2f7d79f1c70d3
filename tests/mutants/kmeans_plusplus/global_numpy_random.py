"""Draws with the legacy global np.random (np.random.randint, np.random.choice(N, p=...)) and ignores rng:
the same seed does not give the same answer."""

import numpy as np

from pcl_course.validation import check_rng
from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans_plusplus as _reference

MISTAKE = None  # no catalogue line: the global stream cannot be replayed (the tests' own messages say it)


def _squared_to(x, c):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - c[j]) ** 2
    return s


def kmeans_plusplus(points, n_clusters, rng=None):
    _reference(points, n_clusters, 0)  # validation only (not the caller's rng: it would consume it)
    check_rng(rng)  # checked, then never used
    x = np.asarray(points, dtype=float)
    chosen = [int(np.random.randint(len(x)))]  # noqa: NPY002 -- the legacy global stream is the mistake
    nearest = _squared_to(x, x[chosen[0]])
    for _ in range(n_clusters - 1):
        chosen.append(int(np.random.choice(len(x), p=nearest / nearest.sum())))  # noqa: NPY002
        nearest = np.minimum(nearest, _squared_to(x, x[chosen[-1]]))
    return np.array(chosen, dtype=np.int64)
