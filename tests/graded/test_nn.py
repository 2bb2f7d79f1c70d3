"""Graded tests of lecture 2's nearest-neighbour search (``pcl_course/nn.py``).

Expected neighbours come from brute force (every distance, sorted by
(squared distance, index) with ``np.lexsort``); builds are checked rule by
rule (``grading/checks/nn.py``), each failure naming the rule, and against
hand-built examples. The searches run on trees the grader builds
(``grading/instructors/trees.py``, in the instructors' grader): a wrong build costs its
own points once. In the student release that module is absent, so these
tests search your own build, after checking it.

The structure tests (does the search read only the nodes its rule reaches?)
are hidden: ``tests/hidden/test_nn_hidden.py``.
"""

import numpy as np
import pytest

from grading import instructors_grader
from grading.checks import as_list, check_array, raises
from grading.checks.nn import check_bst, check_csr, check_kdtree, check_knn, check_octree
from grading.errors import CheckFailed

if instructors_grader():  # the instructors' grader (Gradescope, batch): its own trees
    from grading.instructors import trees as grader_trees
else:  # the student release: your own build, checked first
    grader_trees = None


# -- data and brute force ---------------------------------------------------------------------


def cube(n, seed, dim=3):
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=(n, dim))


def scan_like(n, seed):
    """A lidar-like cloud: rings on the ground (density falling with range) and a wall, in metres."""
    rng = np.random.default_rng(seed)
    n_ground = n * 3 // 4
    elevation = rng.choice(np.radians(np.linspace(-24.0, -2.0, 16)), n_ground)
    radius = 1.73 / np.tan(-elevation)
    azimuth = rng.uniform(0, 2 * np.pi, n_ground)
    ground = np.column_stack([radius * np.cos(azimuth), radius * np.sin(azimuth), rng.normal(-1.73, 0.02, n_ground)])
    wall = np.column_stack(
        [rng.normal(8.0, 0.02, n - n_ground), rng.uniform(-6, 6, n - n_ground), rng.uniform(-1.7, 1.5, n - n_ground)]
    )
    return np.vstack([ground, wall])


def grid(side, dim=3):
    """Integer grid points: many exact ties."""
    axes = np.meshgrid(*[np.arange(float(side))] * dim, indexing="ij")
    return np.stack(axes, axis=-1).reshape(-1, dim)


def far_cloud(n, seed):
    """UTM-like coordinates (millions of metres) whose values are at least 2 m apart along each axis,
    and queries 1e11 m away along each axis: every neighbour of those lies beyond any finite
    "worst distance" a student might start with, and rounding cannot tie two of them."""
    rng = np.random.default_rng(seed)
    points = np.column_stack([rng.permutation(3.0 * np.arange(n) + rng.uniform(0, 1, n)) for _ in range(3)])
    points += [4.0e6, -2.0e6, 1.0e3]
    centre = points.mean(axis=0)
    queries = centre + 1.0e11 * np.vstack([np.eye(3), -np.eye(3)])
    return points, np.vstack([queries, points[:4] + 0.5])


def squared(points, query):
    total = np.zeros(len(points))
    for j in range(points.shape[1]):
        total += (points[:, j] - query[j]) ** 2
    return total


def brute_knn(points, queries, k):
    indices = np.empty((len(queries), k), dtype=np.int64)
    for i, q in enumerate(queries):
        indices[i] = np.lexsort((np.arange(len(points)), squared(points, q)))[:k]
    distances = np.sqrt(np.array([squared(points[row], q) for row, q in zip(indices, queries)]).reshape(-1, k))
    return indices, distances


def brute_radius(points, queries, radius):
    rows = []
    for q in queries:
        s = squared(points, q)
        inside = np.flatnonzero(s <= radius**2)
        order = inside[np.lexsort((inside, s[inside]))]
        rows.append((order, np.sqrt(s[order])))
    return rows


def with_intensity(points, queries, seed):
    """``points`` and ``queries`` with a fourth column, an intensity in [0, 100): an octree searches xyz only,
    so a search that measures distances over every column answers wrong."""
    rng = np.random.default_rng(seed)
    return (
        np.hstack([points, rng.uniform(0, 100, (len(points), 1))]),
        np.hstack([queries, rng.uniform(0, 100, (len(queries), 1))]),
    )


def two_clusters(n, seed, dim=3):
    """``n`` points in the cube [-1, 1]^dim, then ``n`` more 100 away along the first axis: for a query
    well inside the first cluster, the contract's rule never reads the second (its cells lie some 50 away)."""
    return np.vstack([cube(n, seed, dim), cube(n, seed + 1, dim) + np.eye(dim)[0] * 100.0])


