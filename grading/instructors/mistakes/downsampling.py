"""Known mistakes of ``pcl_course/downsampling.py``: voxel filters, FPS, normal-space sampling."""

import numpy as np

from grading.instructors.mistakes import RANDOM, Mistake, Model, Variants, same, valid_points

MAX_LOOPED_POINTS = 200_000  # the hash-table filter is replayed point by point up to this size
MAX_FPS_WORK = 400_000_000  # points x samples replayed for farthest point sampling


def _cells(xyz, voxel_size, origin="minimum"):
    lower = xyz.min(axis=0) if origin == "minimum" else np.zeros(3)
    return np.floor((xyz - lower) / voxel_size).astype(np.int64), lower


# -- voxel_grid_downsample --------------------------------------------------------------------


def voxel_grid(points, voxel_size, method="centroid", rng=None, **changes):
    """The exact filter, with the contract's ordering unless ``changes`` say otherwise."""
    data = valid_points(points, min_columns=3)
    if not voxel_size > 0:
        raise ValueError("voxel_size")
    if len(data) == 0:
        return np.empty((0, data.shape[1]))
    origin = changes.get("origin", "minimum")
    cells, lower = _cells(data[:, :3], voxel_size, origin)
    keys = _voxel_keys(data[:, :3], cells, lower, voxel_size, changes.get("grid", "exact"))
    _, first, inverse, counts = np.unique(keys, axis=0, return_index=True, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    if changes.get("order") == "appearance":
        rank = np.argsort(np.argsort(first, kind="stable"), kind="stable")
        inverse, first, counts = rank[inverse], first[np.argsort(first)], counts[np.argsort(first)]
    if changes.get("order") == "z_fastest":
        rank = _z_fastest_rank(cells, inverse, len(counts))
        inverse = rank[inverse]
        first, counts = _reorder(first, rank), _reorder(counts, rank)
    if method == "random":
        pick = changes.get("pick")
        if pick is None:
            return RANDOM
        members = np.argsort(inverse, kind="stable")
        ends = np.cumsum(counts)
        chosen = members[ends - counts] if pick == "first" else members[ends - 1]
        return data[chosen]
    sums = np.zeros((len(counts), data.shape[1]))
    np.add.at(sums, inverse, data)
    out = sums / counts[:, None]
    if changes.get("extra") == "first" and data.shape[1] > 3:
        out[:, 3:] = data[first, 3:]
    if changes.get("extra") == "dropped":
        out = out[:, :3]
    if changes.get("centres"):
        out[:, :3] = lower + (cells[first] + 0.5) * voxel_size
    if changes.get("drop_last"):
        out = out[:-1]
    return out


def _reorder(values, rank):
    out = np.empty_like(values)
    out[rank] = values
    return out


def _z_fastest_rank(cells, inverse, count):
    representative = np.zeros((count, 3), dtype=np.int64)
    representative[inverse] = cells
    order = np.lexsort((representative[:, 2], representative[:, 1], representative[:, 0]))
    rank = np.empty(count, dtype=np.int64)
    rank[order] = np.arange(count)
    return rank


def _voxel_keys(xyz, cells, lower, voxel_size, grid):
    """One sort key per point: exact (h_z, h_y, h_x), or the linear index of a mistaken grid."""
    if grid == "exact":
        return np.stack([cells[:, 2], cells[:, 1], cells[:, 0]], axis=1)
    extent = (xyz.max(axis=0) - lower) / voxel_size
    if grid == "ceil":
        dims = np.maximum(np.ceil(extent).astype(np.int64), 1)
    elif grid == "unrounded":
        dims = extent
    else:
        dims = np.floor(extent).astype(np.int64) + 1
    if grid == "int32":
        cells, dims = cells.astype(np.int32), dims.astype(np.int32)
    with np.errstate(over="ignore"):
        return (cells[:, 0] + cells[:, 1] * dims[0] + cells[:, 2] * dims[0] * dims[1])[:, None]


def _voxel(**changes):
    """A voxel mistake's answers, with exact voxel keys or with the common int64 linear index
    (whose overflow on huge grids is a second mistake that must not hide the first)."""

    def predict(points, voxel_size, method="centroid", rng=None):
        if (method == "random") != ("pick" in changes):
            return None
        answers = [voxel_grid(points, voxel_size, method, rng, **changes)]
        if "grid" not in changes:
            answers.append(voxel_grid(points, voxel_size, method, rng, grid="int64", **changes))
        return Variants(answers)

    return predict


VOXEL_GRID_DOWNSAMPLE = Model(
    truth=voxel_grid,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "ceil_dimensions",
            "the grid size per axis is D = floor((max - min) / voxel_size) + 1, not ceil(...): when the extent is "
            "a multiple of voxel_size, the points at the maximum collide with another voxel's index",
            _voxel(grid="ceil"),
        ),
        Mistake(
            "drops_last_voxel",
            "the last voxel is missing: one row per occupied voxel, the last one included (a loop over sorted "
            "points must also emit the run it is in when the points run out)",
            _voxel(drop_last=True),
        ),
        Mistake(
            "extra_columns_dropped",
            "return every column: the extra columns (intensity, ...) travel with their row and are averaged too",
            _voxel(extra="dropped"),
        ),
        Mistake(
            "extra_columns_not_averaged",
            "average ALL columns of the voxel's rows, the extra ones too, not only x, y, z",
            _voxel(extra="first"),
        ),
        Mistake(
            "first_appearance_order",
            "order the output rows by increasing linear voxel index (x fastest, then y, then z), not by first "
            "appearance in the input",
            _voxel(order="appearance"),
        ),
        Mistake(
            "int32_index",
            "the linear index overflows int32 on large grids and merges distinct voxels: compute it in int64, or "
            "sort by (h_z, h_y, h_x) with np.lexsort",
            _voxel(grid="int32"),
        ),
        Mistake(
            "int64_index",
            "the linear index overflows even int64 when D_x * D_y * D_z > 2^63 and merges distinct voxels: sort "
            "by (h_z, h_y, h_x) (np.lexsort, or np.unique(..., axis=0)) instead of one linear number",
            _voxel(grid="int64"),
        ),
        Mistake(
            "origin_at_zero",
            "the grid's origin is the per-axis minimum of the points: h = floor((p - min) / voxel_size)",
            _voxel(origin="zero"),
        ),
        Mistake(
            "random_first_point",
            "method='random' must pick one of the voxel's rows uniformly at random with rng: yours always takes "
            "the first",
            _voxel(pick="first"),
        ),
        Mistake(
            "random_last_point",
            "method='random' must pick one of the voxel's rows uniformly at random with rng: yours always takes "
            "the last",
            _voxel(pick="last"),
        ),
        Mistake(
            "unrounded_dimensions",
            "the grid size per axis is the integer D = floor((max - min) / voxel_size) + 1: with the unrounded "
            "ratio the linear index is not an integer and distinct voxels can share it",
            _voxel(grid="unrounded"),
        ),
        Mistake(
            "voxel_centres",
            "return the centroid of each voxel's points, not the centre of the voxel",
            _voxel(centres=True),
        ),
        Mistake(
            "z_fastest_order",
            "the linear index h_x + h_y D_x + h_z D_x D_y makes x the FASTEST axis: sort by (h_z, h_y, h_x), "
            "not by (h_x, h_y, h_z) (np.unique of the rows)",
            _voxel(order="z_fastest"),
        ),
    ),
)


