"""Counts only the OTHER points within eps (j != i) against min_samples: a point needs one neighbour
more than the contract's to be core. Plain Python lists, a set of visited points."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "min_samples_off_by_one"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _others_within(rows, i, eps):
    found = []
    for j, q in enumerate(rows):
        if j == i:
            continue
        s = 0.0
        for a, b in zip(rows[i], q):
            s += (a - b) ** 2
        if s <= eps * eps:
            found.append(j)
    return found


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    rows = np.asarray(points, dtype=float).tolist()
    n = len(rows)
    others = [_others_within(rows, i, eps) for i in range(n)]
    core = [len(o) >= min_samples for o in others]
    labels = [-1] * n
    cluster = 0
    for i in range(n):
        if labels[i] != -1 or not core[i]:
            continue
        labels[i] = cluster
        todo = [i]
        while todo:
            p = todo.pop(0)
            for q in others[p]:
                if labels[q] == -1:
                    labels[q] = cluster
                    if core[q]:
                        todo.append(q)
        cluster += 1
    return np.array(labels, dtype=np.int64), np.array(core, dtype=bool)
