"""Union-find over the core pairs; each border joins its smallest-label core neighbour's set; then the
clusters are renumbered by first appearance over ALL points in index order (a border point of a later
cluster with a low index renumbers it)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "numbered_by_first_point"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    s = np.zeros((n, n))
    for j in range(x.shape[1]):
        s += (x[:, None, j] - x[None, :, j]) ** 2
    near = s <= eps * eps
    is_core = near.sum(axis=1) >= min_samples
    root = np.arange(n)

    def find(i):
        while root[i] != i:
            root[i] = root[root[i]]
            i = root[i]
        return i

    for i, k in zip(*np.nonzero(near & is_core[:, None] & is_core[None, :])):
        a, b = find(i), find(k)
        root[max(a, b)] = min(a, b)
    raw = np.full(n, -1, dtype=np.int64)
    for i in np.flatnonzero(is_core):
        raw[i] = find(i)  # the smallest core of its cluster
    for i in np.flatnonzero(~is_core):
        cores = np.flatnonzero(near[i] & is_core)
        if len(cores):
            raw[i] = raw[cores].min()
    labels = np.full(n, -1, dtype=np.int64)
    order = {}
    for i in range(n):
        if raw[i] >= 0:
            labels[i] = order.setdefault(raw[i], len(order))
    return labels, is_core