# -- approximate_voxel_downsample ------------------------------------------------------------------


def hash_filter(points, voxel_size, n_containers, method="centroid", rng=None, **changes):
    data = valid_points(points, min_columns=3)
    if not voxel_size > 0 or int(n_containers) < 1:
        raise ValueError("voxel_size or n_containers")
    if len(data) > MAX_LOOPED_POINTS:
        raise ValueError("too large to replay")
    if len(data) == 0:
        return np.empty((0, data.shape[1]))
    if method == "random" and changes.get("pick") is None:
        return RANDOM
    cells, lower = _cells(data[:, :3], voxel_size)
    dims = np.floor((data[:, :3].max(axis=0) - lower) / voxel_size).astype(np.int64) + 1
    index = cells[:, 0] + cells[:, 1] * dims[0] + cells[:, 2] * (dims[0] * dims[1])
    slots = (cells[:, 0] if changes.get("hash") == "x" else index) % int(n_containers)
    held, rows, out = {}, {}, []

    def emit(members):
        out.append(data[members].mean(axis=0) if method == "centroid" else data[members[0]])

    for i in range(len(data)):
        slot = int(slots[i])
        if slot in held and held[slot] != index[i] and not changes.get("merge"):
            members = rows.pop(slot)
            if not changes.get("drop_on_conflict"):
                emit(members)
            del held[slot]
        if slot not in held:
            held[slot], rows[slot] = index[i], []
        rows[slot].append(i)
    for slot in list(rows) if changes.get("order") == "insertion" else sorted(rows):
        emit(rows[slot])
    return np.array(out).reshape(-1, data.shape[1])


