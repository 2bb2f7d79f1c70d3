"""Graded tests of the clustering exercises (``pcl_course/cluster.py``).

Expected answers come from small clouds worked out by hand, from scikit-learn's
``KMeans`` started from the same centres (``n_init=1, tol=0``: the same Lloyd
iterations as the contract's, with the same number of iterations, on clouds
where no cluster empties, which scikit-learn would relocate), and from the
tests' own few-line implementations of the contract's rules (the k-means++
draws, the truncated runs), written from the contract, not from the reference.
"""

import copy

import numpy as np
import pytest
from sklearn.cluster import KMeans
from sklearn.datasets import make_blobs

from grading.checks import CheckFailed, as_list, check_array, check_close, raises
from grading.checks.cluster import linked_components, lloyd, nearest_centres, scikit_learn_em

# What a wrong answer far from the origin most likely means.
EXPANDED = (
    "sum (p_j - c_j) ** 2 over the columns: |p|^2 - 2 p.c + |c|^2 loses every digit of a distance "
    "at coordinates of millions"
)
# What a wrong neighbourhood far from the origin most likely means.
FAR_NEIGHBOURS = (
    "sum (p_j - q_j) ** 2 over the columns, in float64: |p|^2 - 2 p.q + |q|^2, or any of it in float32, loses "
    "the digits of a distance at coordinates of millions"
)
# Centres are means: another summation order (np.add.at, bincount, a loop) moves them by a few ulps.
CENTRES_RTOL = 1e-12
CENTRES_ATOL = 1e-12


def _blobs(n=600, centres=4, columns=3, seed=0):
    points, _ = make_blobs(n, n_features=columns, centers=centres, cluster_std=1.5, random_state=seed)
    return points


def _first_points(points, k, seed):
    """``k`` distinct points of ``points`` chosen by ``seed``: centres that start with a point each."""
    return points[np.random.default_rng(seed).choice(len(points), k, replace=False)].copy()


def _unpack(result, n, k, d):
    """The four outputs of ``kmeans``, their types checked."""
    if not isinstance(result, tuple) or len(result) != 4:
        raise CheckFailed(f"kmeans must return a tuple (labels, centers, inertia, n_iter), got {type(result).__name__}")
    labels, centers, inertia, n_iter = result
    check_array(labels, "labels", shape=(n,), dtype="int64")
    check_array(centers, "centers", shape=(k, d))
    check_array(inertia, "inertia", shape=(None,))
    if isinstance(n_iter, bool) or not isinstance(n_iter, int | np.integer):
        raise CheckFailed(f"n_iter must be an int, got {type(n_iter).__name__}")
    if not 1 <= n_iter or len(inertia) != n_iter:
        raise CheckFailed(
            f"n_iter = {n_iter} but inertia holds {len(inertia)} values: n_iter counts the iterations, the last "
            "one (which found no label changed) included, and each records one inertia"
        )
    return labels, centers, inertia, int(n_iter)


def _check_run(impl, points, start, max_iter=300, what=""):
    """``kmeans`` from ``start`` against :func:`lloyd`: labels, centres, n_iter and inertia."""
    expected = lloyd(points, start, max_iter)
    labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, start, max_iter), *points.shape[:1], *start.shape)
    _check_labels(labels, expected[0], what)
    scale = float(np.abs(points).max())
    check_close(centers, expected[1], f"centers{what}", rtol=CENTRES_RTOL, atol=CENTRES_ATOL * scale)
    assert n_iter == expected[3], f"n_iter{what}: expected {expected[3]}, got {n_iter}"
    check_close(inertia, expected[2], f"inertia{what}", rtol=1e-9, atol=1e-12 * scale**2)


def _check_labels(labels, expected, what=""):
    if not np.array_equal(labels, expected):
        first = int(np.argmax(labels != expected))
        raise CheckFailed(
            f"labels are wrong{what}: point {first} has label {labels[first]}, expected {expected[first]}",
            rule="labels are wrong",
        )


# --- kmeans ------------------------------------------------------------------------


@pytest.mark.grades("kmeans")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kmeans_returns_labels_centres_inertia_and_iterations(impl):
    points = _blobs()
    result = impl.kmeans(points, _first_points(points, 4, 1))
    _unpack(result, len(points), 4, 3)


@pytest.mark.grades("kmeans")
@pytest.mark.points(3)
def test_kmeans_on_a_line_worked_by_hand(impl):
    # x = 0, 1, 2, 10, 11, 12 from centres 0 and 1. Iteration 1: only x = 0 is nearer 0; inertia
    # 0 + 0 + 1 + 81 + 100 + 121 = 303; centres 0 and 36 / 5 = 7.2. Iteration 2: 0, 1, 2 | 10, 11, 12;
    # inertia 0 + 1 + 4 + 2.8^2 + 3.8^2 + 4.8^2 = 50.32; centres 1 and 11. Iteration 3: no label
    # changes (inertia 4): stop, n_iter = 3.
    points = np.array([[0.0], [1.0], [2.0], [10.0], [11.0], [12.0]])
    labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, np.array([[0.0], [1.0]])), 6, 2, 1)
    _check_labels(labels, np.array([0, 0, 0, 1, 1, 1]))
    check_close(centers, [[1.0], [11.0]], "centers")
    assert n_iter == 3, f"n_iter: expected 3 (the third assignment changes no label), got {n_iter}"
    check_close(
        inertia,
        [303.0, 50.32, 4.0],
        "inertia",
        rtol=1e-12,
        hint="inertia[t] is the SUM (not the mean) of the squared distances at the "
        "assignment of iteration t + 1, with the centres it assigned to (before their update)",
    )


