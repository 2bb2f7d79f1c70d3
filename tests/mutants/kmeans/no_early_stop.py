"""Never checks for unchanged labels: always runs max_iter iterations (the answer's labels and centres
are right once converged; inertia has max_iter entries and n_iter is max_iter)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import kmeans as _reference

MISTAKE = "no_early_stop"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _squared(x, c):
    s = np.zeros((len(x), len(c)))
    for j in range(x.shape[1]):
        s += (x[:, j, None] - c[None, :, j]) ** 2
    return s


def kmeans(points, init_centers, max_iter=300):
    _reference(points, init_centers, max_iter)  # validation only
    x = np.asarray(points, dtype=float)
    c = np.array(init_centers, dtype=float)
    inertia = []
    for _ in range(max_iter):
        s = _squared(x, c)
        labels = np.argmin(s, axis=1)
        inertia.append(s[np.arange(len(x)), labels].sum())
        for k in range(len(c)):
            if np.any(labels == k):
                c[k] = x[labels == k].mean(axis=0)
    labels = np.argmin(_squared(x, c), axis=1)
    return labels.astype(np.int64), c, np.array(inertia), max_iter
