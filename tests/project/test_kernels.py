"""Every compiled kernel of ``solutions/_fast``, on the inputs that stress it, on many threads, bounds-checked.

numba checks no index by default: a kernel that reads or writes out of range
corrupts memory silently, and on threads shows only now and then, as a crash
of the process that ran it. So every test of the kernels (marker
``kernels``: this module, ``test_fast_paths.py``, ``test_trees.py`` and
``test_oracles.py``) and every graded test of the references runs a second
time with numba's bounds checking on (:func:`test_the_kernel_tests_pass_bounds_checked`):
an index out of range is then an ``IndexError`` in the test that made it.

The stress: clouds of one, two and k + 1 points, one leaf and one leaf and a
point, every point equal, lattice ties, a line, coordinates far from the
origin; every threaded path on 16 threads over slices of one item
(:func:`solutions._fast.threads.stress_slicing`), so that tiny inputs are
cut as finely as a scan. The answers are checked against brute force and
SciPy (a normal, not unique on these clouds, by its curvature and length).
:func:`test_every_kernel_runs_here` fails when a kernel is added that nothing
here reaches (compiled in this process, or called by name from one that
was), or when a kernel's entry in numba's cache carries numba's own sort or
search helpers, which another process can link to a different closure (the
crash of issue 33: ``solutions/_fast/sorting.py``).
"""

import importlib
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import plain  # tests/project/plain.py
import pytest
from _helpers import backstop
from scipy.spatial import cKDTree

import solutions._fast
from grading import REPO_ROOT
from grading.instructors import tree_searches, trees
from solutions import downsampling, filters, nn, normals
from solutions._fast import density, lloyd, rows
from solutions._fast.grid import grid_radius_count
from solutions._fast.knn import LEAF_SIZE, leaf_knn
from solutions._fast.sorting import search_left, sort_pairs, sort_range
from solutions._fast.threads import stress_slicing

pytestmark = pytest.mark.kernels


def _stress_clouds():
    rng = np.random.default_rng(20261203)  # its own stream: the clouds do not depend on test order
    cube = rng.random((300, 3))
    return {
        "one point": rng.random((1, 3)),
        "two points": rng.random((2, 3)),
        "one leaf": rng.random((LEAF_SIZE, 3)),
        "one leaf and a point": rng.random((LEAF_SIZE + 1, 3)),
        "all equal": np.tile(rng.random(3), (70, 1)),
        "pairs": np.repeat(rng.random((40, 3)), 2, axis=0),
        "lattice": np.stack(np.meshgrid(*[np.arange(5.0)] * 3, indexing="ij"), -1).reshape(-1, 3),
        "line": np.c_[rng.random(90), np.zeros((90, 2))],
        "far": cube * [3.0, 2.0, 0.1] + 1e6,
        "cube": cube,
    }


CLOUDS = _stress_clouds()


@pytest.fixture(autouse=True)
def many_threads():
    """Every test here runs its kernels on 16 threads over slices of one item."""
    with stress_slicing(threads=16, slice_items=1):
        yield


def _ks(n, skip_self=False):
    """Neighbour counts at the edges: 1, the largest allowed, and one in between."""
    largest = n - 1 if skip_self else n
    return sorted({k for k in (1, min(7, largest), largest) if 1 <= k <= largest})


# --- lecture 1: Z-order leaves, grid counts, normals, filters, voxels, FPS --------------------------


@pytest.mark.parametrize("name", CLOUDS)
def test_leaf_knn_under_stress(name):
    points = CLOUDS[name]
    scale = max(1.0, float(np.abs(points).max()))
    for skip_self in (False, True):
        for k in _ks(len(points), skip_self):
            distances, indices = leaf_knn(points, k, skip_self)
            expected = cKDTree(points).query(points, k=k + 1)[0].reshape(len(points), -1)
            expected = expected[:, 1 : k + 1] if skip_self else expected[:, :k]
            np.testing.assert_allclose(distances, expected, rtol=0, atol=1e-12 * scale, err_msg=f"k={k}")
            # The rows are the points at those distances, each once, never the query itself when skipped.
            reached = np.linalg.norm(points[indices] - points[:, None, :], axis=2)
            np.testing.assert_allclose(reached, distances, rtol=0, atol=1e-9 * scale, err_msg=f"k={k}")
            assert all(len(set(row)) == k for row in indices.tolist())
            assert not skip_self or not np.any(indices == np.arange(len(points))[:, None])


