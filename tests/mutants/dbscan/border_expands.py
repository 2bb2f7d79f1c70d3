"""Grows each cluster from every point it reaches, border points included: clusters merge through a
border point, and points within eps of a border join too."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "border_expands"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    neighbours = []
    for i in range(n):
        s = np.zeros(n)
        for j in range(x.shape[1]):
            s += (x[:, j] - x[i, j]) ** 2
        neighbours.append([int(q) for q in np.flatnonzero(s <= eps**2)])
    is_core = np.array([len(nb) >= min_samples for nb in neighbours], dtype=bool)
    taken = [False] * n
    labels = np.full(n, -1, dtype=np.int64)
    cluster = 0
    for i in range(n):
        if taken[i] or not is_core[i]:
            continue
        taken[i] = True
        members = [i]
        for p in members:  # the list grows while it is read
            for q in neighbours[p]:
                if not taken[q]:
                    taken[q] = True
                    members.append(q)
        labels[members] = cluster
        cluster += 1
    return labels, is_core
