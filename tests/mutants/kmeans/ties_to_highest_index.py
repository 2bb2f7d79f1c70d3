"""Assigns with a loop over the centres and <=: a tie goes to the highest centre index."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference

MISTAKE = "ties_to_highest_index"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _squared(x, c):
    s = np.zeros((len(x), len(c)))
    for j in range(x.shape[1]):
        s += (x[:, j, None] - c[None, :, j]) ** 2
    return s


def _assign(x, c):
    s = _squared(x, c)
    labels, best = np.zeros(len(x), dtype=np.int64), np.full(len(x), np.inf)
    for k in range(len(c)):
        closer = s[:, k] <= best
        labels[closer], best[closer] = k, s[closer, k]
    return labels, best.sum()


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    x = np.asarray(points, dtype=float)
    c = np.array(init_centers, dtype=float)
    inertia, previous = [], None
    for t in range(1, max_iter + 1):
        labels, total = _assign(x, c)
        inertia.append(total)
        if previous is not None and np.array_equal(labels, previous):
            break
        for k in range(len(c)):
            if np.any(labels == k):
                c[k] = x[labels == k].mean(axis=0)
        previous = labels
        if t == max_iter:
            labels, _ = _assign(x, c)
    return labels, c, np.array(inertia), len(inertia)