def with_decoys(points, far, query, k):
    """The cloud as a lying tree shows it: the points ``far`` moved near the query, at random within the
    k-th distance of the others, while the tree still lists them where they were. A search that follows the
    rule never reads them; one that reads every point (brute force, a library, no pruning) returns them.
    The hidden structure tests plant such decoys in every node the rule does not reach, on other data."""
    lying = np.array(points, dtype=float)
    rows = lying.reshape(len(lying), -1)
    query = np.atleast_1d(query)
    others = np.setdiff1d(np.arange(len(lying)), far)
    within = np.sqrt(np.sort(squared(rows[others], query))[k - 1]) * (1 - 1e-3)
    rng = np.random.default_rng(len(far) + k)
    directions = rng.standard_normal((len(far), len(query)))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    places = query + directions * (within * rng.uniform(size=len(far)) ** (1 / len(query)))[:, None]
    lying[far] = places if lying.ndim == 2 else places[:, 0]
    return lying


def check_no_decoy(indices, far, what):
    """Fail, naming the rule, if a search returned a planted decoy (:func:`with_decoys`)."""
    read = np.intersect1d(np.asarray(indices).ravel(), far)
    if len(read):
        raise CheckFailed(
            f"{what} returned point {read[0]} of the far cluster, which its rule never reaches for this query; "
            "the cluster's points were moved nearer the query than its k-th true neighbour, and a search that "
            "follows the rule never reads them: yours reads points its rule does not reach (brute force, a library, "
            "no pruning)",
            rule=f"{what} reads nodes its rule does not reach",
        )


# -- the trees searched -------------------------------------------------------------------------


def kd_tree(impl, points, leaf_size):
    if grader_trees is not None:
        return grader_trees.kdtree(points, leaf_size)
    tree = impl.kdtree_build(points, leaf_size)
    try:
        check_kdtree(tree, points, leaf_size)
    except AssertionError as exc:
        raise AssertionError(f"locally this search runs on your own kdtree_build, which is wrong: {exc}") from None
    return tree


def oc_tree(impl, points, leaf_size, min_extent=1e-3):
    if grader_trees is not None:
        return grader_trees.octree(points, leaf_size, min_extent)
    tree = impl.octree_build(points, leaf_size, min_extent)
    try:
        check_octree(tree, points, leaf_size, min_extent)
    except AssertionError as exc:
        raise AssertionError(f"locally this search runs on your own octree_build, which is wrong: {exc}") from None
    return tree


# -- knn_result_set -----------------------------------------------------------------------------


def check_result_set(indices, distances, worst, held, offered):
    """The three arrays' types and shapes first: what a student reads when they are lists, not a
    test's own ``AttributeError``."""
    check_array(indices, "indices", shape=(held,), dtype="int64")
    check_array(distances, "distances", shape=(held,))
    check_array(worst, "worst", shape=(offered,))


@pytest.mark.grades("knn_result_set")
@pytest.mark.points(2)
def test_knn_result_set_hand_worked(impl):
    # Offers (3, 10), (1, 11), (2, 12), (1, 9) to k = 2: (2, 12) evicts (3, 10); (1, 9) evicts (2, 12)
    # because (1, 9) < (2, 12); it also goes before (1, 11), on the index.
    indices, distances, worst = impl.knn_result_set(np.array([3.0, 1.0, 2.0, 1.0]), np.array([10, 11, 12, 9]), 2)
    check_result_set(indices, distances, worst, 2, 4)
    assert indices.tolist() == [9, 11], f"expected [9, 11] (ties by the lower index), got {indices.tolist()}"
    assert distances.tolist() == [1.0, 1.0]
    assert worst.tolist() == [np.inf, 3.0, 2.0, 1.0], f"worst after each offer: expected [inf, 3, 2, 1], got {worst}"