@pytest.mark.grades("kmeans")
@pytest.mark.points(3)
def test_kmeans_matches_scikit_learn_from_the_same_centres(impl):
    for seed, (k, columns, max_iter) in enumerate([(3, 3, 300), (5, 2, 300), (8, 3, 300), (4, 5, 300), (6, 3, 4)]):
        points = _blobs(800, centres=5, columns=columns, seed=seed)
        start = _first_points(points, k, seed + 10)
        expected = KMeans(k, init=start, n_init=1, max_iter=max_iter, tol=0, algorithm="lloyd").fit(points)
        labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, start, max_iter), len(points), k, columns)
        _check_labels(labels, expected.labels_, f" (K = {k}, D = {columns})")
        check_close(centers, expected.cluster_centers_, "centers", rtol=CENTRES_RTOL, atol=CENTRES_ATOL)
        assert n_iter == expected.n_iter_, f"n_iter: expected {expected.n_iter_}, got {n_iter} (K = {k})"


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_truncated_runs_are_the_first_iterations(impl):
    # max_iter = t: the first t iterations' inertia, then the centres updated once more and the
    # labels assigned to them.
    points = _blobs(500, centres=6, columns=2, seed=7)
    start = _first_points(points, 6, 3)
    full = _unpack(impl.kmeans(points, start), len(points), 6, 2)
    assert full[3] > 3, f"this cloud takes more than 3 iterations, got n_iter = {full[3]}"
    centers = start.copy()
    for t in (1, 2, 3):
        labels, _ = nearest_centres(points, centers)
        centers = np.array([points[labels == c].mean(axis=0) for c in range(6)])  # no cluster empties here
        expected_labels, _ = nearest_centres(points, centers)
        got = _unpack(impl.kmeans(points, start, max_iter=t), len(points), 6, 2)
        assert got[3] == t, f"max_iter = {t}: n_iter must be {t}, got {got[3]}"
        check_close(got[2], full[2][:t], f"inertia with max_iter = {t}", rtol=1e-12)
        check_close(
            got[1],
            centers,
            f"centers after max_iter = {t}",
            rtol=CENTRES_RTOL,
            atol=CENTRES_ATOL,
            hint="after the last iteration's update, the centres are returned as they are",
        )
        _check_labels(got[0], expected_labels, f" with max_iter = {t} (the assignment to the returned centres)")


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_an_empty_cluster_keeps_its_centre(impl):
    rng = np.random.default_rng(5)
    points = rng.uniform(0.0, 1.0, size=(60, 2))
    start = np.array([[0.25, 0.5], [0.75, 0.5], [50.0, -50.0]])
    labels, centers, _, _ = _unpack(impl.kmeans(points, start), 60, 3, 2)
    assert not np.any(labels == 2), (
        f"your labels put {int(np.sum(labels == 2))} points in cluster 2, whose centre is far from every point"
    )
    check_close(
        centers[2],
        [50.0, -50.0],
        "centers[2] (a cluster with no point)",
        rtol=0,
        atol=0,
        hint="an empty cluster keeps its centre (no mean of nothing: NaN; no relocation)",
    )
    # Equal initial centres at the exact mean of a symmetric grid: ties send every point to the
    # first, whose mean is that same centre; the second stays empty at it, and nothing changes.
    grid = np.array([[x, y] for x in np.linspace(0.0, 1.0, 5) for y in np.linspace(0.0, 1.0, 5)])
    labels, centers, _, n_iter = _unpack(impl.kmeans(grid, np.array([[0.5, 0.5], [0.5, 0.5]])), 25, 2, 2)
    _check_labels(labels, np.zeros(25, dtype=np.int64), " (equal centres: ties go to the lowest index)")
    check_close(centers, [[0.5, 0.5], [0.5, 0.5]], "centers", rtol=0, atol=0, hint="an empty cluster keeps its centre")
    assert n_iter == 2, f"n_iter: expected 2 (the second assignment changes no label), got {n_iter}"


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_ties_go_to_the_lowest_centre(impl):
    # On a grid every distance is exact. x = 2 is 1 from both centres 1 and 3 (centre 0 wins): then
    # the centres are 1 (of 0, 1, 2) and 4 (of 4); nothing changes after. Ties to the highest index
    # would give 0.5 (of 0, 1) and 3 (of 2, 4) instead.
    points = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [4.0, 0.0]])
    labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, np.array([[1.0, 0.0], [3.0, 0.0]])), 4, 2, 2)
    _check_labels(labels, np.array([0, 0, 0, 1]), " (a point equidistant from two centres goes to the lower index)")
    check_close(centers, [[1.0, 0.0], [4.0, 0.0]], "centers")
    check_close(inertia, [3.0, 2.0], "inertia", rtol=1e-12)
    assert n_iter == 2, f"n_iter: expected 2, got {n_iter}"


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_the_final_state_is_a_fixed_point(impl):
    # Whatever the cloud: the labels are the nearest centres, every centre with points is their
    # mean, the inertia never increases, and its last value is the returned state's.
    rng = np.random.default_rng(11)
    points = np.vstack([rng.normal(c, 0.6, size=(150, 3)) for c in ([0, 0, 0], [4, 0, 1], [0, 5, -2])])
    points = points + [612.0, -340.0, 25.0]  # away from the origin
    start = points[[0, 1, 2, 3, 4]].copy()  # five centres from one blob
    labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, start), len(points), 5, 3)
    assert n_iter < 300, f"n_iter is {n_iter}: this cloud converges well before 300 (stop when no label changes)"
    # ... and the one these iterations reach from this start (any other fixed point would pass the rest:
    # one centre at the mean of all, the others without points, say).
    _check_labels(labels, lloyd(points, start)[0], " (the fixed point Lloyd's iterations reach from the start)")
    nearest, s = nearest_centres(points, centers)
    _check_labels(labels, nearest, " (each point's nearest returned centre)")
    for c in np.unique(labels):
        check_close(
            centers[c],
            points[labels == c].mean(axis=0),
            f"centers[{c}] (the mean of its points)",
            rtol=CENTRES_RTOL,
            atol=1e-9,
        )
    assert np.all(np.diff(inertia) <= 1e-9 * inertia[0]), f"inertia must never increase, got {as_list(inertia, n_iter)}"
    check_close(
        inertia[-1],
        s[np.arange(len(points)), labels].sum(),
        "inertia[-1]",
        rtol=1e-10,
        hint="the sum of SQUARED distances of the points to their centres",
    )


@pytest.mark.grades("kmeans")
@pytest.mark.points(1)
def test_kmeans_every_column_is_a_coordinate(impl):
    # Two groups told apart by the fifth column alone: counting three columns would mix them.
    rng = np.random.default_rng(2)
    points = rng.normal(0.0, 0.1, size=(40, 5))
    points[20:, 4] += 10.0
    labels, centers, _, _ = _unpack(impl.kmeans(points, points[[0, 20]].copy()), 40, 2, 5)
    _check_labels(labels, np.repeat([0, 1], 20), " (every column counts in the distance)")
    check_close(
        centers, [points[:20].mean(axis=0), points[20:].mean(axis=0)], "centers", rtol=CENTRES_RTOL, atol=CENTRES_ATOL
    )


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_a_cluster_that_empties_keeps_its_centre_and_can_fill_again(impl):
    # Equal centres at 0: the second starts empty at 0, and after the first update (centre 0 at
    # 5.5) it takes 0 and 1 back. Then 5, 2, 6 from 2, 8, 1: cluster 0 has point 1 at the first
    # assignment, none at the second (its centre stays at 2, not back at its start), points again
    # later. A cluster written off for good, or sent back to its initial centre, answers otherwise.
    _check_run(
        impl, np.array([[0.0], [1.0], [10.0], [11.0]]), np.array([[0.0], [0.0]]), what=" (a cluster fills again)"
    )
    _check_run(impl, np.array([[5.0], [2.0], [6.0]]), np.array([[2.0], [8.0], [1.0]]), what=" (a cluster empties)")


@pytest.mark.grades("kmeans")
@pytest.mark.points(1)
def test_kmeans_a_near_tie_is_not_a_tie(impl):
    # x = 1 is nearer centre 1 by a relative 1e-10: no tolerance decides a tie. And the squares,
    # not the distances: 1 + 2^-52 against 1 are a tie once square-rooted.
    _check_run(impl, np.array([[1.0], [-3.0], [5.0]]), np.array([[-1e-10], [2.0]]), what=" (a near-tie)")
    points = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 5.0], [1.0, 6.0]])
    _check_run(impl, points, np.array([[1.0, 2.0**-26], [1.0, 0.0]]), 1, " (squared distances, not distances)")


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_far_from_the_origin_and_at_a_small_scale(impl):
    # UTM-like coordinates (4.2e6 m): |x|^2 - 2 x.c + |c|^2 loses every digit of a distance there;
    # the contract's differences do not. Then blobs a centimetre apart in kilometres.
    rng = np.random.default_rng(4)
    points = np.vstack([rng.normal(c, 1.0, size=(150, 3)) for c in ([0, 0, 0], [3, 0, 0], [0, 3, 0], [2, 2, 1])])
    points = np.vstack([points, points[:40]]) + [525_000.0, 4_200_000.0, 35.0]
    _check_run(impl, points, points[:6].copy(), what=f" far from the origin ({EXPANDED})")
    small = np.vstack([rng.normal(c, 1.0, size=(40, 2)) for c in ([0, 0], [6, 0], [0, 6])]) * 1e-5
    _check_run(impl, small, small[:3].copy(), what=" (a small scale)")


