"""Exact farthest point sampling, skipping buckets the new sample cannot change (numba)."""

import numpy as np
from numba import njit

__all__ = ["bucket_fps"]


@njit(cache=True)
def bucket_fps(x, y, z, ids, n_samples, start, bucket_size):
    """Exact farthest point sampling over buckets of ``bucket_size`` consecutive points.

    A bucket keeps its bounding box and the largest nearest-distance of its
    points. A new sample can lower a point's distance only if it is closer to
    that point than the point's current distance, so a bucket whose box is at
    least its largest distance away is skipped. Floating-point rounding is
    monotonic, so the skip is exact, not approximate. Ties go to the lowest
    original index ``ids``.
    """
    n = x.shape[0]
    n_buckets = (n + bucket_size - 1) // bucket_size
    lower = np.empty((n_buckets, 3))
    upper = np.empty((n_buckets, 3))
    for b in range(n_buckets):
        first = b * bucket_size
        lower[b, 0] = upper[b, 0] = x[first]
        lower[b, 1] = upper[b, 1] = y[first]
        lower[b, 2] = upper[b, 2] = z[first]
        for i in range(first + 1, min(n, first + bucket_size)):
            lower[b, 0], upper[b, 0] = min(lower[b, 0], x[i]), max(upper[b, 0], x[i])
            lower[b, 1], upper[b, 1] = min(lower[b, 1], y[i]), max(upper[b, 1], y[i])
            lower[b, 2], upper[b, 2] = min(lower[b, 2], z[i]), max(upper[b, 2], z[i])
    nearest = np.full(n, np.inf)
    bucket_max = np.full(n_buckets, np.inf)
    bucket_arg = np.zeros(n_buckets, dtype=np.int64)
    selected = np.empty(n_samples, dtype=np.int64)
    last = start
    for j in range(n_samples):
        selected[j] = ids[last]
        nearest[last] = -1.0  # never selected again, even among duplicates
        if j + 1 == n_samples:
            break
        cx, cy, cz = x[last], y[last], z[last]
        own_bucket = last // bucket_size
        for b in range(n_buckets):
            if b != own_bucket:  # its maximum may have been the new sample
                gx = max(lower[b, 0] - cx, 0.0, cx - upper[b, 0])
                gy = max(lower[b, 1] - cy, 0.0, cy - upper[b, 1])
                gz = max(lower[b, 2] - cz, 0.0, cz - upper[b, 2])
                if gx * gx + gy * gy + gz * gz >= bucket_max[b]:
                    continue
            best, best_i = -np.inf, 0
            for i in range(b * bucket_size, min(n, (b + 1) * bucket_size)):
                dx, dy, dz = x[i] - cx, y[i] - cy, z[i] - cz
                d = dx * dx + dy * dy + dz * dz
                m = nearest[i]
                if d < m:
                    m = d
                    nearest[i] = d
                if m > best or (m == best and ids[i] < ids[best_i]):
                    best, best_i = m, i
            bucket_max[b], bucket_arg[b] = best, best_i
        g = 0
        for b in range(1, n_buckets):
            if bucket_max[b] > bucket_max[g] or (
                bucket_max[b] == bucket_max[g] and ids[bucket_arg[b]] < ids[bucket_arg[g]]
            ):
                g = b
        last = bucket_arg[g]
    return selected
