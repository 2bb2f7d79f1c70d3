"""Graded tests of the downsampling exercises (``pcl_course/downsampling.py``).

Expected values come from hand-built clouds whose voxels, containers, buckets
and farthest points are known by construction, from NumPy group-bys the test
computes itself (``np.unique``), and from the greedy definition of farthest
point sampling evaluated with SciPy (checked against Open3D by the project's tests). Random methods are tested
statistically over fixed seeds.
"""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from grading.checks import check_array, check_close, raises


def voxel_keys(xyz, size):
    """Per-axis voxel coordinates with the origin at the per-axis minimum."""
    return np.floor((xyz - xyz.min(axis=0)) / size).astype(np.int64)


def expected_centroids(points, size):
    """Centroids of the occupied voxels, ordered by (h_z, h_y, h_x) -- the test's own group-by."""
    keys = voxel_keys(points[:, :3], size)
    _, inverse, counts = np.unique(keys[:, ::-1], axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    sums = np.zeros((len(counts), points.shape[1]))
    np.add.at(sums, inverse, points)
    return sums / counts[:, None]


@pytest.fixture
def cloud():
    """3000 points with 2 extra columns, shifted away from the origin."""
    rng = np.random.default_rng(31)
    xyz = rng.uniform(0.0, 1.0, size=(3000, 3)) * [2.0, 1.0, 0.5] + [-3.7, 12.2, 0.35]
    extra = rng.uniform(size=(3000, 2))
    return np.hstack([xyz, extra])


# --- voxel_grid_downsample ------------------------------------------------------


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(1)
@pytest.mark.interface
def test_voxel_grid_downsample_returns_a_float64_array(impl, cloud):
    result = impl.voxel_grid_downsample(cloud, 0.25)
    check_array(result, "downsampled", shape=(None, 5))


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(3)
def test_voxel_grid_downsample_centroids_in_linear_index_order(impl, cloud):
    result = impl.voxel_grid_downsample(cloud, 0.25)
    expected = expected_centroids(cloud, 0.25)
    check_close(
        result,
        expected,
        "centroids",
        rtol=1e-9,
        atol=1e-12,
        hint="one row per occupied voxel (origin at the per-axis minimum, h = floor((p - min) / voxel_size)), "
        "the mean of ALL columns, ordered by linear index (x fastest, then y, z)",
    )


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(2)
def test_voxel_grid_downsample_hand_built_voxels(impl):
    # Voxel size 1, minimum at (0.5, 0.5, 0.5): the origin is the minimum, not 0.
    points = np.array(
        [
            [0.5, 0.5, 0.5, 10.0],  # h = (0, 0, 0), linear index 0
            [1.4, 0.6, 0.7, 20.0],  # h = (0, 0, 0)
            [1.6, 0.5, 0.5, 30.0],  # h = (1, 0, 0), index 1
            [0.5, 1.6, 0.5, 40.0],  # h = (0, 1, 0), index D_x = 3
            [2.6, 2.6, 2.6, 50.0],  # h = (2, 2, 2), the maximum
        ]
    )
    result = impl.voxel_grid_downsample(points, 1.0)
    expected = np.array(
        [
            [0.95, 0.55, 0.6, 15.0],
            [1.6, 0.5, 0.5, 30.0],
            [0.5, 1.6, 0.5, 40.0],
            [2.6, 2.6, 2.6, 50.0],
        ]
    )
    check_close(result, expected, "downsampled", hint="origin at the per-axis MINIMUM of the points")


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(2)
def test_voxel_grid_downsample_when_the_extent_is_a_multiple_of_the_size(impl):
    # Extent exactly 2 voxels on x: the grid needs floor(2) + 1 = 3 cells, or
    # the point at the maximum collides with another voxel's index.
    points = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.5, 0.0], [1.0, 0.0, 0.0]])
    result = impl.voxel_grid_downsample(points, 1.0)
    expected = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.5, 0.0]])
    check_close(result, expected, "downsampled", hint="grid size per axis D = floor((max - min) / voxel_size) + 1")


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(3)
def test_voxel_grid_downsample_on_a_grid_too_large_for_int64(impl):
    # D_x = D_y = 2^16 and h_z = 2^32: the linear index of the last point is
    # 2^64, which wraps to 0 in int64 and would merge it with the first.
    points = np.array([[0.0, 0.0, 0.0], [65535.0, 65535.0, 0.0], [0.0, 0.0, 2.0**32], [1.0, 0.0, 2.0**32]])
    result = impl.voxel_grid_downsample(points[[2, 0, 3, 1]], 1.0)  # the output is in voxel order
    check_close(
        result,
        points,
        "downsampled",
        hint="4 distinct voxels; the linear index overflows int64 here: sort by (h_z, h_y, h_x) instead",
    )


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(2)
def test_voxel_grid_downsample_on_a_lidar_sized_grid(impl):
    # The lecture's case: 200 m x 200 m x 20 m at 5 cm is 6.4e9 voxels > 2^32.
    rng = np.random.default_rng(32)
    xyz = rng.uniform([-100, -100, -10], [100, 100, 10], size=(4000, 3))
    xyz = np.vstack([xyz, xyz[:500] + 0.001])  # some voxels hold two points
    result = impl.voxel_grid_downsample(xyz, 0.05)
    expected = expected_centroids(xyz, 0.05)
    check_close(
        result,
        expected,
        "centroids",
        rtol=1e-12,
        atol=1e-9,
        hint="int32 linear indices overflow on this grid (6.4e9 voxels)",
    )


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(3)
def test_voxel_grid_downsample_random_picks_every_row_uniformly(impl):
    # One voxel of 4 rows: over 400 seeds each row must be picked about 100 times.
    points = np.array(
        [[0.1, 0.1, 0.1, 0.0], [0.2, 0.3, 0.1, 1.0], [0.4, 0.2, 0.3, 2.0], [0.3, 0.4, 0.2, 3.0], [5.0, 5.0, 5.0, 4.0]]
    )
    picks = []
    for seed in range(400):
        result = impl.voxel_grid_downsample(points, 1.0, method="random", rng=seed)
        check_array(result, "downsampled", shape=(2, 4))  # 2 voxels; float64, or no row can equal an input row
        assert any(np.array_equal(result[0], row) for row in points[:4]), (
            f"method='random' must return one of the voxel's input rows, got {result[0]}"
        )
        picks.append(int(result[0, 3]))
    counts = np.bincount(picks, minlength=4)
    assert counts.min() >= 60, f"rows of a voxel picked {counts.tolist()} times in 400 runs: not uniform"


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(1)
def test_voxel_grid_downsample_random_is_reproducible(impl, cloud):
    a = impl.voxel_grid_downsample(cloud, 0.3, method="random", rng=7)
    b = impl.voxel_grid_downsample(cloud, 0.3, method="random", rng=np.random.default_rng(7))
    assert np.array_equal(a, b), "the same seed (int or Generator) must give the same answer"
    assert len(a) == len(expected_centroids(cloud, 0.3)), "one row per occupied voxel"
    rows = {tuple(r) for r in cloud}
    assert all(tuple(r) in rows for r in a), "method='random' must return input rows unchanged"