@pytest.mark.grades("kmeans")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kmeans_converts_float32(impl):
    points = _blobs(300, centres=3, columns=3, seed=4).astype(np.float32)
    start = _first_points(points, 3, 0)
    labels, centers, inertia, n_iter = _unpack(impl.kmeans(points, start), 300, 3, 3)
    expected = _unpack(impl.kmeans(points.astype(np.float64), start.astype(np.float64)), 300, 3, 3)
    _check_labels(labels, expected[0], " (float32 points are converted to float64 first)")
    check_close(centers, expected[1], "centers", rtol=CENTRES_RTOL, atol=CENTRES_ATOL)


@pytest.mark.grades("kmeans")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kmeans_rejects_bad_arguments(impl):
    points = _blobs(50, centres=2, columns=3, seed=1)
    start = points[:2].copy()
    nan = points.copy()
    nan[3, 1] = np.nan
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"points": nan}, "points"),
        ({"points": np.empty((0, 3))}, "points"),
        ({"init_centers": start[:, :2]}, "init_centers"),
        ({"init_centers": np.empty((0, 3))}, "init_centers"),
        ({"init_centers": np.vstack([points, points[:1]])}, "init_centers"),
        ({"init_centers": np.full((2, 3), np.inf)}, "init_centers"),
        ({"init_centers": start[0]}, "init_centers"),  # one centre, but 1-D
        ({"max_iter": 0}, "max_iter"),
        ({"max_iter": 2.5}, "max_iter"),
        ({"max_iter": True}, "max_iter"),
    ]
    for change, name in cases:
        arguments = {"points": points, "init_centers": start, "max_iter": 300, **change}
        with raises(ValueError, naming=name):
            impl.kmeans(**arguments)
    # A NumPy integer is an integer.
    _unpack(impl.kmeans(points, start, np.int64(3)), 50, 2, 3)


# --- kmeans_plusplus -----------------------------------------------------------------


def d2_seeding(points, n_clusters, rng):
    """The contract's draws, written from its docstring: the first index ``rng.integers(N)``, then
    each next the smallest i with ``cumsum(w)[i] > u * cumsum(w)[-1]``, ``u = rng.random()``."""
    rng = np.random.default_rng(rng)
    chosen = [int(rng.integers(len(points)))]
    w = ((points - points[chosen[0]]) ** 2).sum(axis=1)
    while len(chosen) < n_clusters:
        cumulative = np.cumsum(w)
        u = rng.random()
        chosen.append(int(np.flatnonzero(cumulative > u * cumulative[-1])[0]))
        w = np.minimum(w, ((points - points[chosen[-1]]) ** 2).sum(axis=1))
    return np.array(chosen)


def _check_draws(result, expected, what):
    check_array(result, "indices", shape=(len(expected),), dtype="int64")
    if not np.array_equal(result, expected):
        first = int(np.argmax(result != expected))
        raise CheckFailed(
            f"draw {first} is index {result[first]}, expected {expected[first]} ({what}): the first index is "
            "rng.integers(N), each next one the D^2 draw of the docstring, with exactly one rng.random() each",
            rule="the draws are wrong",
        )


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kmeans_plusplus_returns_distinct_int64_indices(impl):
    points = _blobs(400, centres=5, columns=3, seed=3)
    result = impl.kmeans_plusplus(points, 8, rng=0)
    check_array(result, "indices", shape=(8,), dtype="int64")
    assert len(set(result.tolist())) == 8, f"the indices must be distinct, got {result.tolist()}"
    assert result[0] == np.random.default_rng(0).integers(len(points)), (
        f"the first index is rng.integers(N) = {np.random.default_rng(0).integers(len(points))}, got {result[0]}"
    )


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(3)
def test_kmeans_plusplus_draws_as_the_contract_says(impl):
    for seed, (columns, k) in enumerate([(3, 5), (2, 10), (1, 4), (4, 6)]):
        points = _blobs(300, centres=4, columns=columns, seed=seed) + 100.0
        _check_draws(
            impl.kmeans_plusplus(points, k, rng=seed + 40),
            d2_seeding(points, k, seed + 40),
            f"D = {columns}, rng = {seed + 40}",
        )


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(1)
def test_kmeans_plusplus_takes_a_generator_and_its_stream(impl):
    points = _blobs(200, centres=3, columns=3, seed=9)
    expected = d2_seeding(points, 6, np.random.default_rng(123))
    _check_draws(impl.kmeans_plusplus(points, 6, rng=np.random.default_rng(123)), expected, "a Generator")
    _check_draws(impl.kmeans_plusplus(points, 6, rng=123), expected, "the same seed as an int")


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(2)
def test_kmeans_plusplus_draws_far_from_the_origin_at_a_small_scale_and_on_many_points(impl):
    # The weights as the contract's differences, in float64: UTM-like coordinates with duplicates
    # (the expansion |x|^2 - 2 x.c + |c|^2 loses them), blobs a centimetre apart in kilometres
    # (no weight is "close to 0"), and 20,000 points (float32 sums lose the draws).
    rng = np.random.default_rng(4)
    far = np.vstack([rng.normal(c, 1.0, size=(150, 3)) for c in ([0, 0, 0], [3, 0, 0], [0, 3, 0], [2, 2, 1])])
    far = np.vstack([far, far[:40]]) + [525_000.0, 4_200_000.0, 35.0]
    small = np.vstack([rng.normal(c, 1.0, size=(40, 2)) for c in ([0, 0], [6, 0], [0, 6])]) * 1e-5
    many = np.random.default_rng(0).normal(size=(20_000, 3))
    for points, k, seed, what in (
        (far, 25, 2, f"far from the origin: {EXPANDED}"),
        (small, 4, 3, "a small scale"),
        (many, 10, 6, "20,000 points"),
    ):
        _check_draws(impl.kmeans_plusplus(points, k, rng=seed), d2_seeding(points, k, seed), what)


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(2)
def test_kmeans_plusplus_never_draws_a_duplicate_of_a_chosen_point(impl):
    # Five distinct points, each repeated: every draw must be a new position, up to all five.
    base = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3], [5, 5, 5]])
    points = np.repeat(base, [7, 3, 5, 2, 4], axis=0)
    for seed in range(6):
        result = impl.kmeans_plusplus(points, 5, rng=seed)
        check_array(result, "indices", shape=(5,), dtype="int64")
        positions = {tuple(p) for p in points[as_list(result, 5)]}
        assert len(positions) == 5, (
            f"rng = {seed}: indices {result.tolist()} repeat a position: a point at distance 0 from a chosen "
            "one has weight 0 and is never drawn (the first i with cumsum[i] > u * cumsum[-1], strictly)"
        )
        _check_draws(result, d2_seeding(points, 5, seed), f"rng = {seed}")