def _hash(**changes):
    def predict(points, voxel_size, n_containers, method="centroid", rng=None):
        if (method == "random") != ("pick" in changes):
            return None
        return hash_filter(points, voxel_size, n_containers, method, rng, **changes)

    return predict


APPROXIMATE_VOXEL_DOWNSAMPLE = Model(
    truth=hash_filter,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "conflict_drops_the_old_voxel",
            "on a conflict, first EMIT one row for what the container holds, then start it afresh with the new "
            "point: yours drops the old voxel's points",
            _hash(drop_on_conflict=True),
        ),
        Mistake(
            "hash_of_x_only",
            "the container is the full linear index h_x + h_y * D_x + h_z * D_x * D_y modulo n_containers, not "
            "h_x alone",
            _hash(hash="x"),
        ),
        Mistake(
            "insertion_order_at_the_end",
            "at the end, emit the non-empty containers in increasing container order, not in the order they "
            "were filled",
            _hash(order="insertion"),
        ),
        Mistake(
            "no_conflict_detection",
            "a container holds ONE voxel at a time: when a point of another voxel arrives, emit and restart the "
            "container (yours merges distinct voxels that share it)",
            _hash(merge=True),
        ),
        Mistake(
            "random_first_row",
            "method='random' must emit a uniformly random row of the container (with rng): yours always emits "
            "its first row",
            _hash(pick="first"),
        ),
    ),
)


# -- farthest_point_sampling ------------------------------------------------------------------------


def fps(points, n_samples, start_index=0, **changes):
    data = valid_points(points, min_columns=3)
    n_samples, start_index = int(n_samples), int(start_index)
    if not 0 <= n_samples <= len(data) or not 0 <= start_index < max(len(data), 1):
        raise ValueError("n_samples or start_index")
    if len(data) * n_samples > MAX_FPS_WORK:
        raise ValueError("too large to replay")
    xyz = data if changes.get("columns") == "all" else data[:, :3]
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)

    def gap(i):
        if changes.get("metric") == "l1":
            return np.abs(xyz - xyz[i]).sum(axis=1)
        return ((xyz - xyz[i]) ** 2).sum(axis=1)

    first = 0 if changes.get("ignore_start") else start_index
    chosen = [first]
    # A finite start value ("distance = 1e10") caps every nearest distance at it.
    nearest = np.minimum(gap(first), changes.get("sentinel", np.inf))
    taken = np.zeros(len(xyz), bool)
    taken[first] = True
    while len(chosen) < n_samples:
        scores = nearest.copy()
        if not changes.get("repeats"):
            scores[taken] = -1.0
        if changes.get("ties") == "highest":
            pick = len(scores) - 1 - int(np.argmax(scores[::-1]))
        else:
            pick = int(np.argmax(scores))
        chosen.append(pick)
        taken[pick] = True
        distances = gap(pick)
        nearest = distances if changes.get("last_only") else np.minimum(nearest, distances)
    return np.array(chosen, dtype=np.int64)


