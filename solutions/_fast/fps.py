"""Exact farthest point sampling, skipping the buckets a new sample cannot change (numba)."""

import numpy as np
from numba import njit

__all__ = ["bucket_fps"]


@njit(cache=True, inline="always")
def _box_gap(lower, upper, row, cx, cy, cz):
    """Squared distance from (cx, cy, cz) to the box ``lower[row]``-``upper[row]``."""
    gx = max(lower[row, 0] - cx, 0.0, cx - upper[row, 0])
    gy = max(lower[row, 1] - cy, 0.0, cy - upper[row, 1])
    gz = max(lower[row, 2] - cz, 0.0, cz - upper[row, 2])
    return gx * gx + gy * gy + gz * gz


@njit(cache=True)
def _boxes(x, y, z, size):
    """Bounding boxes of consecutive runs of ``size`` points: (lower, upper), each (runs, 3)."""
    n = x.shape[0]
    runs = (n + size - 1) // size
    lower, upper = np.empty((runs, 3)), np.empty((runs, 3))
    for r in range(runs):
        first = r * size
        lower[r, 0] = upper[r, 0] = x[first]
        lower[r, 1] = upper[r, 1] = y[first]
        lower[r, 2] = upper[r, 2] = z[first]
        for i in range(first + 1, min(n, first + size)):
            lower[r, 0], upper[r, 0] = min(lower[r, 0], x[i]), max(upper[r, 0], x[i])
            lower[r, 1], upper[r, 1] = min(lower[r, 1], y[i]), max(upper[r, 1], y[i])
            lower[r, 2], upper[r, 2] = min(lower[r, 2], z[i]), max(upper[r, 2], z[i])
    return lower, upper


@njit(cache=True)
def _group_boxes(lower, upper, group):
    """Bounding boxes of consecutive runs of ``group`` boxes."""
    runs = (lower.shape[0] + group - 1) // group
    glower, gupper = np.empty((runs, 3)), np.empty((runs, 3))
    for g in range(runs):
        first = g * group
        glower[g], gupper[g] = lower[first], upper[first]
        for b in range(first + 1, min(lower.shape[0], first + group)):
            for a in range(3):
                glower[g, a] = min(glower[g, a], lower[b, a])
                gupper[g, a] = max(gupper[g, a], upper[b, a])
    return glower, gupper


@njit(cache=True)
def bucket_fps(x, y, z, ids, n_samples, start, bucket_size, group):
    """Exact farthest point sampling over buckets of ``bucket_size`` consecutive points, in groups
    of ``group`` consecutive buckets.

    A bucket keeps its bounding box and the largest nearest-distance of its
    points, a group the box of its buckets and the largest of theirs. A new
    sample can lower a point's distance only if it is closer to that point
    than the point's current distance, so a bucket (or a whole group) whose box
    is at least its largest distance away is skipped. Floating-point rounding
    is monotonic, so the skip is exact, not approximate. Ties go to the lowest
    original index ``ids``. A bucket is updated in two passes, the distances
    and their maximum first (they vectorise), then the tie rule.
    """
    n = x.shape[0]
    lower, upper = _boxes(x, y, z, bucket_size)
    glower, gupper = _group_boxes(lower, upper, group)
    n_buckets, n_groups = lower.shape[0], glower.shape[0]
    nearest = np.full(n, np.inf)
    bucket_max = np.full(n_buckets, np.inf)
    bucket_arg = np.zeros(n_buckets, dtype=np.int64)
    group_max = np.full(n_groups, np.inf)
    group_arg = np.zeros(n_groups, dtype=np.int64)  # the group's farthest point (a position)
    selected = np.empty(n_samples, dtype=np.int64)
    last = start
    for j in range(n_samples):
        selected[j] = ids[last]
        nearest[last] = -1.0  # never selected again, even among duplicates
        if j + 1 == n_samples:
            break
        cx, cy, cz = x[last], y[last], z[last]
        own_bucket = last // bucket_size
        own_group = own_bucket // group  # their maximum may have been the new sample
        for g in range(n_groups):
            if g != own_group and _box_gap(glower, gupper, g, cx, cy, cz) >= group_max[g]:
                continue
            changed = False
            for b in range(g * group, min(n_buckets, (g + 1) * group)):
                if b != own_bucket and _box_gap(lower, upper, b, cx, cy, cz) >= bucket_max[b]:
                    continue
                changed = True
                lo, hi = b * bucket_size, min(n, (b + 1) * bucket_size)
                best = -np.inf
                for i in range(lo, hi):
                    dx, dy, dz = x[i] - cx, y[i] - cy, z[i] - cz
                    m = min(nearest[i], dx * dx + dy * dy + dz * dz)
                    nearest[i] = m
                    best = max(best, m)
                best_i = -1
                for i in range(lo, hi):
                    if nearest[i] == best and (best_i < 0 or ids[i] < ids[best_i]):
                        best_i = i
                bucket_max[b], bucket_arg[b] = best, best_i
            if changed:
                first = g * group
                top, top_i = bucket_max[first], bucket_arg[first]
                for b in range(first + 1, min(n_buckets, first + group)):
                    if bucket_max[b] > top or (bucket_max[b] == top and ids[bucket_arg[b]] < ids[top_i]):
                        top, top_i = bucket_max[b], bucket_arg[b]
                group_max[g], group_arg[g] = top, top_i
        g = 0
        for h in range(1, n_groups):
            if group_max[h] > group_max[g] or (group_max[h] == group_max[g] and ids[group_arg[h]] < ids[group_arg[g]]):
                g = h
        last = group_arg[g]
    return selected