def _generator_drawing_zero():
    """A PCG64 Generator whose ``integers(10)`` is 4 and whose next ``random()`` is exactly 0.0:
    its state set two steps before one whose output is 0 (the 128-bit LCG run backwards)."""
    multiplier, modulus = 0x2360ED051FC65DA44385DF649FCCF645, 1 << 128
    inverse = pow(multiplier, -1, modulus)
    generator = np.random.Generator(np.random.PCG64(0))
    state = generator.bit_generator.state
    increment = state["state"]["inc"]
    zero = (12345 << 64) | 12345  # high and low halves equal: this step outputs 0
    state["state"]["state"] = ((((zero - increment) * inverse) % modulus - increment) * inverse) % modulus
    state["has_uint32"], state["uinteger"] = 0, 0
    generator.bit_generator.state = state
    return generator


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(1)
def test_kmeans_plusplus_a_draw_of_zero_takes_the_first_point_of_positive_weight(impl):
    # u = 0: the smallest i with cum[i] > 0 is the first point of positive weight; ">=" (or
    # searchsorted's default side) would take point 0, a duplicate of the first chosen point 4.
    points = np.arange(10.0)[:, None] ** 1.5
    points[0] = points[4]
    expected = d2_seeding(points, 3, copy.deepcopy(_generator_drawing_zero()))
    _check_draws(impl.kmeans_plusplus(points, 3, rng=_generator_drawing_zero()), expected, "a draw u = 0.0")


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kmeans_plusplus_rejects_bad_arguments(impl):
    points = np.repeat(np.eye(3), 4, axis=0)  # 12 points, 3 distinct
    nan = points.copy()
    nan[0, 0] = np.nan
    cases = [
        ({"n_clusters": 0}, "n_clusters"),
        ({"n_clusters": 4}, "n_clusters"),  # more than the distinct points
        ({"n_clusters": 2.0}, "n_clusters"),
        ({"points": nan}, "points"),
        ({"points": np.empty((0, 3))}, "points"),
        ({"rng": "seed"}, "rng"),
        ({"points": np.arange(10.0)}, "points"),  # 1-D
        ({"points": np.array([[0.0, 1.0], [0.0, 1.0]])}, "n_clusters"),  # one distinct row
    ]
    for change, name in cases:
        arguments = {"points": points, "n_clusters": 2, "rng": 0, **change}
        with raises(ValueError, naming=name):
            impl.kmeans_plusplus(**arguments)
    # Distinct rows, not values: four distinct points of two values; a NumPy integer is an integer.
    square = np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]])
    check_array(impl.kmeans_plusplus(square, np.int64(3), rng=0), "indices", shape=(3,), dtype="int64")


# --- dbscan ----------------------------------------------------------------------------


def neighbourhoods(points, eps):
    """The contract's N(p) of every point, itself included: a list of index arrays (brute force)."""
    points = np.asarray(points, dtype=float)
    s = sum((points[:, j, None] - points[None, :, j]) ** 2 for j in range(points.shape[1]))
    return [np.flatnonzero(row <= eps * eps) for row in s]


def density_clusters(points, eps, min_samples):
    """The contract's answer, written from its rules: cores by |N(p)|, clusters the connected
    components of the cores numbered by their smallest core, a border the smallest label it touches."""
    near = neighbourhoods(points, eps)
    is_core = np.array([len(n) >= min_samples for n in near], dtype=bool)
    labels = np.full(len(near), -1, dtype=np.int64)
    cluster = 0
    for seed in np.flatnonzero(is_core):  # the smallest core index first
        if labels[seed] >= 0:
            continue
        labels[seed], frontier = cluster, [seed]
        while frontier:
            p = frontier.pop()
            for q in near[p]:
                if is_core[q] and labels[q] < 0:
                    labels[q] = cluster
                    frontier.append(q)
        cluster += 1
    for p in np.flatnonzero(~is_core):
        touched = [labels[q] for q in near[p] if is_core[q]]
        labels[p] = min(touched) if touched else -1
    return labels, is_core


def _scikit_learn_dbscan(points, eps, min_samples):
    from sklearn.cluster import DBSCAN

    fitted = DBSCAN(eps=eps, min_samples=min_samples).fit(points)
    is_core = np.zeros(len(points), dtype=bool)
    is_core[fitted.core_sample_indices_] = True
    return fitted.labels_.astype(np.int64), is_core


def _unpack_dbscan(result, n):
    if not isinstance(result, tuple) or len(result) != 2:
        raise CheckFailed(f"dbscan must return a tuple (labels, is_core), got {type(result).__name__}")
    labels, is_core = result
    check_array(labels, "labels", shape=(n,), dtype="int64")
    check_array(is_core, "is_core", shape=(n,), dtype="bool")
    return labels, is_core


def _check_dbscan(impl, points, eps, min_samples, expected=None, what=""):
    """Call dbscan and compare with ``expected`` (the tests' own rules by default), naming the first
    point that differs and the rule it breaks."""
    labels, is_core = _unpack_dbscan(impl.dbscan(points, eps, min_samples), len(points))
    want_labels, want_core = density_clusters(points, eps, min_samples) if expected is None else expected
    near = None
    if not np.array_equal(is_core, want_core):
        near = neighbourhoods(points, eps)
        p = int(np.argmax(is_core != want_core))
        raise CheckFailed(
            f"point {p} has {len(near[p])} points within eps (itself and its duplicates included, a distance "
            f"equal to eps included), min_samples = {min_samples}: it is {'' if want_core[p] else 'not '}core, "
            f"yours says it is{'' if is_core[p] else ' not'}{what}",
            rule="core points are those with |N(p)| >= min_samples",
        )
    if np.array_equal(labels, want_labels):
        return labels, is_core
    p = int(np.argmax(labels != want_labels))
    if want_core[p]:
        clusters = want_labels[want_core]
        first = [int(np.flatnonzero(want_core & (want_labels == c))[0]) for c in range(clusters.max() + 1)]
        raise CheckFailed(
            f"core point {p} has label {labels[p]}, expected {want_labels[p]}{what}: the clusters are the connected "
            "components of the core points, numbered by their smallest core index (here the clusters' smallest "
            f"cores are {as_list(first, 6)})",
            rule="clusters are numbered by their smallest core point",
        )
    near = neighbourhoods(points, eps) if near is None else near
    touched = sorted({int(want_labels[q]) for q in near[p] if want_core[q]})
    if not touched:
        raise CheckFailed(
            f"point {p} is noise (no core point within eps), yours labels it {labels[p]}{what}: noise is -1",
            rule="noise is -1",
        )
    raise CheckFailed(
        f"border point {p} touches the clusters {as_list(touched, 6)} through its core neighbours, yours labels it "
        f"{labels[p]}{what}: a border point takes the smallest label among its core neighbours' clusters",
        rule="a border point takes the smallest label it touches",
    )


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
@pytest.mark.interface
def test_dbscan_returns_int64_labels_and_boolean_cores(impl):
    points = _blobs(200, centres=3, columns=3, seed=11)
    _unpack_dbscan(impl.dbscan(points, 1.0, 5), 200)
    labels, is_core = _unpack_dbscan(impl.dbscan(np.empty((0, 3)), 1.0, 5), 0)  # an empty cloud: empty labels