@pytest.mark.parametrize("name", CLOUDS)
def test_normals_and_filters_under_stress(name):
    points = CLOUDS[name]
    n = len(points)
    scale = float(np.ptp(points, axis=0).max()) or 1.0
    for k in _ks(n):
        # The normal is not unique on these clouds (a line, one point repeated): the curvature is.
        result, curvature = normals.estimate_normals(points, k=k)
        _, expected_curvature = plain.estimate_normals(points, k)
        finite = np.isfinite(expected_curvature)
        np.testing.assert_array_equal(np.isfinite(curvature), finite, err_msg=f"k={k}")
        # Where the k-th distance is tied (the lattice) any of the tied points may complete the set.
        distances = cKDTree(points).query(points, k=min(k + 1, n))[0].reshape(n, -1)
        untied = finite & ((k == n) | (distances[:, k - 1] < distances[:, min(k, distances.shape[1] - 1)]))
        np.testing.assert_allclose(curvature[untied], expected_curvature[untied], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(result[finite], axis=1), 1.0, atol=1e-9)
    _, curvature = normals.estimate_normals(points, k=5, radius=0.3 * scale)
    _, expected_curvature = plain.estimate_normals(points, 5, 0.3 * scale)
    np.testing.assert_array_equal(np.isfinite(curvature), np.isfinite(expected_curvature))
    for k in _ks(n, skip_self=True):
        np.testing.assert_array_equal(
            filters.statistical_outlier_removal(points, k, 1.0), plain.statistical_outlier_mask(points, k, 1.0)
        )
    for radius in (0.1 * scale, scale):
        np.testing.assert_array_equal(
            grid_radius_count(points, radius) - 1, plain.radius_neighbour_counts(points, radius)
        )
        np.testing.assert_array_equal(
            filters.radius_outlier_removal(points, radius, 1), plain.radius_neighbour_counts(points, radius) >= 1
        )