def _fps(**changes):
    return lambda points, n_samples, start_index=0: fps(points, n_samples, start_index, **changes)


FARTHEST_POINT_SAMPLING = Model(
    truth=fps,
    output_dtypes=("int64",),
    mistakes=(
        Mistake(
            "all_columns",
            "measure distances over x, y, z only (points[:, :3]): the extra columns are attributes, not coordinates",
            _fps(columns="all"),
        ),
        Mistake(
            "l1_distance",
            "use the (squared) Euclidean distance, sum((p - q) ** 2), not the L1 (Manhattan) distance",
            _fps(metric="l1"),
        ),
        Mistake(
            "last_selected_only",
            "each point's distance is to its NEAREST selected point: keep the running minimum over all selected "
            "points (np.minimum), not the distance to the last one",
            _fps(last_only=True),
        ),
        Mistake(
            "repeats_indices",
            "never pick an index twice: exclude the selected points (with duplicates, the farthest can be one "
            "already taken)",
            _fps(repeats=True),
        ),
        Mistake(
            "start_index_ignored",
            "the first index must be start_index: yours always starts at 0",
            _fps(ignore_start=True),
        ),
        Mistake(
            "ties_to_highest_index",
            "ties go to the LOWEST index (np.argmax returns the first maximum)",
            _fps(ties="highest"),
        ),
        Mistake(
            "finite_sentinel",
            "start each point's nearest distance at +inf: a finite start value such as 1e10 is smaller than the "
            "squared distances of clouds far apart (coordinates around 1e6), and then picks the wrong points",
            lambda points, n_samples, start_index=0: Variants(
                [fps(points, n_samples, start_index, sentinel=1e10, repeats=repeats) for repeats in (False, True)]
            ),
        ),
    ),
)


# -- normal_space_sampling ------------------------------------------------------------------------------


class _Buckets:
    """What a normal-space sample must look like, as bucket labels in draw order.

    ``labels[i]`` is point i's bucket under some bucketing; an answer
    matches when its indices are distinct and their labels, in draw order,
    are ``sequence``. Whether two such structures differ is decided on a
    canonical answer (each bucket's points in index order).
    """

    def __init__(self, labels, sequence, rounds=None):
        self.labels, self.sequence, self.rounds = labels, sequence, rounds

    def accepts(self, indices):
        indices = np.asarray(indices)
        if indices.ndim != 1 or len(np.unique(indices)) != len(indices) or len(indices) != len(self.sequence):
            return False
        if indices.dtype.kind not in "iu" or np.any(indices < 0) or np.any(indices >= len(self.labels)):
            return False
        got = self.labels[indices]
        if self.rounds is None:
            return bool(np.array_equal(got, self.sequence))
        return _rounds_are_permutations(got, self.rounds)

    def canonical(self):
        queues = {b: list(np.flatnonzero(self.labels == b)) for b in np.unique(self.labels)}
        return np.array([queues[b].pop(0) for b in self.sequence], dtype=np.int64)


def _rounds_are_permutations(got, rounds):
    """Each round visits each of its buckets once, in any order, and not all rounds in increasing order."""
    position, in_order = 0, True
    for members in rounds:
        chunk = got[position : position + len(members)]
        if sorted(chunk.tolist()) != sorted(members):
            return False
        in_order &= chunk.tolist() == sorted(members)
        position += len(members)
    return not in_order


def _bucket_labels(normals, n_bins, clip=True, x_slowest=False):
    bins = np.floor((normals + 1.0) / 2.0 * n_bins)
    if clip:
        bins = np.clip(bins, 0, n_bins - 1)
    bins = bins.astype(np.int64)
    width = n_bins + 1 if not clip else n_bins  # an unclipped bin index can reach n_bins
    if x_slowest:
        return bins[:, 2] + bins[:, 1] * width + bins[:, 0] * width**2
    return bins[:, 0] + bins[:, 1] * width + bins[:, 2] * width**2