@pytest.mark.grades("dbscan")
@pytest.mark.points(3)
def test_dbscan_on_a_line_worked_by_hand(impl):
    # eps = 1 and min_samples = 3: 1, 2 and 8 have 3 points within 1 (themselves included) and are core;
    # 0 and 3 border the first cluster, 7 and 9 the second; 20 is noise. Neighbours 1 apart are at
    # exactly eps: the neighbourhood is inclusive.
    points = np.array([[0.0], [1.0], [2.0], [3.0], [7.0], [8.0], [9.0], [20.0]])
    expected = (np.array([0, 0, 0, 0, 1, 1, 1, -1]), np.array([0, 1, 1, 0, 0, 1, 0, 0], dtype=bool))
    _check_dbscan(impl, points, 1.0, 3, expected, " (a line worked by hand)")
    # min_samples = 1: every point is core, each run of points 1 apart a cluster.
    expected = (np.array([0, 0, 0, 0, 1, 1, 1, 2]), np.ones(8, dtype=bool))
    _check_dbscan(impl, points, 1.0, 1, expected, " (min_samples = 1)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(2)
def test_dbscan_a_border_point_takes_the_smallest_label_it_touches(impl):
    # Two runs of points 0.5 apart, cores 1.5..3 and 5..6.5 (eps = 1, min_samples = 4); point 0, at 4, is
    # within eps of a core of each but has only 3 points within eps: a border point of both clusters.
    # Listed first, the right run's cores come before the left's: the right run is cluster 0.
    right = [5.0, 5.5, 6.0, 6.5, 7.0]
    left = [1.0, 1.5, 2.0, 2.5, 3.0]
    points = np.array([[4.0], *([x] for x in right), *([x] for x in left)])
    labels, _ = _check_dbscan(impl, points, 1.0, 4, what=" (a border point between two clusters)")
    assert labels[0] == 0 and labels[1] == labels[2] == 0 and labels[-2] == 1  # the test's own premise
    mirrored = points[::-1].copy()  # the left run's cores first now: it is cluster 0, and so is the border
    _check_dbscan(impl, mirrored, 1.0, 4, what=" (the same points in reverse order)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(3)
def test_dbscan_matches_scikit_learn(impl):
    from sklearn.datasets import make_moons

    moons, _ = make_moons(600, noise=0.08, random_state=3)
    noise = np.random.default_rng(3).uniform([-1.5, -1.0], [2.5, 1.5], size=(60, 2))
    cases = [
        (np.vstack([moons, noise]), 0.12, 5),
        (_blobs(800, centres=5, columns=3, seed=12), 0.9, 8),
        (_blobs(500, centres=4, columns=2, seed=13), 0.4, 1),
        (_blobs(400, centres=3, columns=3, seed=14), 2.5, 30),
    ]
    for points, eps, min_samples in cases:
        expected = _scikit_learn_dbscan(points, eps, min_samples)
        _check_dbscan(impl, points, eps, min_samples, expected, f" (eps = {eps}, min_samples = {min_samples})")


@pytest.mark.grades("dbscan")
@pytest.mark.points(2)
def test_dbscan_on_the_scan_without_its_ground(impl):
    from pcl_course.datasets import LIDAR_CLASSES, simulate_lidar_scan

    scan = simulate_lidar_scan(seed=5, n_azimuth=900)
    above = scan.points[(scan.labels != LIDAR_CLASSES.index("ground")) & (np.linalg.norm(scan.points, axis=1) < 30)]
    points = above[np.random.default_rng(5).choice(len(above), min(3000, len(above)), replace=False)]
    for eps, min_samples in ((0.5, 4), (1.0, 10)):
        expected = _scikit_learn_dbscan(points, eps, min_samples)
        _check_dbscan(impl, points, eps, min_samples, expected, f" (the scan, eps = {eps} m)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(2)
def test_dbscan_numbers_clusters_by_their_smallest_core(impl):
    # A border point of the second cluster comes first: numbering by the first point of each cluster
    # (any point) would call the second cluster 0.
    grid = np.stack(np.meshgrid(np.arange(4.0), np.arange(4.0)), -1).reshape(-1, 2)
    points = np.vstack([[[10.0, 1.5]], grid, grid + [10.0, 3.0]])
    _check_dbscan(impl, points, 1.0, 4, what=" (a border point listed first)")
    shuffled = _blobs(600, centres=6, columns=2, seed=15)[np.random.default_rng(15).permutation(600)]
    _check_dbscan(impl, shuffled, 0.6, 6, _scikit_learn_dbscan(shuffled, 0.6, 6), " (shuffled blobs)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(2)
def test_dbscan_counts_the_point_itself_and_its_duplicates(impl):
    # Point 0 has 3 duplicates: 4 points at distance 0, so it is core for min_samples 4, not 5.
    base = np.array([[0.0, 0.0, 0.0]] * 4 + [[5.0, 0.0, 0.0], [5.0, 0.0, 0.0], [9.0, 9.0, 9.0]])
    for min_samples in (2, 3, 4, 5):
        _check_dbscan(impl, base, 0.1, min_samples, what=f" (duplicate points, min_samples = {min_samples})")
    # On a unit grid with eps = 1 the four grid neighbours lie at exactly eps: 5 points with itself.
    grid = np.stack(np.meshgrid(np.arange(6.0), np.arange(5.0)), -1).reshape(-1, 2)
    for min_samples in (4, 5, 6):
        _check_dbscan(impl, grid, 1.0, min_samples, what=f" (a unit grid, eps = 1, min_samples = {min_samples})")
    # More samples than points: nothing is core.
    _check_dbscan(impl, np.array([[0.0], [0.5]]), 1.0, 5, what=" (min_samples larger than the cloud)")
    # Just beyond eps: 1 + 1e-10 apart with eps = 1; and sqrt(3) apart with eps = np.sqrt(3), whose
    # square rounds to 2.9999999999999996 < 3: the contract compares s with eps ** 2, so neither pair
    # are neighbours (a comparison of sqrt(s) with eps, or with a relative slack, links them).
    _check_dbscan(impl, np.array([[0.0], [1.0 + 1e-10]]), 1.0, 2, what=" (two points 1 + 1e-10 apart, eps = 1)")
    diagonal = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    _check_dbscan(impl, diagonal, float(np.sqrt(3.0)), 2, what=" (eps = np.sqrt(3): s = 3 > eps ** 2)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
def test_dbscan_every_column_is_a_coordinate(impl):
    rng = np.random.default_rng(16)
    points = _blobs(400, centres=4, columns=5, seed=16)
    points[:, 3:] *= rng.choice([1.0, 30.0], size=(400, 1))  # far apart in the last columns only
    _check_dbscan(impl, points, 1.5, 5, _scikit_learn_dbscan(points, 1.5, 5), " (5 columns)")
    line = np.sort(rng.uniform(0, 40, 300))[:, None]
    _check_dbscan(impl, line, 0.3, 3, _scikit_learn_dbscan(line, 0.3, 3), " (1 column)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
def test_dbscan_far_from_the_origin(impl):
    rng = np.random.default_rng(17)
    points = np.vstack([rng.normal(c, 0.3, size=(120, 3)) for c in ([0, 0, 0], [2, 0, 0], [0, 2, 1])])
    points += [525_000.0, 4_200_000.0, 35.0]  # UTM-like coordinates, in metres
    _check_dbscan(impl, points, 0.25, 5, what=f" far from the origin ({FAR_NEIGHBOURS})")


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
@pytest.mark.interface
def test_dbscan_converts_float32(impl):
    points = _blobs(300, centres=3, columns=3, seed=18).astype(np.float32)
    labels, is_core = _unpack_dbscan(impl.dbscan(points, 0.8, 6), 300)
    _check_dbscan(impl, points.astype(np.float64), 0.8, 6, (labels, is_core), " (float32 points are converted)")


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
@pytest.mark.interface
def test_dbscan_rejects_bad_arguments(impl):
    points = _blobs(50, centres=2, columns=3, seed=19)
    nan = points.copy()
    nan[3, 1] = np.nan
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"points": nan}, "points"),
        ({"eps": 0.0}, "eps"),
        ({"eps": -1.0}, "eps"),
        ({"eps": np.inf}, "eps"),
        ({"eps": np.nan}, "eps"),
        ({"eps": True}, "eps"),
        ({"min_samples": 0}, "min_samples"),
        ({"min_samples": 2.5}, "min_samples"),
        ({"min_samples": 3.0}, "min_samples"),  # a float, if a whole one, is not an integer
        ({"min_samples": True}, "min_samples"),
        ({"eps": "1.0"}, "eps"),
        ({"points": np.where(np.arange(150).reshape(50, 3) == 7, np.inf, points)}, "points"),
    ]
    for change, name in cases:
        arguments = {"points": points, "eps": 1.0, "min_samples": 5, **change}
        with raises(ValueError, naming=name):
            impl.dbscan(**arguments)
    _unpack_dbscan(impl.dbscan(points, np.float32(1.0), np.int64(5)), 50)  # NumPy scalars are numbers


# --- euclidean_clusters ----------------------------------------------------------------


def _check_components(impl, points, tolerance, min_size=1, max_size=None, expected=None, what=""):
    labels = impl.euclidean_clusters(points, tolerance, min_size, max_size)
    check_array(labels, "labels", shape=(len(points),), dtype="int64")
    want = linked_components(points, tolerance, min_size, max_size) if expected is None else np.asarray(expected)
    if np.array_equal(labels, want):
        return labels
    p = int(np.argmax(labels != want))
    if want[p] < 0:
        size = int(np.sum(linked_components(points, tolerance) == linked_components(points, tolerance)[p]))
        raise CheckFailed(
            f"point {p} lies in a component of {size} points, outside the sizes {min_size}..{max_size}: it is -1, "
            f"yours labels it {labels[p]}{what}",
            rule="a component outside the sizes is dropped (-1)",
        )
    if labels[p] < 0:
        size = int(np.sum(want == want[p]))
        raise CheckFailed(
            f"point {p} lies in a cluster of {size} points, within the sizes {min_size}..{max_size} (both inclusive): "
            f"it is kept, as cluster {want[p]}; yours labels it -1{what}",
            rule="a component within the sizes is kept",
        )
    sizes = np.bincount(want[want >= 0])
    raise CheckFailed(
        f"point {p} has label {labels[p]}, expected {want[p]}{what}: the clusters are the connected components of "
        "the links s <= tolerance ** 2 (inclusive), numbered by decreasing size, equal sizes by their smallest "
        f"index (here the sizes are {as_list(sizes, 6)})",
        rule="the clusters are the components, largest first",
    )


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(1)
@pytest.mark.interface
def test_euclidean_clusters_returns_int64_labels(impl):
    points = _blobs(200, centres=3, columns=3, seed=21)
    check_array(impl.euclidean_clusters(points, 0.8), "labels", shape=(200,), dtype="int64")
    check_array(impl.euclidean_clusters(np.empty((0, 3)), 0.8), "labels", shape=(0,), dtype="int64")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(2)
def test_euclidean_clusters_on_a_line_worked_by_hand(impl):
    # Runs of points 1 apart with tolerance 1 (exactly the tolerance: linked): sizes 3, 2 and 1.
    points = np.array([[0.0], [1.0], [2.0], [5.0], [6.0], [9.0]])
    _check_components(impl, points, 1.0, expected=[0, 0, 0, 1, 1, 2], what=" (a line worked by hand)")
    _check_components(impl, points, 1.0, 2, expected=[0, 0, 0, 1, 1, -1], what=" (min_size = 2)")
    _check_components(impl, points, 1.0, 1, 2, expected=[-1, -1, -1, 0, 0, 1], what=" (max_size = 2)")
    _check_components(impl, points, 3.0, expected=[0] * 6, what=" (tolerance 3: gaps of 3 linked)")
    _check_components(impl, points, 3.0, 1, 5, expected=[-1] * 6, what=" (tolerance 3, max_size = 5)")
    # Just beyond the tolerance (s compared with tolerance ** 2): not linked.
    _check_components(impl, np.array([[0.0], [1.0 + 1e-10]]), 1.0, expected=[0, 1], what=" (1 + 1e-10 apart)")
    diagonal = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    root = float(np.sqrt(3.0))
    _check_components(impl, diagonal, root, expected=[0, 1], what=" (tolerance np.sqrt(3): s = 3 > its square)")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(2)
def test_euclidean_clusters_numbers_the_largest_first(impl):
    # The first points form the smallest cluster; two clusters of equal size follow in reverse order.
    grid = np.stack(np.meshgrid(np.arange(3.0), np.arange(3.0)), -1).reshape(-1, 2)  # 9 points
    points = np.vstack([[[-10.0, 0.0]], [[-10.0, 1.0]], grid + [20.0, 0.0], grid, grid[:4] + [0.0, 10.0]])
    _check_components(impl, points, 1.0, what=" (clusters of sizes 2, 9, 9 and 4)")
    shuffled = _blobs(600, centres=7, columns=3, seed=22)[np.random.default_rng(22).permutation(600)]
    _check_components(impl, shuffled, 0.5, 3, what=" (shuffled blobs)")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(2)
def test_euclidean_clusters_on_the_scan_without_its_ground(impl):
    from pcl_course.datasets import LIDAR_CLASSES, simulate_lidar_scan

    scan = simulate_lidar_scan(seed=6, n_azimuth=900)
    above = scan.points[(scan.labels != LIDAR_CLASSES.index("ground")) & (np.linalg.norm(scan.points, axis=1) < 30)]
    points = above[np.random.default_rng(6).choice(len(above), min(3000, len(above)), replace=False)]
    _check_components(impl, points, 0.5, 20, what=" (the scan, tolerance 0.5 m, at least 20 points)")
    _check_components(impl, points, 0.8, 5, 400, what=" (the scan, tolerance 0.8 m, 5 to 400 points)")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(1)
def test_euclidean_clusters_is_dbscan_with_one_sample(impl):
    points = _blobs(500, centres=5, columns=2, seed=23)
    labels = impl.euclidean_clusters(points, 0.3)
    dbscan_labels, _ = _scikit_learn_dbscan(points, 0.3, 1)
    # The same partition (scikit-learn numbers by smallest index, the contract by size).
    pairs = {(int(a), int(b)) for a, b in zip(labels, dbscan_labels)}
    if len(pairs) != len(set(dbscan_labels)) or len({a for a, _ in pairs}) != len(pairs):
        raise CheckFailed(
            "your clusters are not the connected components of the links s <= tolerance ** 2 (scikit-learn's "
            "DBSCAN with min_samples = 1 finds other groups)",
            rule="the clusters are the components",
        )
    _check_components(impl, points, 0.3, what=" (blobs)")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(1)
def test_euclidean_clusters_every_column_and_far_from_the_origin(impl):
    rng = np.random.default_rng(24)
    points = _blobs(300, centres=4, columns=5, seed=24)
    points[:, 3:] *= rng.choice([1.0, 30.0], size=(300, 1))
    _check_components(impl, points, 1.0, what=" (5 columns)")
    far = np.vstack([rng.normal(c, 0.2, size=(100, 3)) for c in ([0, 0, 0], [2, 0, 0])]) + [525_000.0, 4.2e6, 35.0]
    _check_components(impl, far, 0.15, 2, what=f" far from the origin ({FAR_NEIGHBOURS})")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(1)
@pytest.mark.interface
def test_euclidean_clusters_converts_float32(impl):
    points = _blobs(300, centres=3, columns=3, seed=25).astype(np.float32)
    labels = impl.euclidean_clusters(points, 0.6, 2)
    _check_components(impl, points.astype(np.float64), 0.6, 2, expected=labels, what=" (float32 is converted)")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(1)
@pytest.mark.interface
def test_euclidean_clusters_rejects_bad_arguments(impl):
    points = _blobs(50, centres=2, columns=3, seed=26)
    nan = points.copy()
    nan[3, 1] = np.nan
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"points": nan}, "points"),
        ({"tolerance": 0.0}, "tolerance"),
        ({"tolerance": np.inf}, "tolerance"),
        ({"tolerance": True}, "tolerance"),
        ({"min_size": 0}, "min_size"),
        ({"min_size": 1.5}, "min_size"),
        ({"min_size": 2.0}, "min_size"),
        ({"points": np.where(np.arange(150).reshape(50, 3) == 7, np.inf, points)}, "points"),
        ({"max_size": 0}, "max_size"),
        ({"min_size": 5, "max_size": 4}, "max_size"),
        ({"max_size": 2.5}, "max_size"),
        ({"max_size": True}, "max_size"),
    ]
    for change, name in cases:
        arguments = {"points": points, "tolerance": 1.0, "min_size": 1, "max_size": None, **change}
        with raises(ValueError, naming=name):
            impl.euclidean_clusters(**arguments)
    check_array(impl.euclidean_clusters(points, 1.0, np.int64(2), np.int64(50)), "labels", shape=(50,), dtype="int64")