@pytest.mark.parametrize("name", CLOUDS)
def test_voxels_and_sampling_under_stress(name):
    points = CLOUDS[name]
    n = len(points)
    extent = float(np.ptp(points, axis=0).max()) or 1.0
    # A dense table of cells, hashed int64 keys, and keys beyond int64 (solutions/downsampling.py).
    for size in (extent / 4, extent / 1000, extent * 1e-16):
        np.testing.assert_allclose(
            downsampling.voxel_grid_downsample(points, size), plain.voxel_grid_centroids(points, size), rtol=1e-12
        )
        chosen = downsampling.voxel_grid_downsample(points, size, method="random", rng=1)
        assert len(chosen) == len(plain.voxel_groups(points, size))
    size = extent / 4
    for containers in (1, 7, 10**6):
        groups = plain.approximate_voxel_groups(points, size, containers)
        expected = np.array([points[g].mean(axis=0) for g in groups])
        result = downsampling.approximate_voxel_downsample(points, size, containers)
        np.testing.assert_allclose(result, expected, rtol=1e-12)
        assert len(downsampling.approximate_voxel_downsample(points, size, containers, "random", rng=2)) == len(groups)
    for n_samples, start in ((1, 0), (n, n - 1), (max(1, n // 2), n // 3)):
        np.testing.assert_array_equal(
            downsampling.farthest_point_sampling(points, n_samples, start_index=start),
            plain.farthest_point_sampling(points, n_samples, start),
        )


# --- lecture 2: the BST, the k-d tree and the octree ------------------------------------------------


def _queries(points):
    """The points themselves (every tie; of the two random clouds of 300, every fourth: the
    grader's plain searches that give the expected answers take seconds), a few inside, and one
    far away."""
    rng = np.random.default_rng(len(points))
    lower, upper = points.min(axis=0), points.max(axis=0)
    inside = lower + rng.random((5, points.shape[1])) * np.maximum(upper - lower, 1.0)
    return np.vstack([points[:: 1 if len(points) < 200 else 4], inside, upper + 1e3])


def _assert_same(result, expected, what):
    for got, want in zip(result, expected):
        np.testing.assert_array_equal(np.asarray(got).shape, np.asarray(want).shape, err_msg=what)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0, err_msg=what)


@pytest.mark.parametrize("name", CLOUDS)
def test_trees_under_stress(name):
    # The expected answers: the grader's plain searches, which follow the contract's
    # rules literally (grading/instructors/trees.py). They equal brute force except where a
    # rule's floating-point test prunes a point at distance 0 from a radius-0 query.
    points = CLOUDS[name]
    queries = _queries(points)
    scale = float(np.ptp(points, axis=0).max()) or 1.0
    for leaf_size in (1, 16, 100):  # 100: leaves sorted by the introsort, not inline
        kd = nn.kdtree_build(points, leaf_size=leaf_size)
        octree = nn.octree_build(points, leaf_size=leaf_size)
        for k in _ks(len(points)):
            what = f"leaf_size={leaf_size}, k={k}"
            _assert_same(
                nn.kdtree_knn(kd, points, queries, k), tree_searches.kdtree_search(kd, points, queries, k=k), what
            )
            _assert_same(
                nn.octree_knn(octree, points, queries, k),
                tree_searches.octree_search(octree, points, queries, k=k),
                what,
            )
            _assert_same(nn.kdtree_knn(kd, points, queries, k), _brute_knn(points, queries, k), what)
        for radius in (0.0, 0.2 * scale, 2 * scale):
            what = f"leaf_size={leaf_size}, radius={radius}"
            expected = tree_searches.kdtree_search(kd, points, queries, radius=radius)
            _assert_same(nn.kdtree_radius(kd, points, queries, radius), expected, what)
            expected = tree_searches.octree_search(octree, points, queries, radius=radius)
            _assert_same(nn.octree_radius(octree, points, queries, radius), expected, what)


def _brute_knn(points, queries, k):
    rows = [trees.brute_knn(points, query, k) for query in queries]
    return np.array([row[0] for row in rows]), np.array([row[1] for row in rows])


@pytest.mark.parametrize("name", CLOUDS)
def test_bst_under_stress(name):
    keys = CLOUDS[name][:, 0]
    left, right = nn.bst_build(keys)
    for query in (*keys[:5], keys.min() - 1.0, keys.max() + 1.0):
        for k in _ks(len(keys)):
            indices, distances = nn.bst_knn(keys, left, right, query, k)
            expected = np.lexsort((np.arange(len(keys)), np.abs(keys - query)))[:k]
            np.testing.assert_array_equal(indices, expected, err_msg=f"query {query}, k={k}")
    distances = np.abs(keys - keys[0])
    for k in _ks(len(keys)):
        indices, _, _ = nn.knn_result_set(distances, np.arange(len(keys)), k)
        np.testing.assert_array_equal(indices, np.lexsort((np.arange(len(keys)), distances))[:k])


# --- the kernels' own sort ------------------------------------------------------------------------------


def _sort_cases():
    rng = np.random.default_rng(20261204)
    for n in (0, 1, 2, 16, 17, 100, 5000):
        yield f"random {n}", rng.random(n)
        yield f"few values {n}", rng.integers(0, 3, n).astype(float)
    yield "sorted", np.arange(3000.0)
    yield "reversed", np.arange(3000.0)[::-1].copy()
    yield "all equal", np.ones(3000)
    yield "all zero", np.zeros(300)
    yield "one far value", np.r_[np.full(2000, 0.25), 1.0]  # all but one in one bucket
    yield "a scan's squared distances", np.square(rng.random(4000) * 0.3) + np.square(rng.random(4000) * 0.3)
    yield "organ pipe", np.r_[np.arange(1500.0), np.arange(1500.0)[::-1]]


# --- lecture 3: Lloyd's passes ----------------------------------------------------------------


@pytest.mark.parametrize("name", CLOUDS)
def test_lloyd_under_stress(name):
    """A pass's labels against argmin (the first of equal distances), its inertia against the sum of
    the minima, and its sums: whole ones against np.add.at, changes against the difference of two
    whole ones (to rounding: another order of the same additions)."""
    points = CLOUDS[name]
    rng = np.random.default_rng(len(points))
    columns = np.ascontiguousarray(points.T)
    for k in sorted({1, min(3, len(points)), len(points)}):
        # Centres on points (exact ties where points repeat) and a copy of the first (a tie for all).
        centers = np.vstack([points[rng.choice(len(points), k, replace=False)], points[:1]])
        s = sum((points[:, j, None] - centers[None, :, j]) ** 2 for j in range(points.shape[1]))
        expected = np.argmin(s, axis=1)
        previous = rng.integers(len(centers), size=len(points)).astype(np.int32)  # as kmeans keeps them
        labels = previous.copy()
        sums, counts, inertia, changed = lloyd.lloyd_pass(columns, centers, labels, full=True)
        np.testing.assert_array_equal(labels, expected, err_msg=f"k={k}")
        assert changed == np.count_nonzero(previous != expected)
        np.testing.assert_allclose(inertia, s.min(axis=1).sum(), rtol=1e-12)
        np.testing.assert_array_equal(counts, np.bincount(expected, minlength=len(centers)))
        whole = np.zeros_like(sums)
        np.add.at(whole, expected, points)
        np.testing.assert_allclose(sums, whole, rtol=1e-12, atol=1e-9)
        labels = previous.copy()
        gained, gained_counts, _, _ = lloyd.lloyd_pass(columns, centers, labels, full=False)
        before = np.zeros_like(sums)
        np.add.at(before, previous, points)
        np.testing.assert_array_equal(gained_counts, counts - np.bincount(previous, minlength=len(centers)))
        np.testing.assert_allclose(before + gained, whole, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("name", CLOUDS)
def test_density_clusters_under_stress(name):
    """DBSCAN's kernel from every pair (a superset of the neighbours, as a k-d tree's candidates)
    against scikit-learn's DBSCAN, whose rules are the contract's."""
    from sklearn.cluster import DBSCAN

    points = np.ascontiguousarray(CLOUDS[name])
    pairs = np.array([(i, j) for i in range(len(points)) for j in range(i + 1, len(points))], dtype=np.int64)
    pairs = pairs.reshape(-1, 2)
    spread = float(np.ptp(points, axis=0).max()) or 1.0
    for eps in (spread / 20, spread / 5):
        for min_samples in (1, 2, 5):
            labels, is_core = density.density_clusters(points, pairs, eps * eps, min_samples)
            fitted = DBSCAN(eps=eps, min_samples=min_samples).fit(points)
            np.testing.assert_array_equal(labels, fitted.labels_, err_msg=f"eps={eps}, min_samples={min_samples}")
            np.testing.assert_array_equal(np.flatnonzero(is_core), fitted.core_sample_indices_)


@pytest.mark.parametrize("name, keys", list(_sort_cases()), ids=lambda v: v if isinstance(v, str) else "")
def test_the_kernels_sort_is_numpys(name, keys):
    values = keys.copy()
    sort_range(values, 0, len(values))
    np.testing.assert_array_equal(values, np.sort(keys))
    ids = np.random.default_rng(len(keys)).permutation(len(keys)).astype(np.int64)
    pair_keys, payload = keys.copy(), ids.copy()
    sort_pairs(pair_keys, payload, 0, len(keys))
    rank = np.lexsort((ids, keys))
    np.testing.assert_array_equal(pair_keys, keys[rank])
    np.testing.assert_array_equal(payload, ids[rank])
    ordered = np.sort(keys)
    for value in (*keys[:50], -np.inf, np.inf, 0.5):
        assert search_left(ordered, value) == np.searchsorted(ordered, value, side="left")
    if np.all(keys >= 0):  # a radius search's row: (squared distance, index), buckets for long ones
        row_keys, row_ids = keys.copy(), ids.copy()
        rows.sort_row(row_keys, row_ids, len(keys))
        np.testing.assert_array_equal(row_keys, keys[rank])
        np.testing.assert_array_equal(row_ids, ids[rank])
    if len(keys) > 4:  # a range of a larger array: nothing outside it moves
        inner = keys.copy()
        sort_range(inner, 1, len(keys) - 2)
        np.testing.assert_array_equal(inner[[0, -2, -1]], keys[[0, -2, -1]])
        np.testing.assert_array_equal(inner[1:-2], np.sort(keys[1:-2]))


# Helpers numba builds from factories: several closures share one qualified name and one signature
# (sort and argsort, a comparison or another, searchsorted's two sides), told apart only by the
# compiling process's counter.
# A kernel that carries one can be bound, in another process, to the other closure (solutions/_fast/sorting.py).
FACTORY_HELPERS = (b"4misc9quicksort", b"4misc9mergesort", b"18_partition_factory", b"9arraymath13_searchsorted")


# --- every kernel is reached, and the checked run ----------------------------------------------------


def _dispatchers():
    """Every numba dispatcher defined in ``solutions/_fast``, by ``module.name``."""
    found = {}
    for module_info in pkgutil.iter_modules(solutions._fast.__path__):
        module = importlib.import_module(f"solutions._fast.{module_info.name}")
        for name, value in vars(module).items():
            if isinstance(value, numba.core.dispatcher.Dispatcher) and value.__module__ == module.__name__:
                found[f"{module_info.name}.{name}"] = value
    return found


def _reached(dispatchers):
    """The dispatchers compiled in this process, and every one their code calls, transitively.

    A kernel loaded from numba's cache carries its callees' machine code, so
    they show no compiled signature of their own: they are reached by name.
    """
    by_identity = {id(dispatcher): name for name, dispatcher in dispatchers.items()}
    reached = {name for name, dispatcher in dispatchers.items() if dispatcher.signatures}
    pending = list(reached)
    while pending:
        function = dispatchers[pending.pop()].py_func
        for global_name in function.__code__.co_names:
            callee = by_identity.get(id(function.__globals__.get(global_name)))
            if callee is not None and callee not in reached:
                reached.add(callee)
                pending.append(callee)
    return reached


def _cached_helpers(dispatcher):
    """The factory-made helpers in the machine code of ``dispatcher``'s current cache entries."""
    cache_file = dispatcher._cache._cache_file
    found = set()
    for data_name in cache_file._load_index().values():
        data = (Path(dispatcher._cache.cache_path) / data_name).read_bytes()
        found.update(helper for helper in FACTORY_HELPERS if helper in data)
    return found


# The clouds on which test_every_kernel_runs_here runs every stress test again: the small ones,
# which reach every kernel (the two of 300 points spend seconds in the grader's plain searches).
SMALL_CLOUDS = [name for name, points in CLOUDS.items() if len(points) < 200]


def test_every_kernel_runs_here():
    # Run every stress test on the small clouds once more in this process (xdist may have run
    # them elsewhere); then every kernel must have run, itself or inside a kernel that calls it.
    # The stress tests are this module's test_*_under_stress, found by name: a list kept by hand
    # missed DBSCAN's, and this test passed only where xdist had run a DBSCAN test in its process.
    stress_tests = [test for name, test in sorted(globals().items()) if name.endswith("_under_stress")]
    assert test_density_clusters_under_stress in stress_tests
    for name in SMALL_CLOUDS:
        for test in stress_tests:
            test(name)
    dispatchers = _dispatchers()
    unused = sorted(set(dispatchers) - _reached(dispatchers))
    assert not unused, f"kernels no stress test here reaches (add a call to this module): {unused}"
    # No kernel's entry in numba's cache (what other processes load) carries a helper that could
    # be bound there to another process's closure. (numba's private cache API: tests only.)
    carrying = sorted(name for name, dispatcher in dispatchers.items() if _cached_helpers(dispatcher))
    assert not carrying, f"kernels carrying numba's factory-made sort helpers (use solutions._fast.sorting): {carrying}"


@pytest.mark.skipif(not numba.config.BOUNDSCHECK, reason="the bounds-checked run only")
def test_bounds_checking_is_on():
    """In the checked run, a kernel indexing out of range raises instead of reading memory."""

    @numba.njit
    def read(values, i):
        return values[i]

    with pytest.raises(IndexError):
        read(np.zeros(3), 3)


# The kernel tests, and the graded tests of the references in this process (--impl solutions,
# no sandbox: the sandbox passes no NUMBA_ variable through).
CHECKED_RUN = [
    "tests/project/test_kernels.py",
    "tests/project/test_fast_paths.py",
    "tests/project/test_trees.py",
    "tests/project/test_oracles.py",
    "tests/graded",
    "tests/hidden",
]


# About 60 s on an idle machine once its cache is filled (make test's numba-cache does that first;
# on an empty cache numba compiles every kernel again, checked: a minute more).
@pytest.mark.long
@pytest.mark.timeout(backstop(300))
@pytest.mark.skipif(bool(numba.config.BOUNDSCHECK), reason="runs the checked run; not inside it")
def test_the_kernel_tests_pass_bounds_checked(tmp_path):
    # Its own cache (the Makefile's NUMBA_CHECKED_CACHE): numba's cache key ignores the
    # bounds-checking flag, so a shared cache would hand this run the unchecked machine code.
    env = {**os.environ, "NUMBA_BOUNDSCHECK": "1", "NUMBA_CACHE_DIR": str(REPO_ROOT / "_build" / "numba-boundscheck")}
    command = [sys.executable, "-m", "pytest", *CHECKED_RUN, "--impl", "solutions", "-m", "kernels or grades"]
    command += ["-p", "no:xdist", "-p", "no:cacheprovider", "-q", "-x", f"--basetemp={tmp_path / 'run'}"]
    completed = subprocess.run(command, cwd=REPO_ROOT, env=env, capture_output=True, text=True, timeout=backstop(290))
    tail = "\n".join((completed.stdout + completed.stderr).splitlines()[-40:])
    assert completed.returncode == 0, tail
