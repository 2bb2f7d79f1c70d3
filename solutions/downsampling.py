"""Reference: voxel grids, farthest point sampling, normal space sampling."""

import numpy as np
from numba import njit

from pcl_course.validation import as_points, check_choice, check_integer, check_positive, check_rng

METHODS = ("centroid", "random")
FPS_BUCKET_SIZE = 128  # measured: 64-256 within 10 %, see benchmarks/


def voxel_coordinates(xyz, voxel_size):
    """Per-axis voxel coordinates ``h`` (int64, shape (N, 3)) and grid sizes ``D`` (Python ints).

    ``D`` stays a tuple of Python ints so that products of it never overflow.
    """
    lower = xyz.min(axis=0)
    h = np.floor((xyz - lower) / voxel_size).astype(np.int64)
    dims = tuple(int(d) + 1 for d in np.floor((xyz.max(axis=0) - lower) / voxel_size))
    return h, dims


def _group_sorted(h):
    """Group ids ordered by linear index, by sorting the coordinates lexicographically.

    Ordering by the linear index ``h_x + h_y D_x + h_z D_x D_y`` is ordering
    by ``(h_z, h_y, h_x)``: exact for any grid size, where the linear index
    itself may overflow int64. The slow path, for grids of more than 2^63 cells.
    """
    order = np.lexsort((h[:, 0], h[:, 1], h[:, 2]))
    sorted_h = h[order]
    new_voxel = np.ones(len(h), dtype=bool)
    new_voxel[1:] = np.any(sorted_h[1:] != sorted_h[:-1], axis=1)
    groups = np.empty(len(h), dtype=np.int64)
    groups[order] = np.cumsum(new_voxel) - 1
    return groups, int(new_voxel.sum())


def voxel_groups(h, dims):
    """Voxel id of every point, numbered ``0..M-1`` in increasing linear index.

    Returns
    -------
    groups : ndarray of int64, shape (N,)
    n_groups : int
        ``M``, the number of occupied voxels.

    Notes
    -----
    Three strategies, by grid size: a grid of at most ``8 N`` cells is a dense
    table (a counting pass, O(N + cells), no sorting); a larger one that still
    fits int64 sorts the linear indices (O(N log N) on one key); beyond int64
    the coordinates are sorted lexicographically (three keys, slowest).
    """
    n_cells = dims[0] * dims[1] * dims[2]  # Python ints: never overflows
    if n_cells > np.iinfo(np.int64).max:
        return _group_sorted(h)
    linear = h[:, 0] + dims[0] * (h[:, 1] + dims[1] * h[:, 2])
    if n_cells <= 8 * len(h):
        occupied = np.bincount(linear, minlength=n_cells) > 0
        rank = np.cumsum(occupied) - 1
        return rank[linear], int(rank[-1]) + 1
    unique, groups = np.unique(linear, return_inverse=True)
    return groups.reshape(-1), len(unique)


@njit(cache=True)
def _reservoir_choice(groups, n_groups, uniform):
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


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
    check_choice(method, "method", METHODS)
    rng = check_rng(rng)
    if len(points) == 0:
        return np.empty((0, points.shape[1]))
    h, dims = voxel_coordinates(points[:, :3], voxel_size)
    groups, n_groups = voxel_groups(h, dims)
    if method == "random":
        return points[_reservoir_choice(groups, n_groups, rng.random(len(points)))]
    counts = np.bincount(groups, minlength=n_groups)
    columns = [np.bincount(groups, points[:, c], minlength=n_groups) for c in range(points.shape[1])]
    return np.stack(columns, axis=1) / counts[:, None]