# --- gmm_em ------------------------------------------------------------------------------


# Different correct codings of EM (a Cholesky solve or an inverse, another summation order) agree to
# about 1e-12 relative after many iterations; the responsibilities to about 1e-12 absolute.
EM_RTOL = 1e-9
EM_ATOL = 1e-9


def _mixture_start(points, k, seed):
    """Initial parameters: equal weights, means at ``k`` points, identity-scaled covariances."""
    rng = np.random.default_rng(seed)
    d = points.shape[1]
    weights = rng.dirichlet(np.full(k, 4.0))
    means = points[rng.choice(len(points), k, replace=False)].copy()
    a = rng.normal(size=(k, d, d)) * 0.3
    covariances = a @ a.transpose(0, 2, 1) + np.eye(d) * np.var(points, axis=0).mean()
    return weights, means, covariances


def _unpack_em(result, n, k, d):
    if not isinstance(result, tuple) or len(result) != 6:
        raise CheckFailed(
            "gmm_em must return a tuple (weights, means, covariances, responsibilities, lower_bounds, n_iter), "
            f"got {type(result).__name__}"
        )
    weights, means, covariances, responsibilities, lower_bounds, n_iter = result
    check_array(weights, "weights", shape=(k,))
    check_array(means, "means", shape=(k, d))
    check_array(covariances, "covariances", shape=(k, d, d))
    check_array(responsibilities, "responsibilities", shape=(n, k))
    check_array(lower_bounds, "lower_bounds", shape=(None,))
    if isinstance(n_iter, bool) or not isinstance(n_iter, int | np.integer):
        raise CheckFailed(f"n_iter must be an int, got {type(n_iter).__name__}")
    if not 1 <= n_iter or len(lower_bounds) != n_iter:
        raise CheckFailed(
            f"n_iter = {n_iter} but lower_bounds holds {len(lower_bounds)} values: n_iter counts the iterations, "
            "each records one lower bound at its E-step"
        )
    return weights, means, covariances, responsibilities, lower_bounds, int(n_iter)


