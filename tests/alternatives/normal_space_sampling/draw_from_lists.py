"""Normal space sampling drawing each point with rng.integers from the bucket's remaining list."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403


def normal_space_sampling(normals, n_samples, n_bins=4, rng=None):
    n = np.asarray(normals, dtype=float)
    if n.ndim != 2 or n.shape[1] != 3 or not np.isfinite(n).all():
        raise ValueError("normals must be a finite (N, 3) array")
    if not 0 <= n_samples <= len(n):
        raise ValueError("n_samples must be between 0 and N")
    if not (isinstance(n_bins, int) and n_bins >= 1):
        raise ValueError("n_bins must be a positive int")
    rng = np.random.default_rng(rng)
    buckets = {}
    for i, normal in enumerate(n):
        b = [min(max(int(np.floor((c + 1) / 2 * n_bins)), 0), n_bins - 1) for c in normal]
        buckets.setdefault(b[0] + b[1] * n_bins + b[2] * n_bins**2, []).append(i)
    out = []
    while len(out) < n_samples:
        for key in sorted(buckets):
            if buckets[key] and len(out) < n_samples:
                out.append(buckets[key].pop(int(rng.integers(len(buckets[key])))))
    return np.array(out, dtype=np.int64)
