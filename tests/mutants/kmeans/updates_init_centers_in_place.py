"""Moves the caller's init_centers in place (np.asarray makes no copy of a float64 array)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _squared(x, c):
    s = np.zeros((len(x), len(c)))
    for j in range(x.shape[1]):
        s += (x[:, j, None] - c[None, :, j]) ** 2
    return s


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    x = np.asarray(points, dtype=float)
    c = np.asarray(init_centers, dtype=float)
    inertia, previous = [], None
    for t in range(1, max_iter + 1):
        s = _squared(x, c)
        labels = np.argmin(s, axis=1)
        inertia.append(s[np.arange(len(x)), labels].sum())
        if previous is not None and np.array_equal(labels, previous):
            break
        for k in range(len(c)):
            if np.any(labels == k):
                c[k] = x[labels == k].mean(axis=0)
        previous = labels
        if t == max_iter:
            labels = np.argmin(_squared(x, c), axis=1)
    return labels.astype(np.int64), c, np.array(inertia), len(inertia)