@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.points(1)
@pytest.mark.interface
def test_voxel_grid_downsample_empty_cloud(impl):
    result = impl.voxel_grid_downsample(np.empty((0, 4)), 0.5)
    check_array(result, "downsampled", shape=(0, 4))


@pytest.mark.points(0.5)
@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"voxel_size": 0.0}, "voxel_size"),
        ({"voxel_size": -1.0}, "voxel_size"),
        ({"method": "median"}, "method"),
        ({"points": np.zeros((4, 2))}, "points"),
    ],
    ids=["size-zero", "size-negative", "method", "width"],
)
@pytest.mark.grades("voxel_grid_downsample")
@pytest.mark.interface
def test_voxel_grid_downsample_rejects_bad_input(impl, kwargs, name):
    arguments = {"points": np.random.default_rng(33).uniform(size=(10, 3)), "voxel_size": 0.5, **kwargs}
    with raises(ValueError, naming=name):
        impl.voxel_grid_downsample(**arguments)


# --- approximate_voxel_downsample ---------------------------------------------------


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(2)
def test_approximate_voxel_downsample_without_conflicts_is_the_exact_filter(impl, cloud):
    # With more containers than the largest linear index, no two voxels share a
    # container: the output is every voxel's centroid in container (= index) order.
    result = impl.approximate_voxel_downsample(cloud, 0.25, n_containers=10**6)
    check_close(result, expected_centroids(cloud, 0.25), "approximate filter without conflicts", rtol=1e-9)


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(3)
def test_approximate_voxel_downsample_hand_built_conflicts(impl):
    # Voxel size 1, D = (4, 2, 1); 3 containers. Linear index -> container:
    # (0,0,0) -> 0 -> 0; (3,0,0) -> 3 -> 0; (1,0,0) -> 1 -> 1; (1,1,0) -> 5 -> 2
    points = np.array(
        [
            [0.1, 0.1, 0.0],  # voxel 0, container 0 (empty): held
            [0.3, 0.2, 0.0],  # voxel 0, container 0: same voxel, held
            [3.5, 0.5, 0.0],  # voxel 3, container 0: CONFLICT -> emit centroid of voxel 0
            [1.5, 0.5, 0.0],  # voxel 1, container 1: held
            [1.5, 1.5, 0.0],  # voxel 5, container 2: held
            [0.4, 0.9, 0.0],  # voxel 0, container 0: CONFLICT -> emit voxel 3
            [1.7, 0.1, 0.0],  # voxel 1, container 1: held
        ]
    )
    result = impl.approximate_voxel_downsample(points, 1.0, n_containers=3)
    expected = np.array(
        [
            [0.2, 0.15, 0.0],  # emitted by the first conflict
            [3.5, 0.5, 0.0],  # emitted by the second conflict
            [0.4, 0.9, 0.0],  # end: container 0
            [1.6, 0.3, 0.0],  # end: container 1
            [1.5, 1.5, 0.0],  # end: container 2
        ]
    )
    check_close(
        result,
        expected,
        "emitted rows",
        hint="on a conflict emit the container's voxel first; at the end emit containers in increasing order",
    )


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(2)
def test_approximate_voxel_downsample_with_one_container(impl):
    # One container: every change of voxel along the input emits the run so far.
    rng = np.random.default_rng(34)
    points = rng.uniform(0, 3, size=(200, 3))
    points = points[np.argsort(np.floor(points[:, 0]))]  # long runs of the same x-slab
    result = impl.approximate_voxel_downsample(points, 1.0, n_containers=1)
    keys = voxel_keys(points, 1.0)
    change = np.flatnonzero(np.any(keys[1:] != keys[:-1], axis=1)) + 1
    runs = np.split(points, change)
    check_close(
        result,
        np.array([run.mean(axis=0) for run in runs]),
        "one-container output",
        rtol=1e-9,
        hint="with one container, each run of consecutive points in one voxel gives one row",
    )


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(2)
def test_approximate_voxel_downsample_hash_uses_all_three_axes(impl):
    # D = (2, 2, 2). Voxels A = (0,0,0), B = (0,1,1) and C = (1,0,0) have
    # linear indices 0, 0 + 1*2 + 1*4 = 6 and 1: containers 0, 6 and 1 of 7,
    # no conflict. A hash of h_x alone would put A and B in one container.
    points = np.array([[0.0, 0.0, 0.0], [0.5, 1.5, 1.5], [1.5, 0.2, 0.1], [0.2, 0.1, 0.0], [0.3, 1.7, 1.1]])
    result = impl.approximate_voxel_downsample(points, 1.0, n_containers=7)
    expected = np.array([[0.1, 0.05, 0.0], [1.5, 0.2, 0.1], [0.4, 1.6, 1.3]])
    check_close(
        result, expected, "emitted rows", hint="linear index h_x + h_y * D_x + h_z * D_x * D_y, then % n_containers"
    )


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(2)
def test_approximate_voxel_downsample_random_returns_rows_of_the_container(impl):
    points = np.array([[0.1, 0.1, 0.1], [0.2, 0.3, 0.4], [0.5, 0.6, 0.7], [3.5, 0.5, 0.5]])
    seen = set()
    for seed in range(200):
        result = impl.approximate_voxel_downsample(points, 1.0, n_containers=1, method="random", rng=seed)
        check_array(result, "emitted rows", shape=(2, 3))  # float64, or no row can equal an input row
        assert np.array_equal(result[1], points[3])
        match = [i for i in range(3) if np.array_equal(result[0], points[i])]
        assert match, f"method='random' must emit one of the container's rows, got {result[0]}"
        seen.add(match[0])
    assert seen == {0, 1, 2}, f"over 200 seeds only rows {sorted(seen)} of the container were ever chosen"