def _round_robin(labels, n_samples):
    queues = {b: int(np.sum(labels == b)) for b in np.unique(labels)}
    sequence, rounds = [], []
    while len(sequence) < n_samples:
        this_round = []
        for b in sorted(queues):
            if queues[b] and len(sequence) < n_samples:
                queues[b] -= 1
                sequence.append(b)
                this_round.append(b)
        rounds.append(this_round)
    return np.array(sequence, dtype=np.int64), rounds


def sampling(normals, n_samples, n_bins=4, rng=None, **changes):
    directions = np.array(normals, dtype=float)
    if directions.ndim != 2 or directions.shape[1] != 3 or not np.isfinite(directions).all():
        raise ValueError("normals")
    if not 0 <= int(n_samples) <= len(directions) or int(n_bins) < 1:
        raise ValueError("n_samples or n_bins")
    labels = _bucket_labels(directions, int(n_bins), changes.get("clip", True), changes.get("x_slowest", False))
    sequence, rounds = _round_robin(labels, int(n_samples))
    buckets = _Buckets(labels, sequence, rounds if changes.get("shuffled_rounds") else None)
    if changes.get("index_order"):
        return _Exact(buckets)
    return buckets


class _Exact:
    """A deterministic answer where the contract draws at random (each bucket's points in index order)."""

    def __init__(self, buckets):
        self.buckets, self.indices = buckets, buckets.canonical()

    def chance(self):
        """The chance that a right answer (uniform draws) takes each bucket's points in index order."""
        chance = 1.0
        for b in np.unique(self.buckets.sequence):
            size, draws = int(np.sum(self.buckets.labels == b)), int(np.sum(self.buckets.sequence == b))
            for j in range(draws):
                chance /= size - j
        return chance


def _sampling_same(a, b, arguments):
    if isinstance(b, _Exact):
        if isinstance(a, _Buckets):  # the truth: the same only where no draw had a choice
            return b.chance() >= 1.0
        return same(a, b.indices)
    if isinstance(a, _Buckets) and isinstance(b, _Buckets):
        return b.accepts(a.canonical()) and a.accepts(b.canonical())
    if isinstance(a, _Buckets):
        a, b = b, a
    if isinstance(b, _Buckets):
        return not isinstance(a, _Buckets) and b.accepts(a)
    return same(a, b)


def _sampling(**changes):
    return lambda normals, n_samples, n_bins=4, rng=None: sampling(normals, n_samples, n_bins, rng, **changes)


NORMAL_SPACE_SAMPLING = Model(
    truth=sampling,
    same=_sampling_same,
    output_dtypes=("int64",),
    unique_truth=False,  # the truth is the set of draws the contract allows
    mistakes=(
        Mistake(
            "index_order_in_bucket",
            "each draw takes a uniformly RANDOM not-yet-taken point of its bucket (with rng): yours takes the "
            "bucket's points in index order",
            _sampling(index_order=True),
        ),
        Mistake(
            "no_clip",
            "clip each bin index to n_bins - 1: a normal component of exactly 1 gives floor(n_bins), a bin "
            "outside the grid",
            _sampling(clip=False),
        ),
        Mistake(
            "x_slowest_bucket_id",
            "the bucket id is b_x + b_y * n_bins + b_z * n_bins**2 (x fastest): the round-robin visits the "
            "buckets in increasing id, so the id's order matters",
            _sampling(x_slowest=True),
        ),
        Mistake(
            "buckets_in_random_order",
            "every round visits the non-empty buckets in INCREASING bucket id: only the point drawn within each "
            "bucket is random",
            _sampling(shuffled_rounds=True),
        ),
    ),
)


MODELS = {
    "voxel_grid_downsample": VOXEL_GRID_DOWNSAMPLE,
    "approximate_voxel_downsample": APPROXIMATE_VOXEL_DOWNSAMPLE,
    "farthest_point_sampling": FARTHEST_POINT_SAMPLING,
    "normal_space_sampling": NORMAL_SPACE_SAMPLING,
}
