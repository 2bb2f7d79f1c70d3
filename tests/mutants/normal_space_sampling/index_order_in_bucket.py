"""Takes each bucket's points in index order instead of at random."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import normal_space_sampling as _reference

MISTAKE = "index_order_in_bucket"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def normal_space_sampling(normals, n_samples, n_bins=4, rng=None):
    _reference(normals, n_samples, n_bins, rng)  # validation only
    n = np.asarray(normals, dtype=float)
    rng = np.random.default_rng(rng)
    b = np.clip(np.floor((n + 1.0) / 2.0 * n_bins), 0, n_bins - 1).astype(np.int64)
    ids = b[:, 0] + b[:, 1] * n_bins + b[:, 2] * n_bins**2
    queues = {k: list(np.flatnonzero(ids == k)) for k in sorted(set(ids.tolist()))}
    out = []
    while len(out) < n_samples:
        for k in list(queues):
            if queues[k] and len(out) < n_samples:
                out.append(queues[k].pop(0))
    return np.array(out, dtype=np.int64)