def _check_em(impl, points, start, max_iter=100, tol=1e-3, reg_covar=1e-6, expected=None, what=""):
    """gmm_em against ``expected`` (scikit-learn's by default), the first differing output named."""
    n, d = points.shape
    k = len(start[0])
    result = _unpack_em(impl.gmm_em(points, *start, max_iter, tol, reg_covar), n, k, d)
    expected = scikit_learn_em(points, *start, max_iter, tol, reg_covar) if expected is None else expected
    lower_bounds, n_iter = result[4], result[5]
    steps = min(n_iter, expected[5])
    check_close(
        lower_bounds[:steps],
        expected[4][:steps],
        "lower_bounds",
        rtol=EM_RTOL,
        atol=EM_ATOL,
        hint=f"lower_bounds[t - 1] is the mean log-likelihood of the parameters iteration t starts from{what}",
    )
    if n_iter != expected[5]:
        raise CheckFailed(
            f"n_iter = {n_iter}, expected {expected[5]}{what}: after iteration t's M-step, stop when t > 1 and "
            "|lower_bounds[t - 1] - lower_bounds[t - 2]| < tol, else go on up to max_iter",
            rule="EM stops when the lower bound changes by less than tol",
        )
    for index, name in enumerate(("weights", "means", "covariances", "responsibilities")):
        check_close(result[index], expected[index], name, rtol=EM_RTOL, atol=EM_ATOL, hint=what.strip(" ()"))
    return result


