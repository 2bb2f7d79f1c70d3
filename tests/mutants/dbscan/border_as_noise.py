"""Labels only the core points (the connected components of the core graph): a border point, not core
but within eps of a core, is left as noise."""

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "border_as_noise"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    labels = np.full(n, -1, dtype=np.int64)
    if n == 0:
        return labels, np.zeros(0, dtype=bool)
    s = np.zeros((n, n))
    for j in range(x.shape[1]):
        s += (x[:, None, j] - x[None, :, j]) ** 2
    near = s <= eps**2
    is_core = near.sum(axis=1) >= min_samples
    i, k = np.nonzero(near & is_core[:, None] & is_core[None, :])
    _, component = connected_components(coo_array((np.ones(len(i)), (i, k)), shape=(n, n)), directed=False)
    seen = {}
    for p in np.flatnonzero(is_core):
        labels[p] = seen.setdefault(component[p], len(seen))
    return labels, is_core