@njit(cache=True)
def _hash_table_filter(containers, h, n_slots, values, uniform, centroid):
    """The lecture's sequential conflict rule over containers ``0..n_slots-1``.

    Returns the emitted rows: centroids (``centroid=True``) or the row index
    chosen by reservoir sampling in each flushed container.
    """
    n, d = values.shape
    occupied = np.zeros(n_slots, dtype=np.bool_)
    held = np.empty((n_slots, 3), dtype=np.int64)
    sums = np.zeros((n_slots, d))
    counts = np.zeros(n_slots, dtype=np.int64)
    chosen = np.empty(n_slots, dtype=np.int64)
    out_rows = np.empty((n if centroid else 0, d))
    out_index = np.empty(n, dtype=np.int64)
    n_out = 0
    for i in range(n + n_slots):
        if i < n:
            s = containers[i]
            if not occupied[s] or (held[s, 0] == h[i, 0] and held[s, 1] == h[i, 1] and held[s, 2] == h[i, 2]):
                flush = False
            else:
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
                held[s, 0], held[s, 1], held[s, 2] = h[i, 0], h[i, 1], h[i, 2]
                counts[s] = 0
                sums[s, :] = 0.0
            counts[s] += 1
            if centroid:
                for c in range(d):
                    sums[s, c] += values[i, c]
            elif uniform[i] * counts[s] < 1.0:
                chosen[s] = i
    return out_rows[:n_out], out_index[:n_out]


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
    n_containers = check_integer(n_containers, "n_containers", low=1)
    check_choice(method, "method", METHODS)
    rng = check_rng(rng)
    if len(points) == 0:
        return np.empty((0, points.shape[1]))
    h, (dx, dy, _) = voxel_coordinates(points[:, :3], voxel_size)
    # linear_index % n_containers, computed modulo n_containers term by term
    # so that it stays exact when the linear index overflows int64.
    m = n_containers
    containers = (h[:, 0] % m + (h[:, 1] % m) * (dx % m) % m + (h[:, 2] % m) * ((dx * dy) % m) % m) % m
    if m <= 4 * len(points):
        slots, n_slots = containers, m
    else:  # renumber the containers in use, keeping their order, so tables stay O(N)
        used, slots = np.unique(containers, return_inverse=True)
        slots, n_slots = slots.reshape(-1), len(used)
    centroid = method == "centroid"
    uniform = np.empty(0) if centroid else rng.random(len(points))
    rows, chosen = _hash_table_filter(slots, h, n_slots, points, uniform, centroid)
    return rows if centroid else points[chosen]


def _morton_order(xyz, bits=10):
    """Indices that sort the points along a Z-order curve (nearby points, nearby ranks)."""
    lower = xyz.min(axis=0)
    span = float((xyz.max(axis=0) - lower).max()) or 1.0
    cells = np.minimum((xyz - lower) / span * (1 << bits), (1 << bits) - 1).astype(np.uint64)

    def spread(v):  # insert two zero bits between the bits of a 10-bit integer
        v = (v | (v << np.uint64(16))) & np.uint64(0x30000FF)
        v = (v | (v << np.uint64(8))) & np.uint64(0x300F00F)
        v = (v | (v << np.uint64(4))) & np.uint64(0x30C30C3)
        return (v | (v << np.uint64(2))) & np.uint64(0x9249249)

    code = spread(cells[:, 0]) | (spread(cells[:, 1]) << np.uint64(1)) | (spread(cells[:, 2]) << np.uint64(2))
    return np.argsort(code, kind="stable")


@njit(cache=True)
def _bucket_fps(x, y, z, ids, n_samples, start, bucket_size):
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


def farthest_point_sampling(points, n_samples, start_index=0):
    points = as_points(points)
    n = len(points)
    n_samples = check_integer(n_samples, "n_samples", low=0, high=n)
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)
    start_index = check_integer(start_index, "start_index", low=0, high=n - 1)
    xyz = points[:, :3]
    order = _morton_order(xyz).astype(np.int64)
    position = np.empty(n, dtype=np.int64)
    position[order] = np.arange(n)
    x, y, z = (np.ascontiguousarray(xyz[order, axis]) for axis in range(3))
    return _bucket_fps(x, y, z, order, n_samples, position[start_index], FPS_BUCKET_SIZE)


def normal_bucket_ids(normals, n_bins):
    """Bucket id of each normal in the ``n_bins^3`` cube grid over ``[-1, 1]^3``."""
    b = np.clip(np.floor((normals + 1.0) / 2.0 * n_bins), 0, n_bins - 1).astype(np.int64)
    return b[:, 0] + b[:, 1] * n_bins + b[:, 2] * n_bins**2


def normal_space_sampling(normals, n_samples, n_bins=4, rng=None):
    normals = as_points(normals, "normals", columns=3)
    n_samples = check_integer(n_samples, "n_samples", low=0, high=len(normals))
    n_bins = check_integer(n_bins, "n_bins", low=1)
    rng = check_rng(rng)
    buckets = normal_bucket_ids(normals, n_bins)
    # A random order inside each bucket; a point's draw round is its rank in
    # that order. Round-robin = sort by (round, bucket id).
    shuffled = rng.permutation(len(normals))
    by_bucket = shuffled[np.argsort(buckets[shuffled], kind="stable")]
    sorted_buckets = buckets[by_bucket]
    first = np.searchsorted(sorted_buckets, sorted_buckets, side="left")
    rounds = np.arange(len(normals)) - first
    draw_order = np.lexsort((sorted_buckets, rounds))
    return by_bucket[draw_order[:n_samples]].astype(np.int64)