@pytest.mark.grades("knn_result_set")
@pytest.mark.points(3)
def test_knn_result_set_matches_sorting_with_ties(impl):
    rng = np.random.default_rng(7)
    for n, k in ((50, 5), (200, 17), (30, 30), (10, 1)):
        distances = rng.integers(0, 8, n).astype(float) / 4  # many ties
        indices = rng.permutation(1000)[:n]
        got_indices, got_distances, worst = impl.knn_result_set(distances, indices, k)
        check_result_set(got_indices, got_distances, worst, min(n, k), n)
        rank = np.lexsort((indices, distances))[:k]
        assert got_indices.tolist() == indices[rank].tolist(), (
            f"n={n}, k={k}: expected the k smallest (distance, index) pairs, ascending; the lower index wins ties"
        )
        assert np.array_equal(got_distances, distances[rank])
        expected_worst = [np.inf if j + 1 < k else np.sort(distances[: j + 1])[k - 1] for j in range(n)]
        assert np.array_equal(worst, expected_worst), f"n={n}, k={k}: worst must be the k-th best after each offer"


@pytest.mark.grades("knn_result_set")
@pytest.mark.points(1)
def test_knn_result_set_with_fewer_candidates_than_k_is_not_padded(impl):
    indices, distances, worst = impl.knn_result_set(np.array([0.5, 0.25]), np.array([4, 2]), 5)
    check_result_set(indices, distances, worst, 2, 2)
    assert indices.tolist() == [2, 4] and distances.tolist() == [0.25, 0.5], "fewer than k: return them all, sorted"
    assert np.all(np.isinf(worst)), "worst is inf while fewer than k are held"
    empty = impl.knn_result_set(np.empty(0), np.empty(0, dtype=np.int64), 3)
    assert [len(a) for a in empty] == [0, 0, 0], "no candidates: three empty arrays"


@pytest.mark.grades("knn_result_set")
@pytest.mark.points(1)
@pytest.mark.interface
def test_knn_result_set_rejects_bad_input(impl):
    with raises(ValueError, naming="distances"):
        impl.knn_result_set(np.array([1.0, -1.0]), np.array([0, 1]), 1)
    with raises(ValueError):
        impl.knn_result_set(np.array([1.0, np.nan]), np.array([0, 1]), 1)
    with raises(ValueError, naming="indices"):
        impl.knn_result_set(np.array([1.0, 2.0]), np.array([0]), 1)
    with raises(ValueError, naming="k"):
        impl.knn_result_set(np.array([1.0]), np.array([0]), 0)


# -- bst_build, bst_knn ----------------------------------------------------------------------------


@pytest.mark.grades("bst_build")
@pytest.mark.points(2)
def test_bst_build_hand_worked(impl):
    # 5 is the root; 3 < 5 goes left; 8 right; the second 5 is not < 5: right of the root, then left of 8.
    left, right = impl.bst_build(np.array([5.0, 3.0, 8.0, 5.0]))
    check_array(left, "left", shape=(4,), dtype="int64")
    check_array(right, "right", shape=(4,), dtype="int64")
    assert left.tolist() == [1, -1, 3, -1] and right.tolist() == [2, -1, -1, -1], (
        f"expected left [1, -1, 3, -1], right [2, -1, -1, -1] (equal keys go right), got {left}, {right}"
    )