@pytest.mark.grades("approximate_voxel_downsample")
@pytest.mark.points(1)
@pytest.mark.interface
def test_approximate_voxel_downsample_rejects_bad_input(impl):
    points = np.random.default_rng(35).uniform(size=(10, 3))
    for kwargs, name in (
        ({"n_containers": 0}, "n_containers"),
        ({"voxel_size": 0.0}, "voxel_size"),
        ({"method": "mode"}, "method"),
    ):
        arguments = {"points": points, "voxel_size": 0.5, "n_containers": 10, **kwargs}
        with raises(ValueError, naming=name):
            impl.approximate_voxel_downsample(**arguments)


# --- farthest_point_sampling -------------------------------------------------------------


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(1)
@pytest.mark.interface
def test_farthest_point_sampling_returns_int64_indices(impl, cloud):
    result = impl.farthest_point_sampling(cloud, 10)
    check_array(result, "indices", shape=(10,), dtype="int64")
    assert result[0] == 0, "the first index is start_index (default 0)"


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_on_a_line(impl):
    x = np.array([0.0, 1.0, 3.0, 7.0, 10.0, 4.0])
    points = np.column_stack([x, np.zeros(6), np.zeros(6)])
    # From x=0 the farthest is x=10 (index 4). Distances to the nearest of
    # {0, 10}: x=1: 1, x=3: 3, x=7: 3, x=4: 4 -> index 5 (x=4). Then to the
    # nearest of {0, 10, 4}: x=3: 1, x=7: 3, x=1: 1 -> index 3 (x=7).
    result = impl.farthest_point_sampling(points, 4)
    check_array(result, "indices", shape=(4,), dtype=None)  # before any .tolist()
    assert result.tolist() == [0, 4, 5, 3], (
        f"expected [0, 4, 5, 3], got {result.tolist()}; hint: the next point maximises the distance to "
        "its NEAREST selected point; ties go to the lowest index"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_uses_the_nearest_selected_point(impl):
    # After 0 and 1, point 2 is far from point 1 (the last selected) but close
    # to point 0; point 3 is farther from both.
    points = np.array([[0.0, 0, 0], [10.0, 0, 0], [0.5, 0, 0], [5.0, 4.0, 0]])
    result = impl.farthest_point_sampling(points, 3)
    check_array(result, "indices", shape=(3,), dtype=None)  # before any .tolist()
    assert result.tolist() == [0, 1, 3], (
        f"expected [0, 1, 3], got {result.tolist()}: the distance to the NEAREST selected point, not to the last one"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_uses_euclidean_distance(impl):
    # From the origin: (3, 3, 0) is farther in L1 (6) but nearer in L2 (4.24)
    # than (4.5, 0, 0) (4.5).
    points = np.array([[0.0, 0, 0], [3.0, 3.0, 0], [4.5, 0, 0]])
    result = impl.farthest_point_sampling(points, 2)
    check_array(result, "indices", shape=(2,), dtype=None)  # before any .tolist()
    assert result.tolist() == [0, 2], f"expected [0, 2] (Euclidean distance), got {result.tolist()}"


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(1)
def test_farthest_point_sampling_uses_only_xyz(impl):
    # x = 0..5 on a line, a large fourth column at 1 and 4. On xyz: 5 is farthest from 0; then 2 and 3
    # tie at distance 2 from {0, 5}, and the lower index wins. Counting the column would pick 1 or 4.
    points = np.column_stack([np.arange(6.0), np.zeros(6), np.zeros(6), [0.0, 100, 0, 0, 100, 0]])
    result = impl.farthest_point_sampling(points, 3)
    check_array(result, "indices", shape=(3,), dtype=None)  # before any .tolist()
    assert result.tolist() == [0, 5, 2], f"extra columns must not count in the distance, got {result.tolist()}"


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_start_index_and_ties(impl):
    # A square: from corner 2, the opposite corner 0 is farthest; then 1 and 3
    # tie (same distance to their nearest selected corner): lowest index first.
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 1, 0], [0.0, 1, 0]])
    result = impl.farthest_point_sampling(points, 4, start_index=2)
    check_array(result, "indices", shape=(4,), dtype=None)  # before any .tolist()
    assert result.tolist() == [2, 0, 1, 3], (
        f"expected [2, 0, 1, 3], got {result.tolist()}: start at start_index, ties to the lowest index"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_never_repeats_with_duplicates(impl):
    points = np.array([[0.0, 0, 0], [0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [0.5, 0, 0]])
    result = impl.farthest_point_sampling(points, 5)
    check_array(result, "indices", shape=(5,), dtype=None)  # before any .tolist()
    assert sorted(result.tolist()) == [0, 1, 2, 3, 4], f"indices must not repeat, got {result.tolist()}"
    assert result[:3].tolist() == [0, 2, 4], f"expected to start [0, 2, 4], got {result.tolist()}"


def greedy_farthest_points(points, n_samples, start_index=0):
    """Farthest point sampling by its definition, with SciPy's distances: each
    next index maximises the distance to the nearest selected point (ties to the
    lowest index). tests/project/test_oracles.py checks it against Open3D's
    ``farthest_point_down_sample``."""
    selected = [start_index]
    nearest = cdist(points, points[[start_index]])[:, 0]
    for _ in range(n_samples - 1):
        selected.append(int(np.argmax(nearest)))
        nearest = np.minimum(nearest, cdist(points, points[[selected[-1]]])[:, 0])
    return np.array(selected)


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_matches_the_greedy_definition(impl):
    # 300 picks of 2,000: a sampler that follows the rule for its first picks only (then fills in
    # index order, or at random) is caught however late it stops.
    rng = np.random.default_rng(36)
    points = rng.uniform(size=(2000, 3))
    expected = greedy_farthest_points(points, 300)
    result = impl.farthest_point_sampling(points, 300)
    check_array(result, "indices", shape=(300,), dtype="int64")
    first = int(np.argmax(result != expected)) if not np.array_equal(result, expected) else None
    assert first is None, (
        f"selection {first} is index {result[first]}, expected {expected[first]}: each next point is the one "
        "farthest from its nearest selected point"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(2)
def test_farthest_point_sampling_far_from_the_origin(impl):
    # On a line at x = 1e6 * (0, 1, 4, 2, 3): squared distances reach 1.6e13.
    # From 0 the farthest is 2 (4e6); then 3, at 2e6 from both. A "distance
    # = 1e10" start value for "not measured yet" is smaller than every true
    # distance here and picks index 1 instead.
    points = np.column_stack([1e6 * np.array([0.0, 1.0, 4.0, 2.0, 3.0]), np.zeros(5), np.zeros(5)])
    result = impl.farthest_point_sampling(points, 3)
    check_array(result, "indices", shape=(3,), dtype="int64")
    assert result.tolist() == [0, 2, 3], (
        f"expected [0, 2, 3], got {result.tolist()}: start the nearest-distances at +inf "
        "(no finite sentinel is larger than every squared distance)"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(0.5)
def test_farthest_point_sampling_zero_and_all_samples(impl, cloud):
    check_array(impl.farthest_point_sampling(cloud, 0), "indices", shape=(0,), dtype="int64")
    # Every point of 300 (of the whole cloud, a plain-Python search of N^2 = 9e6 distances took 25 s).
    part = cloud[:300]
    every = impl.farthest_point_sampling(part, len(part), start_index=7)
    check_array(every, "indices", shape=(len(part),), dtype="int64")
    assert every[0] == 7 and np.array_equal(np.sort(every), np.arange(len(part))), (
        "n_samples = N selects every point once, starting at start_index"
    )


@pytest.mark.grades("farthest_point_sampling")
@pytest.mark.points(0.5)
@pytest.mark.interface
def test_farthest_point_sampling_rejects_bad_arguments(impl, cloud):
    for kwargs, name in (
        ({"n_samples": 3001}, "n_samples"),
        ({"n_samples": -1}, "n_samples"),
        ({"start_index": 3000}, "start_index"),
    ):
        arguments = {"points": cloud, "n_samples": 5, **kwargs}
        with raises(ValueError, naming=name):
            impl.farthest_point_sampling(**arguments)


# --- normal_space_sampling ------------------------------------------------------------------


def bucket(normals, n_bins):
    b = np.clip(np.floor((normals + 1.0) / 2.0 * n_bins), 0, n_bins - 1).astype(int)
    return b[:, 0] + b[:, 1] * n_bins + b[:, 2] * n_bins**2


@pytest.fixture
def skewed_normals():
    """90 % of the normals point up (a floor), the rest in four other directions."""
    rng = np.random.default_rng(37)
    directions = np.array([[0.0, 0, 1], [1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0.6, 0.0, -0.8]])
    choice = np.concatenate([np.zeros(900, int), rng.integers(1, 5, 100)])
    normals = directions[choice] + rng.normal(scale=0.02, size=(1000, 3))
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(1)
def test_normal_space_sampling_returns_distinct_int64_indices(impl, skewed_normals):
    result = impl.normal_space_sampling(skewed_normals, 200, rng=0)
    check_array(result, "indices", shape=(200,), dtype="int64")
    assert len(set(result.tolist())) == 200, "indices must not repeat"
    assert result.min() >= 0 and result.max() < 1000


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(3)
def test_normal_space_sampling_draws_round_robin_over_buckets(impl, skewed_normals):
    ids = bucket(skewed_normals, 4)
    occupied, sizes = np.unique(ids, return_counts=True)
    result = impl.normal_space_sampling(skewed_normals, 300, n_bins=4, rng=1)
    check_array(result, "indices", shape=(300,), dtype=None)  # before any .tolist()
    expected, rounds = [], 0
    while len(expected) < 300:  # the bucket sequence is fixed by the contract
        expected += [b for b, s in zip(occupied, sizes) if s > rounds]
        rounds += 1
    assert ids[result].tolist() == expected[:300], (
        f"bucket sequence of the draws {ids[result][:12].tolist()}... expected {expected[:12]}...: "
        "round-robin over non-empty buckets in increasing bucket id, skipping exhausted ones"
    )


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(2)
def test_normal_space_sampling_keeps_rare_orientations(impl, skewed_normals):
    result = impl.normal_space_sampling(skewed_normals, 100, rng=2)
    check_array(result, "indices", shape=(100,), dtype=None)  # before any .tolist()
    up = np.sum(skewed_normals[result, 2] > 0.9)
    assert up <= 40, f"{up} of 100 samples are floor normals: normal space sampling must not sample uniformly"


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(2)
def test_normal_space_sampling_is_uniform_within_a_bucket(impl):
    normals = np.tile([0.0, 0.0, 1.0], (5, 1))  # one bucket of five points
    first = [int(impl.normal_space_sampling(normals, 1, rng=seed)[0]) for seed in range(300)]
    counts = np.bincount(first, minlength=5)
    assert counts.min() >= 30, f"first draw from a 5-point bucket over 300 seeds: {counts.tolist()}"
    again = impl.normal_space_sampling(normals, 5, rng=np.random.default_rng(4))
    assert np.array_equal(again, impl.normal_space_sampling(normals, 5, rng=4)), "same seed, same answer"


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(2)
def test_normal_space_sampling_bucket_boundaries(impl):
    # n_bins = 3. A component of exactly 1 must be clipped into the last bin:
    # (1, 0, 0) then shares bucket 2 + 1*3 + 1*9 = 14 with (0.9, 0, 0.1)/norm,
    # so one of them waits for the second round. -1 falls in bin 0, 0 in bin 1.
    normals = np.array([[1.0, 0.0, 0.0], [0.9, 0.0, 0.1], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    ids = bucket(normals, 3)
    assert ids.tolist() == [14, 14, 12, 22, 4]
    for seed in range(5):
        result = impl.normal_space_sampling(normals, 5, n_bins=3, rng=seed)
        check_array(result, "indices", shape=(5,), dtype=None)  # before any .tolist()
        assert ids[result].tolist() == [4, 12, 14, 22, 14], (
            f"bucket ids of the draws {ids[result].tolist()}, expected [4, 12, 14, 22, 14]: "
            "b = clip(floor((n + 1) / 2 * n_bins), 0, n_bins - 1), id = b_x + b_y n_bins + b_z n_bins^2"
        )


@pytest.mark.grades("normal_space_sampling")
@pytest.mark.points(1)
@pytest.mark.interface
def test_normal_space_sampling_rejects_bad_input(impl, skewed_normals):
    for kwargs, name in (
        ({"n_samples": 1001}, "n_samples"),
        ({"n_bins": 0}, "n_bins"),
        ({"normals": np.zeros((5, 2))}, "normals"),
    ):
        arguments = {"normals": skewed_normals, "n_samples": 10, **kwargs}
        with raises(ValueError, naming=name):
            impl.normal_space_sampling(**arguments)