def _anisotropic(seed, n=500, columns=2):
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(3):
        shear = rng.normal(size=(columns, columns)) * 0.6 + np.eye(columns)
        parts.append(rng.normal(size=(n // 3, columns)) @ shear + rng.uniform(-6, 6, columns))
    return np.vstack(parts)


@pytest.mark.grades("gmm_em")
@pytest.mark.points(1)
@pytest.mark.interface
def test_gmm_em_returns_the_parameters_responsibilities_and_bounds(impl):
    points = _anisotropic(31, 300)
    weights, _, _, responsibilities, _, _ = _unpack_em(impl.gmm_em(points, *_mixture_start(points, 3, 31)), 300, 3, 2)
    check_close(responsibilities.sum(axis=1), np.ones(300), "the sum of each row of responsibilities", rtol=1e-12)
    check_close(weights.sum(), 1.0, "the sum of the weights", rtol=1e-12)


@pytest.mark.grades("gmm_em")
@pytest.mark.points(2)
def test_gmm_em_one_component_is_the_sample_mean_and_covariance(impl):
    # One component: every responsibility is 1, so the first M-step gives the sample mean and the
    # covariance divided by N (plus 10 eps in N); the second E-step's bound is -(D log(2 pi) +
    # log det Sigma + D) / 2, and the third repeats it: EM stops at n_iter = 3.
    rng = np.random.default_rng(32)
    points = rng.normal(size=(400, 3)) @ np.array([[2.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.0, 0.3, 0.5]]) + 10.0
    start = (np.array([1.0]), np.zeros((1, 3)), np.eye(3)[None])
    weights, means, covariances, responsibilities, lower_bounds, n_iter = _unpack_em(
        impl.gmm_em(points, *start, 100, 1e-9, 0.0), 400, 1, 3
    )
    centred = points - points.mean(axis=0)
    sample = centred.T @ centred / (400 + 10 * np.finfo(float).eps)
    check_close(means[0], points.mean(axis=0), "means", rtol=1e-12, hint="one component: the sample mean")
    check_close(covariances[0], sample, "covariances", rtol=1e-10, hint="one component: divided by N, not N - 1")
    bound = -(3 * np.log(2 * np.pi) + np.linalg.slogdet(sample)[1] + 3) / 2
    check_close(lower_bounds[1:], [bound, bound], "lower_bounds[1:]", rtol=1e-10, hint="the Gaussian's entropy bound")
    if n_iter != 3:
        raise CheckFailed(f"n_iter = {n_iter}, expected 3: the third iteration's bound repeats the second's")
    check_close(responsibilities, np.ones((400, 1)), "responsibilities", rtol=0, atol=1e-12)
    check_close(weights, [1.0], "weights", rtol=1e-15)
    # tol = 0: |change| < 0 never holds, so EM runs max_iter iterations though the bound stops changing.
    n_iter = _unpack_em(impl.gmm_em(points, *start, 6, 0.0, 0.0), 400, 1, 3)[5]
    if n_iter != 6:
        raise CheckFailed(
            f"n_iter = {n_iter} with tol = 0 and max_iter = 6, expected 6: stop only when |change| < tol (strict), "
            "which never holds for tol = 0"
        )


@pytest.mark.grades("gmm_em")
@pytest.mark.points(4)
def test_gmm_em_matches_scikit_learn_from_the_same_parameters(impl):
    cases = [
        (_anisotropic(33, 600), 3, 1e-3),
        (_anisotropic(34, 450, columns=3), 4, 1e-6),
        (_blobs(300, centres=2, columns=1, seed=35), 2, 1e-8),
        (_blobs(400, centres=3, columns=5, seed=36), 3, 1e-5),
    ]
    for points, k, tol in cases:
        start = _mixture_start(points, k, len(points))
        _check_em(impl, points, start, 200, tol, what=f" ({points.shape[1]} columns, K = {k}, tol = {tol:g})")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(2)
def test_gmm_em_truncated_runs_are_the_first_iterations(impl):
    points = _anisotropic(37, 450)
    start = _mixture_start(points, 3, 37)
    for max_iter in (1, 2, 5):
        _check_em(impl, points, start, max_iter, 0.0, what=f" (max_iter = {max_iter}, tol = 0)")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(2)
def test_gmm_em_stops_at_the_first_small_change(impl):
    # tol between two consecutive changes of the bound: EM stops exactly after the smaller one.
    points = _anisotropic(38, 600)
    start = _mixture_start(points, 3, 38)
    bounds = scikit_learn_em(points, *start, 40, 0.0)[4]
    changes = np.abs(np.diff(bounds))  # changes[i]: between iterations i + 1 and i + 2
    t = next(i for i in range(2, len(changes)) if changes[i] < changes[:i].min() * 0.5)
    tol = float(np.sqrt(changes[t] * changes[:t].min()))  # every earlier change > tol > changes[t]
    assert changes[:t].min() > tol > changes[t]  # the test's own premise
    _check_em(impl, points, start, 100, tol, what=f" (tol between the changes of iterations {t + 1} and {t + 2})")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(2)
def test_gmm_em_works_in_the_log_domain(impl):
    # A point hundreds of standard deviations from every component: its densities underflow to 0 in
    # floating point (exp(-1e5)); the log domain (logsumexp) keeps its responsibilities.
    points = np.vstack([_anisotropic(39, 300), [[400.0, -300.0]]])
    start = _mixture_start(points[:-1], 3, 39)
    _check_em(impl, points, start, 20, 1e-6, what=" (a point far from every component: compute in the log domain)")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(2)
def test_gmm_em_regularises_a_collapsing_component(impl):
    # Component 2 starts on five copies of one point, far from the rest: it keeps them alone, and its
    # covariance is reg_covar I (without reg_covar it would be singular).
    rng = np.random.default_rng(40)
    points = np.vstack([rng.normal(0, 1, (200, 2)), rng.normal([6, 0], 1, (200, 2)), np.tile([[30.0, 30.0]], (5, 1))])
    start = (np.array([0.45, 0.45, 0.1]), np.array([[0.0, 0.0], [6.0, 0.0], [30.0, 30.0]]), np.stack([np.eye(2)] * 3))
    for reg_covar in (1e-6, 1e-2):
        result = _check_em(impl, points, start, 50, 1e-8, reg_covar, what=f" (reg_covar = {reg_covar:g})")
        check_close(result[2][2], reg_covar * np.eye(2), "covariances[2]", rtol=1e-8, atol=1e-14)


@pytest.mark.grades("gmm_em")
@pytest.mark.points(1)
def test_gmm_em_an_empty_component_and_a_falling_bound(impl):
    # The component at 1000 gets no responsibility: N_k = 10 eps keeps its mean finite (0 / 10 eps).
    points = np.array([[0.0], [1.0], [2.0]])
    start = (np.array([0.5, 0.5]), np.array([[1.0], [1000.0]]), np.ones((2, 1, 1)))
    _check_em(impl, points, start, 5, 0.0, what=" (a component with no responsibility: N_k = sum r + 10 eps)")
    # A large reg_covar makes the bound fall: EM stops on |change| < tol, not on change < tol.
    start = (np.array([1.0]), np.zeros((1, 1)), np.ones((1, 1, 1)))
    _check_em(impl, np.array([[-1.0], [1.0]]), start, 10, 1e-3, 10.0, what=" (a falling bound: |change|)")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(1)
def test_gmm_em_never_lowers_the_likelihood(impl):
    points = _anisotropic(41, 600, columns=3)
    start = _mixture_start(points, 4, 41)
    result = _unpack_em(impl.gmm_em(points, *start, 60, 0.0, 0.0), 600, 4, 3)
    lower_bounds, n_iter = result[4], result[5]
    # The bounds of this run, not any non-decreasing numbers: tol = 0 never stops it early, and the
    # first bound is the mean log-likelihood of the start.
    if n_iter != 60:
        raise CheckFailed(f"n_iter = {n_iter}: with tol = 0, EM runs all max_iter = 60 iterations", rule="n_iter")
    first = scikit_learn_em(points, *start, 1, 0.0, 0.0)[4][0]
    check_close(lower_bounds[0], first, "lower_bounds[0]", rtol=1e-9, hint="the mean log-likelihood of the start")
    if not np.all(np.isfinite(lower_bounds)):
        raise CheckFailed("lower_bounds must be finite: the mean log-likelihood of each iteration's parameters")
    drops = np.diff(lower_bounds) < -1e-10 * np.abs(lower_bounds[1:])
    if np.any(drops):
        t = int(np.argmax(drops)) + 1
        raise CheckFailed(
            f"lower_bounds[{t}] < lower_bounds[{t - 1}]: EM never lowers the likelihood (reg_covar = 0); each "
            "iteration records the bound of the parameters it starts from, then updates all of them",
            rule="the likelihood never decreases",
        )


@pytest.mark.grades("gmm_em")
@pytest.mark.points(1)
@pytest.mark.interface
def test_gmm_em_converts_float32(impl):
    points = _anisotropic(42, 300)
    start = _mixture_start(points, 3, 42)
    result = _unpack_em(impl.gmm_em(points.astype(np.float32), *start, 20, 0.0), 300, 3, 2)
    _check_em(impl, points.astype(np.float32).astype(np.float64), start, 20, 0.0, expected=result, what=" (float32)")


@pytest.mark.grades("gmm_em")
@pytest.mark.points(1)
@pytest.mark.interface
def test_gmm_em_rejects_bad_arguments(impl):
    points = _anisotropic(43, 90)
    weights, means, covariances = _mixture_start(points, 3, 43)
    asymmetric = covariances.copy()
    asymmetric[0, 0, 1] += 0.5
    nearly_symmetric = covariances.copy()
    nearly_symmetric[1, 0, 1] += 1e-9 * np.abs(covariances[1]).max()
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"points": np.empty((0, 2))}, "points"),
        ({"weights": np.array([0.5, 0.5])}, "means"),  # K = 2 from the weights: the means do not match
        ({"weights": np.array([0.5, 0.6, -0.1])}, "weights"),
        ({"weights": weights * 2}, "weights"),
        ({"weights": np.array([1.0, 0.0, 0.0])}, "weights"),
        ({"means": means[:, :1]}, "means"),
        ({"means": np.full((3, 2), np.nan)}, "means"),
        ({"covariances": covariances[:, :1, :1]}, "covariances"),
        ({"covariances": asymmetric}, "covariances"),
        ({"covariances": -covariances}, "covariances"),
        ({"max_iter": 0}, "max_iter"),
        ({"max_iter": 2.5}, "max_iter"),
        ({"max_iter": 3.0}, "max_iter"),
        ({"tol": -1.0}, "tol"),
        ({"tol": np.nan}, "tol"),
        ({"tol": True}, "tol"),
        ({"reg_covar": -1e-6}, "reg_covar"),
        ({"weights": weights + np.array([5e-6, 0.0, 0.0])}, "weights"),  # sums to 1 + 5e-6: not within 1e-8
        ({"covariances": nearly_symmetric}, "covariances"),  # 1e-9 of its largest entry: not within 1e-10
        ({"means": means.ravel()}, "means"),
        ({"weights": np.array([1.0]), "means": means[:1], "covariances": covariances[0]}, "covariances"),  # (D, D)
    ]
    for change, name in cases:
        arguments = {"points": points, "weights": weights, "means": means, "covariances": covariances, **change}
        with raises(ValueError, naming=name):
            impl.gmm_em(**arguments)
