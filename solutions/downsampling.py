"""Reference: voxel grids, farthest point sampling, normal space sampling."""

import numpy as np

from pcl_course.validation import as_points, check_choice, check_integer, check_positive, check_rng

METHODS = ("centroid", "random")


def voxel_coordinates(xyz, voxel_size):
    """Per-axis voxel coordinates ``h`` (int64, shape (N, 3)) and grid sizes ``D`` (Python ints).

    ``D`` stays a tuple of Python ints so that products of it never overflow.
    """
    lower = xyz.min(axis=0)
    h = np.floor((xyz - lower) / voxel_size).astype(np.int64)
    dims = tuple(int(d) + 1 for d in np.floor((xyz.max(axis=0) - lower) / voxel_size))
    return h, dims


def _group_sorted(h):
    """Sort voxel coordinates by linear index without forming it.

    Ordering by the linear index ``h_x + h_y D_x + h_z D_x D_y`` is ordering
    lexicographically by ``(h_z, h_y, h_x)``: exact for any grid size, where
    the linear index itself may overflow int64.
    """
    order = np.lexsort((h[:, 0], h[:, 1], h[:, 2]))
    sorted_h = h[order]
    new_voxel = np.ones(len(h), dtype=bool)
    new_voxel[1:] = np.any(sorted_h[1:] != sorted_h[:-1], axis=1)
    starts = np.flatnonzero(new_voxel)
    counts = np.diff(np.append(starts, len(h)))
    return order, starts, counts


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
    check_choice(method, "method", METHODS)
    rng = check_rng(rng)
    if len(points) == 0:
        return np.empty((0, points.shape[1]))
    h, _ = voxel_coordinates(points[:, :3], voxel_size)
    order, starts, counts = _group_sorted(h)
    if method == "centroid":
        return np.add.reduceat(points[order], starts, axis=0) / counts[:, None]
    chosen = starts + np.floor(rng.random(len(starts)) * counts).astype(np.int64)
    return points[order[chosen]]


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

    held_voxel = {}   # container -> voxel coordinates it holds
    held_rows = {}    # container -> row indices of the points it holds
    emitted = []

    def emit(rows):
        if method == "centroid":
            emitted.append(points[rows].mean(axis=0))
        else:
            emitted.append(points[rows[int(rng.integers(len(rows)))]])

    for i, (container, voxel) in enumerate(zip(containers.tolist(), map(tuple, h.tolist()))):
        if container in held_voxel and held_voxel[container] != voxel:
            emit(held_rows[container])  # conflict: flush what the container holds
            del held_voxel[container]
        if container not in held_voxel:
            held_voxel[container], held_rows[container] = voxel, []
        held_rows[container].append(i)
    for container in sorted(held_rows):
        emit(held_rows[container])
    return np.array(emitted, dtype=np.float64).reshape(-1, points.shape[1])


def farthest_point_sampling(points, n_samples, start_index=0):
    points = as_points(points)
    n = len(points)
    n_samples = check_integer(n_samples, "n_samples", low=0, high=n)
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)
    start_index = check_integer(start_index, "start_index", low=0, high=n - 1)
    xyz = points[:, :3]
    selected = np.empty(n_samples, dtype=np.int64)
    selected[0] = start_index
    nearest = np.sum((xyz - xyz[start_index]) ** 2, axis=1)
    nearest[start_index] = -1.0  # never pick a selected point again, even among duplicates
    for j in range(1, n_samples):
        selected[j] = np.argmax(nearest)  # argmax returns the lowest index among ties
        nearest = np.minimum(nearest, np.sum((xyz - xyz[selected[j]]) ** 2, axis=1))
        nearest[selected[: j + 1]] = -1.0
    return selected


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
