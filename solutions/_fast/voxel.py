"""Voxel keys, grouping by key, and the lecture's hash table (numba)."""

import numpy as np
from numba import njit

__all__ = ["hash_groups", "hash_table_filter", "reservoir_choice", "voxel_keys"]


@njit(cache=True)
def voxel_keys(xyz, lower, voxel_size, dim_x, dim_y):
    """Linear voxel index of every point, ``h_x + h_y D_x + h_z D_x D_y``, in one pass.

    ``h = floor((p - lower) / voxel_size)``, evaluated as NumPy would; the
    caller guarantees that the grid fits int64. One fused loop instead of
    NumPy's four full-size temporaries.
    """
    n = xyz.shape[0]
    keys = np.empty(n, dtype=np.int64)
    for i in range(n):
        hx = np.int64(np.floor((xyz[i, 0] - lower[0]) / voxel_size))
        hy = np.int64(np.floor((xyz[i, 1] - lower[1]) / voxel_size))
        hz = np.int64(np.floor((xyz[i, 2] - lower[2]) / voxel_size))
        keys[i] = hx + dim_x * (hy + dim_y * hz)
    return keys


@njit(cache=True)
def hash_groups(keys):
    """Group id of every key, numbered by first appearance, with an open-addressing hash table.

    Returns ``(groups, uniques)``: ``uniques[groups[i]] == keys[i]``. Expected
    O(N): a multiplicative (Fibonacci) hash into a table of at least 2N slots,
    linear probing. Consecutive equal keys (a scan visits a voxel several
    times in a row) skip the table.
    """
    n = keys.shape[0]
    bits = 1
    while (1 << bits) < 2 * n:
        bits += 1
    mask = (1 << bits) - 1
    shift = np.uint64(64 - bits)
    golden = np.uint64(0x9E3779B97F4A7C15)
    slot_key = np.empty(mask + 1, dtype=np.int64)
    slot_group = np.full(mask + 1, -1, dtype=np.int64)
    groups = np.empty(n, dtype=np.int64)
    uniques = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        key = keys[i]
        if i > 0 and key == keys[i - 1]:
            groups[i] = groups[i - 1]
            continue
        slot = np.int64((np.uint64(key) * golden) >> shift)
        while True:
            if slot_group[slot] < 0:
                slot_key[slot] = key
                slot_group[slot] = m
                uniques[m] = key
                groups[i] = m
                m += 1
                break
            if slot_key[slot] == key:
                groups[i] = slot_group[slot]
                break
            slot = (slot + 1) & mask
    return groups, uniques[:m]


@njit(cache=True)
def reservoir_choice(groups, n_groups, uniform):
    """One uniformly random member of every group, in one pass (reservoir sampling).

    The ``c``-th member of a group replaces the choice with probability ``1/c``.
    """
    seen = np.zeros(n_groups, dtype=np.int64)
    chosen = np.empty(n_groups, dtype=np.int64)
    for i in range(groups.shape[0]):
        g = groups[i]
        seen[g] += 1
        if uniform[i] * seen[g] < 1.0:
            chosen[g] = i
    return chosen


@njit(cache=True)
def hash_table_filter(containers, voxels, n_slots, values, uniform, centroid):
    """The lecture's sequential conflict rule over containers ``0..n_slots-1``.

    ``voxels`` identifies each point's voxel: one column (the linear index)
    or three (the coordinates, when the linear index overflows int64).
    Returns the emitted rows: centroids (``centroid=True``) or the row index
    chosen by reservoir sampling in each flushed container.
    """
    n, d = values.shape
    occupied = np.zeros(n_slots, dtype=np.bool_)
    width = voxels.shape[1]
    held = np.empty((n_slots, width), dtype=np.int64)
    sums = np.zeros((n_slots, d))
    counts = np.zeros(n_slots, dtype=np.int64)
    chosen = np.empty(n_slots, dtype=np.int64)
    out_rows = np.empty((n if centroid else 0, d))
    out_index = np.empty(n, dtype=np.int64)
    n_out = 0
    for i in range(n + n_slots):
        if i < n:
            s = containers[i]
            flush = False
            if occupied[s]:
                for c in range(width):
                    if held[s, c] != voxels[i, c]:
                        flush = True
        else:  # the final pass: every container still holding a voxel, in order
            s = i - n
            flush = occupied[s]
        if flush:
            if centroid:
                for c in range(d):
                    out_rows[n_out, c] = sums[s, c] / counts[s]
            out_index[n_out] = chosen[s]
            n_out += 1
            occupied[s] = False
        if i < n:
            if not occupied[s]:
                occupied[s] = True
                for c in range(width):
                    held[s, c] = voxels[i, c]
                counts[s] = 0
                sums[s, :] = 0.0
            counts[s] += 1
            if centroid:
                for c in range(d):
                    sums[s, c] += values[i, c]
            elif uniform[i] * counts[s] < 1.0:
                chosen[s] = i
    return out_rows[:n_out], out_index[:n_out]