@pytest.mark.grades("bst_build")
@pytest.mark.points(3)
def test_bst_build_inserts_in_order_with_duplicates(impl):
    rng = np.random.default_rng(11)
    for n in (1, 2, 40, 500):
        keys = rng.integers(0, max(n // 3, 1), n).astype(float)
        left, right = impl.bst_build(keys)
        check_bst(left, right, keys)


@pytest.mark.grades("bst_build")
@pytest.mark.points(2)
def test_bst_build_of_sorted_keys_is_a_path(impl):
    keys = np.arange(1500.0)  # depth 1499: beyond Python's recursion limit
    left, right = impl.bst_build(keys)
    check_array(left, "left", shape=(1500,), dtype="int64")
    check_array(right, "right", shape=(1500,), dtype="int64")
    assert np.all(left == -1) and right.tolist() == [*range(1, 1500), -1], (
        "sorted keys make a path of right children: every left is -1 and right[j] = j + 1"
    )


@pytest.mark.grades("bst_build")
@pytest.mark.points(1)
@pytest.mark.interface
def test_bst_build_empty_and_bad_keys(impl):
    left, right = impl.bst_build(np.empty(0))
    check_array(left, "left", shape=(0,), dtype="int64")
    check_array(right, "right", shape=(0,), dtype="int64")
    with raises(ValueError, naming="keys"):
        impl.bst_build(np.array([1.0, np.inf]))


def bst_of(impl, keys):
    if grader_trees is not None:
        return grader_trees.bst(keys)
    left, right = impl.bst_build(keys)
    try:
        check_bst(left, right, keys)
    except AssertionError as exc:
        raise AssertionError(f"locally this search runs on your own bst_build, which is wrong: {exc}") from None
    return left, right


@pytest.mark.grades("bst_knn")
@pytest.mark.points(3)
def test_bst_knn_matches_brute_force(impl):
    rng = np.random.default_rng(12)
    keys = np.round(rng.normal(0, 10, 400), 1)  # ties among keys and distances
    left, right = bst_of(impl, keys)
    far = ((-1.0e11, 40), (2.5e11, 3))  # every key beyond any finite starting worst distance
    for query, k in ((0.05, 1), (3.0, 7), (-40.0, 5), (12.35, 400), (rng.normal(0, 10), 25), *far):
        indices, distances = impl.bst_knn(keys, left, right, query, k)
        expected = np.lexsort((np.arange(len(keys)), np.abs(keys - query)))[:k]
        check_array(indices, "indices", shape=(k,), dtype="int64")
        check_array(distances, "distances", shape=(k,))
        check_knn(
            indices[None],
            distances[None],
            expected[None],
            np.abs(keys[expected] - query)[None],
            f"bst_knn, query {query:g}, k={k}",
        )


@pytest.mark.grades("bst_knn")
@pytest.mark.points(1)
def test_bst_knn_tie_in_the_far_subtree(impl):
    # Root 10 (node 0); the second 10 (node 1) goes right; 9 (node 2) goes left. Query 9.5, k = 2: all three
    # are 0.5 away. The left side holds (0.5, node 2) when the search turns back at the root, with w = 0.5;
    # |10 - 9.5| = 0.5 <= w, so the right side is searched and node 1 evicts node 2: [0, 1].
    keys = np.array([10.0, 10.0, 9.0])
    left, right = bst_of(impl, keys)
    indices, distances = impl.bst_knn(keys, left, right, 9.5, 2)
    check_array(indices, "indices", shape=(2,), dtype=None)
    assert indices.tolist() == [0, 1], (
        f"expected [0, 1], got {indices.tolist()}: equal keys go right, so a tie at the k-th distance can lie "
        "on the far side; search it when |keys[j] - query| <= w (inclusive)"
    )
    tie = np.array([[0, 1]])
    check_knn(np.asarray(indices)[None], np.asarray(distances)[None], tie, np.array([[0.5, 0.5]]), "bst_knn")


@pytest.mark.grades("bst_knn")
@pytest.mark.points(1)
def test_bst_knn_on_a_path_of_sorted_keys(impl):
    keys = np.arange(1500.0) / 2
    left, right = bst_of(impl, keys)
    indices, distances = impl.bst_knn(keys, left, right, 700.3, 3)
    check_array(indices, "indices", shape=(3,), dtype=None)
    assert indices.tolist() == [1401, 1400, 1402], "a path of depth 1499: search it with a loop or an explicit stack"
    nearest = np.array([[1401, 1400, 1402]])
    check_knn(np.asarray(indices)[None], np.asarray(distances)[None], nearest, np.abs(keys[nearest] - 700.3), "bst_knn")


@pytest.mark.grades("bst_knn")
@pytest.mark.points(1)
def test_bst_knn_never_reads_a_subtree_its_rule_skips(impl):
    # The second cluster's keys, all above the first's, hang below the first's largest key: for a query in
    # [-0.8, 0], |that key - query| is far above w, so the rule never goes there.
    keys = two_clusters(300, 13, dim=1)[:, 0]
    left, right = bst_of(impl, keys)
    far = np.arange(300, 600)
    for query, k in ((-0.8, 1), (-0.35, 4), (0.0, 9)):
        indices, distances = impl.bst_knn(with_decoys(keys, far, query, k), left, right, query, k)
        check_array(indices, "indices", shape=(k,), dtype="int64")
        check_no_decoy(indices, far, "bst_knn")
        expected = np.lexsort((np.arange(300), np.abs(keys[:300] - query)))[:k]
        check_knn(indices[None], distances[None], expected[None], np.abs(keys[expected] - query)[None], "bst_knn")


@pytest.mark.grades("bst_knn")
@pytest.mark.points(1)
@pytest.mark.interface
def test_bst_knn_checks_its_input(impl):
    keys = np.array([5.0, 3.0, 8.0])
    left, right = np.array([1, -1, -1]), np.array([2, -1, -1])
    with raises(ValueError, naming="k"):
        impl.bst_knn(keys, left, right, 4.0, 4)
    with raises(ValueError):
        impl.bst_knn(keys, np.array([1, 1, -1]), right, 4.0, 1)  # node 1 is its own child
    with raises(ValueError):
        impl.bst_knn(keys, left, right, np.nan, 1)
    for query in (np.float64(4.0), np.array(4.0)):  # a NumPy scalar and a 0-d array are queries too
        indices, _ = impl.bst_knn(keys, left, right, query, 2)
        check_array(indices, "indices", shape=(2,), dtype=None)
        assert indices.tolist() == [0, 1], f"query {query!r}: expected [0, 1], got {indices.tolist()}"


# -- kdtree_build -------------------------------------------------------------------------------


@pytest.mark.grades("kdtree_build")
@pytest.mark.points(2)
def test_kdtree_build_hand_worked(impl):
    # Root: x of (0, 0), (2, 5), (4, 1) is 0, 2, 4; m = ceil(3/2) = 2 go left; split (2 + 4) / 2 = 3.
    # Node 1 (depth 1, axis y): (0, 0) and (2, 5), split 2.5; nodes 2, 3 its leaves; node 4 the root's right.
    tree = impl.kdtree_build(np.array([[0.0, 0.0], [4.0, 1.0], [2.0, 5.0]]), 1)
    assert isinstance(tree, dict), "kdtree_build returns a dict"
    expected = {
        "order": [0, 2, 1],
        "start": [0, 0, 0, 1, 2],
        "stop": [3, 2, 1, 2, 3],
        "axis": [0, 1, -1, -1, -1],
        "left": [1, 2, -1, -1, -1],
        "right": [4, 3, -1, -1, -1],
    }
    for key, value in expected.items():
        got = as_list(tree.get(key), len(value))
        assert got == value, f"tree[{key!r}]: expected {value}, got {got}"
    split = np.asarray(tree["split"])
    assert split[:2].tolist() == [3.0, 2.5] and np.all(np.isnan(split[2:])), (
        f"split: expected [3, 2.5, nan x3], {split}"
    )


@pytest.mark.grades("kdtree_build")
@pytest.mark.points(4)
def test_kdtree_build_follows_the_median_rule(impl):
    for points, leaf_size in (
        (cube(1000, 21), 16),
        (cube(777, 22, dim=2), 5),
        (scan_like(1500, 23), 8),
        (cube(300, 24, dim=5), 3),
        (np.round(cube(400, 25), 1), 4),  # equal coordinates on both sides of a split
    ):
        check_kdtree(impl.kdtree_build(points, leaf_size), points, leaf_size)


@pytest.mark.grades("kdtree_build")
@pytest.mark.points(2)
def test_kdtree_build_with_duplicates_and_leaf_size_one(impl):
    duplicates = np.vstack([np.zeros((40, 3)), np.ones((25, 3)), cube(10, 26)])
    check_kdtree(impl.kdtree_build(duplicates, 4), duplicates, 4)  # terminates: halves are never empty
    points = cube(64, 27)
    check_kdtree(impl.kdtree_build(points, 1), points, 1)


@pytest.mark.grades("kdtree_build")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kdtree_build_edge_cases_and_bad_input(impl):
    empty = impl.kdtree_build(np.empty((0, 3)), 16)
    check_kdtree(empty, np.empty((0, 3)), 16)
    points = cube(10, 28)
    check_kdtree(impl.kdtree_build(points, 10), points, 10)  # one leaf
    with raises(ValueError, naming="leaf_size"):
        impl.kdtree_build(points, 0)
    with raises(ValueError):
        impl.kdtree_build(np.array([[0.0, np.nan]]), 1)


# -- kdtree_knn, kdtree_radius -------------------------------------------------------------------


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(4)
def test_kdtree_knn_matches_brute_force(impl):
    for points, queries, k, leaf in (
        (cube(2000, 31), cube(60, 32), 8, 16),
        (scan_like(2000, 33), scan_like(60, 34) + 0.05, 5, 8),
        (cube(1500, 35, dim=2), cube(50, 36, dim=2) * 1.2, 12, 4),
        (cube(1200, 301, dim=5), cube(40, 302, dim=5), 6, 8),  # D > 3: a k-d tree has any number of axes
    ):
        tree = kd_tree(impl, points, leaf)
        check_knn(*impl.kdtree_knn(tree, points, queries, k), *brute_knn(points, queries, k), "kdtree_knn")


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(2)
def test_kdtree_knn_self_far_and_large_coordinate_queries(impl):
    points = cube(1000, 37) + [4.0e6, -2.0e6, 1.0e3]  # UTM-like coordinates
    tree = kd_tree(impl, points, 8)
    queries = np.vstack([points[:30], points[:10] + [50.0, 0, 0]])
    check_knn(*impl.kdtree_knn(tree, points, queries, 6), *brute_knn(points, queries, 6), "kdtree_knn")
    indices, distances = impl.kdtree_knn(tree, points, points[:5], 1)
    check_array(indices, "indices", shape=(5, 1), dtype=None)
    assert indices[:, 0].tolist() == list(range(5)) and np.all(distances == 0), "a point is its own nearest"
    points, queries = far_cloud(300, 38)  # the k-th neighbour 1e11 away
    tree = kd_tree(impl, points, 8)
    check_knn(*impl.kdtree_knn(tree, points, queries, 20), *brute_knn(points, queries, 20), "kdtree_knn, far queries")


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(1)
def test_kdtree_knn_never_reads_a_cluster_its_rule_skips(impl):
    points = two_clusters(300, 39)  # the root splits them, some 50 from either
    tree = kd_tree(impl, points, 8)
    far = np.arange(300, 600)
    for query in cube(4, 40) * 0.7:
        indices, distances = impl.kdtree_knn(tree, with_decoys(points, far, query, 6), query[None], 6)
        check_array(indices, "indices", shape=(1, 6), dtype="int64")
        check_no_decoy(indices, far, "kdtree_knn")
        check_knn(indices, distances, *brute_knn(points[:300], query[None], 6), "kdtree_knn")


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(3)
def test_kdtree_knn_on_a_grid_with_exact_ties(impl):
    points = grid(7)
    tree = kd_tree(impl, points, 4)
    queries = np.vstack([points[::13], points[::17] + 0.5])
    for k in (1, 7, 19, 27):  # 7: the point and its 6 face neighbours at distance 1, ties everywhere
        check_knn(*impl.kdtree_knn(tree, points, queries, k), *brute_knn(points, queries, k), f"kdtree_knn, k={k}")


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kdtree_knn_bad_input_and_no_queries(impl):
    points = cube(50, 38)
    tree = kd_tree(impl, points, 4)
    indices, distances = impl.kdtree_knn(tree, points, np.empty((0, 3)), 3)
    check_array(indices, "indices", shape=(0, 3), dtype="int64")
    with raises(ValueError, naming="k"):
        impl.kdtree_knn(tree, points, points[:2], 51)
    with raises(ValueError, naming="queries"):
        impl.kdtree_knn(tree, points, np.zeros((2, 2)), 1)
    with raises(ValueError, naming="tree"):
        impl.kdtree_knn({"order": tree["order"]}, points, points[:2], 1)


@pytest.mark.grades("kdtree_radius")
@pytest.mark.points(3)
def test_kdtree_radius_matches_brute_force(impl):
    for points, queries, radius, leaf in (
        (cube(2000, 41), cube(50, 42), 0.2, 16),
        (scan_like(2000, 43), scan_like(50, 44), 0.5, 8),
        (cube(1000, 45, dim=2), cube(40, 46, dim=2), 0.1, 3),
        (cube(1200, 303, dim=4), cube(40, 304, dim=4), 0.5, 8),  # D > 3
    ):
        tree = kd_tree(impl, points, leaf)
        check_csr(impl.kdtree_radius(tree, points, queries, radius), brute_radius(points, queries, radius))


@pytest.mark.grades("kdtree_radius")
@pytest.mark.points(2)
def test_kdtree_radius_zero_finds_duplicates_and_a_large_radius_finds_all(impl):
    points = np.vstack([cube(300, 47), cube(300, 47)[:40]])  # 40 exact duplicates
    tree = kd_tree(impl, points, 8)
    check_csr(impl.kdtree_radius(tree, points, points[:60], 0.0), brute_radius(points, points[:60], 0.0))
    check_csr(impl.kdtree_radius(tree, points, points[:3], 10.0), brute_radius(points, points[:3], 10.0))


@pytest.mark.grades("kdtree_radius")
@pytest.mark.points(2)
def test_kdtree_radius_on_a_grid_with_an_integer_radius(impl):
    points = grid(6)
    tree = kd_tree(impl, points, 2)
    queries = points[::7]
    for radius in (1.0, 2.0):  # neighbours exactly at the radius, and on split planes
        check_csr(impl.kdtree_radius(tree, points, queries, radius), brute_radius(points, queries, radius))


@pytest.mark.grades("kdtree_radius")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kdtree_radius_rejects_bad_radii(impl):
    points = cube(30, 48)
    tree = kd_tree(impl, points, 4)
    for radius in (-0.1, np.nan, np.inf):
        with raises(ValueError, naming="radius"):
            impl.kdtree_radius(tree, points, points[:2], radius)


# -- octree_build -------------------------------------------------------------------------------


@pytest.mark.grades("octree_build")
@pytest.mark.points(2)
def test_octree_build_hand_worked(impl):
    # Root: centre (1, 1, 1), extent 1. (1, 0, 0) lies on the plane x = 1: code 0, with (0, 0, 0); (2, 2, 2): code 7.
    # Node 1 (centre 0.5, extent 0.5) splits (0, 0, 0) -> code 0 and (1, 0, 0) -> code 1.
    tree = impl.octree_build(np.array([[0.0, 0, 0], [2.0, 2, 2], [1.0, 0, 0]]), 1)
    assert isinstance(tree, dict), "octree_build returns a dict"
    assert as_list(tree["children"][0], 8) == [1, -1, -1, -1, -1, -1, -1, 4], (
        f"root's children: expected [1, -1, ..., -1, 4], got {tree['children'][0]}"
    )
    extent = as_list(tree["extent"], 5)
    assert extent == [1.0, 0.5, 0.25, 0.25, 0.5], (
        f"extent (half the side of each node's cube, nodes in preorder): expected [1, 0.5, 0.25, 0.25, 0.5], got "
        f"{extent}: the root's is half the bounding cube's side, each child's half its parent's"
    )
    order = as_list(tree["order"], 3)
    assert order == [0, 2, 1], f"order: expected [0, 2, 1] (the leaves' points in preorder), got {order}"
    center = as_list(tree["center"][3], 3)
    assert center == [0.75, 0.25, 0.25], (
        f"center of node 3 (code 1 under node 1): expected [0.75, 0.25, 0.25], got {center}: a child's centre "
        "is its parent's plus or minus half the parent's extent on each axis, + where its code's bit is 1"
    )


@pytest.mark.grades("octree_build")
@pytest.mark.points(4)
def test_octree_build_follows_the_rules(impl):
    for points, leaf_size in ((cube(1000, 51), 8), (scan_like(1500, 52), 16), (np.round(cube(500, 53), 1), 2)):
        check_octree(impl.octree_build(points, leaf_size, 1e-3), points, leaf_size, 1e-3)


@pytest.mark.grades("octree_build")
@pytest.mark.points(2)
def test_octree_build_root_cube_is_the_bounding_cube(impl):
    rng = np.random.default_rng(54)
    skewed = np.vstack([rng.normal(0, 0.05, (300, 3)), [[10.0, 0.2, -0.1]], rng.uniform(-1, 1, (20, 3))])
    skewed = np.hstack([skewed, rng.uniform(size=(len(skewed), 1))])  # a fourth column, not a coordinate
    tree = impl.octree_build(skewed, 8)
    check_octree(tree, skewed, 8, 1e-3)


@pytest.mark.grades("octree_build")
@pytest.mark.points(2)
def test_octree_build_stops_at_min_extent(impl):
    points = np.vstack([np.full((100, 3), 0.25), cube(30, 55)])
    tree = impl.octree_build(points, 4, 0.01)
    check_octree(tree, points, 4, 0.01)
    same = np.ones((50, 3))
    check_octree(impl.octree_build(same, 4), same, 4, 1e-3)  # extent 0 at the root: one leaf


@pytest.mark.grades("octree_build")
@pytest.mark.points(1)
@pytest.mark.interface
def test_octree_build_edge_cases_and_bad_input(impl):
    tree = impl.octree_build(np.empty((0, 3)))
    check_octree(tree, np.empty((0, 3)), 8, 1e-3)
    check_octree(impl.octree_build(np.ones((1, 3))), np.ones((1, 3)), 8, 1e-3)
    with raises(ValueError, naming="min_extent"):
        impl.octree_build(cube(10, 56), 1, 0.0)
    with raises(ValueError, naming="points"):
        impl.octree_build(cube(10, 56)[:, :2])


# -- octree_radius, octree_knn -------------------------------------------------------------------


@pytest.mark.grades("octree_radius")
@pytest.mark.points(4)
def test_octree_radius_matches_brute_force(impl):
    for points, queries, radius, leaf in (
        (cube(2000, 61), cube(50, 62) * 1.3, 0.25, 8),  # some queries outside the root cube
        (scan_like(2000, 63), scan_like(50, 64), 0.6, 16),
        (cube(1000, 65), cube(30, 66), 1.5, 4),  # large balls: whole octants inside
        (*with_intensity(cube(1200, 305), cube(40, 306), 307), 0.3, 8),  # xyz and an intensity, not a coordinate
    ):
        tree = oc_tree(impl, points, leaf)
        expected = brute_radius(points[:, :3], queries[:, :3], radius)
        check_csr(impl.octree_radius(tree, points, queries, radius), expected)


@pytest.mark.grades("octree_radius")
@pytest.mark.points(2)
def test_octree_radius_on_a_grid(impl):
    for points in (grid(8), grid(9)):  # an odd side puts points on centre planes, on the lower octants' faces
        tree = oc_tree(impl, points, 2)
        queries = np.vstack([points[::11], points[::23] + 0.5])
        for radius in (1.0, 1.5, 3.0, 0.0):  # points at exactly the radius, on centre planes and faces; duplicates
            check_csr(impl.octree_radius(tree, points, queries, radius), brute_radius(points, queries, radius))


@pytest.mark.grades("octree_radius")
@pytest.mark.points(1)
@pytest.mark.interface
def test_octree_radius_rejects_bad_input(impl):
    points = cube(30, 67)
    tree = oc_tree(impl, points, 4)
    with raises(ValueError, naming="radius"):
        impl.octree_radius(tree, points, points[:2], -1.0)
    wide = np.hstack([points, np.ones((30, 1))])  # xyz and one more column
    with raises(ValueError, naming="queries"):  # the queries are as wide as the points, though xyz is used
        impl.octree_radius(oc_tree(impl, wide, 4), wide, points[:2], 0.5)
    indptr, indices, distances = impl.octree_radius(tree, points, np.empty((0, 3)), 0.5)
    check_array(indptr, "indptr", shape=(1,), dtype=None)
    assert indptr.tolist() == [0] and len(indices) == 0, "no queries: indptr [0] and empty rows"


@pytest.mark.grades("octree_knn")
@pytest.mark.points(4)
def test_octree_knn_matches_brute_force(impl):
    for points, queries, k, leaf in (
        (cube(2000, 71), cube(50, 72) * 1.2, 8, 8),
        (scan_like(2000, 73), scan_like(50, 74), 5, 16),
        (cube(300, 75), cube(20, 76), 300, 4),  # k = N
        (*far_cloud(300, 78), 20, 8),  # UTM-like coordinates, the k-th neighbour 1e11 away
        (*with_intensity(cube(1200, 308), cube(40, 309), 310), 6, 8),  # xyz and an intensity, not a coordinate
    ):
        tree = oc_tree(impl, points, leaf)
        expected = brute_knn(points[:, :3], queries[:, :3], k)
        check_knn(*impl.octree_knn(tree, points, queries, k), *expected, "octree_knn")


@pytest.mark.grades("octree_knn")
@pytest.mark.points(2)
def test_octree_knn_on_a_grid_with_exact_ties(impl):
    for points in (grid(8), grid(9)):  # an odd side puts points on centre planes, on the lower octants' faces
        tree = oc_tree(impl, points, 2)
        queries = np.vstack([points[::9], points[::19] + 0.5])
        for k in (1, 7, 19):
            check_knn(*impl.octree_knn(tree, points, queries, k), *brute_knn(points, queries, k), f"octree_knn, k={k}")


@pytest.mark.grades("octree_knn")
@pytest.mark.points(1)
def test_octree_knn_never_reads_a_cluster_its_rule_skips(impl):
    points = two_clusters(300, 79)  # the root's x-plane splits them, some 50 from either
    tree = oc_tree(impl, points, 8)
    far = np.arange(300, 600)
    for query in cube(4, 80) * 0.7:
        indices, distances = impl.octree_knn(tree, with_decoys(points, far, query, 6), query[None], 6)
        check_array(indices, "indices", shape=(1, 6), dtype="int64")
        check_no_decoy(indices, far, "octree_knn")
        check_knn(indices, distances, *brute_knn(points[:300], query[None], 6), "octree_knn")


@pytest.mark.grades("octree_knn")
@pytest.mark.points(1)
@pytest.mark.interface
def test_octree_knn_rejects_bad_input(impl):
    points = cube(30, 77)
    tree = oc_tree(impl, points, 4)
    with raises(ValueError, naming="k"):
        impl.octree_knn(tree, points, points[:2], 0)
    with raises(ValueError, naming="tree"):
        impl.octree_knn(tree, points[:20], points[:2], 1)  # a tree of 30 points
