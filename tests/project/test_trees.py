"""The grader's own trees (grading/instructors/trees.py) agree with the reference, and its lying trees lie as the
book's theorem needs: the rule's answer unchanged, brute force's changed."""

import numpy as np
import pytest

from grading.instructors import lying_trees, tree_searches, trees
from solutions import nn

# Run again with numba's bounds checking: tests/project/test_kernels.py.
pytestmark = pytest.mark.kernels

CLOUDS = {
    "uniform": lambda rng: rng.uniform(size=(600, 3)),
    "grid": lambda rng: np.stack(np.meshgrid(*[np.arange(6.0)] * 3, indexing="ij"), -1).reshape(-1, 3),
    "duplicates": lambda rng: np.repeat(rng.uniform(size=(60, 3)), 5, axis=0),
    "flat 2-D": lambda rng: rng.normal(size=(400, 2)) * [10.0, 0.1],
}


@pytest.mark.parametrize("name", CLOUDS)
def test_the_grader_builds_the_references_trees(name, rng):
    points = CLOUDS[name](rng)
    for leaf_size in (1, 5, 16):
        expected, got = nn.kdtree_build(points, leaf_size), trees.kdtree(points, leaf_size)
        assert all(np.array_equal(expected[k], got[k], equal_nan=True) for k in expected), (name, leaf_size)
        if points.shape[1] >= 3:
            expected, got = nn.octree_build(points, leaf_size), trees.octree(points, leaf_size, 1e-3)
            assert all(np.array_equal(expected[k], got[k]) for k in expected), (name, leaf_size)


@pytest.mark.parametrize("name", ["uniform", "grid", "duplicates"])
def test_the_graders_searches_match_the_reference(name, rng):
    points = CLOUDS[name](rng)
    queries = np.vstack([points[:20], rng.uniform(points.min(0), points.max(0), size=(20, 3))])
    kd, oc = nn.kdtree_build(points, 8), nn.octree_build(points, 8)
    for expected, got in (
        (nn.kdtree_knn(kd, points, queries, 7), tree_searches.kdtree_search(kd, points, queries, k=7)),
        (nn.kdtree_radius(kd, points, queries, 1.0), tree_searches.kdtree_search(kd, points, queries, radius=1.0)),
        (nn.octree_knn(oc, points, queries, 7), tree_searches.octree_search(oc, points, queries, k=7)),
        (nn.octree_radius(oc, points, queries, 1.0), tree_searches.octree_search(oc, points, queries, radius=1.0)),
    ):
        assert all(np.array_equal(e, g) if e.dtype.kind == "i" else np.allclose(e, g) for e, g in zip(expected, got))


def test_a_lying_tree_keeps_the_rules_answer_and_fools_brute_force(rng):
    points = rng.uniform(size=(4096, 3))
    for build, reach, search in (
        (lambda: trees.kdtree(points, 8), lambda t, q: trees.kdtree_reach(t, points, q, k=4)[0], nn.kdtree_knn),
        (lambda: trees.octree(points, 8, 1e-3), lambda t, q: trees.octree_reach(t, points, q, k=4)[0], nn.octree_knn),
    ):
        tree = build()
        for query in rng.uniform(0.1, 0.9, size=(5, 3)):
            reached = reach(tree, query)
            within = np.sqrt(np.sort(trees.squared_distances(points, query))[3])  # the 4th distance
            lying, decoys = lying_trees.decoy_points(points, tree, reached, query, within, rng)
            assert len(decoys) > 10 * len(reached)
            original = trees.brute_knn(points, query, 4)[0]
            assert np.array_equal(search(tree, lying, query[None], 4)[0][0], original)  # the rule is not fooled
            assert set(trees.brute_knn(lying, query, 4)[0]) <= set(decoys)  # brute force is


@pytest.mark.parametrize(
    "balanced, compact", [(True, True), (False, True), (False, False)], ids=["median", "midpoint", "sliding"]
)
@pytest.mark.parametrize("name", ["uniform", "duplicates", "flat 2-D"])
def test_scipy_trees_in_the_course_layout_are_valid_trees_that_search_right(name, balanced, compact, rng):
    """The book's split-rule comparison searches SciPy's trees with the course's own search."""
    from pcl_course.neighbors import scipy_kdtree
    from pcl_course.validation import check_kdtree

    points = CLOUDS[name](rng)
    tree = scipy_kdtree(points, 8, balanced_tree=balanced, compact_nodes=compact)
    check_kdtree(tree, len(points), points.shape[1])
    for node in np.flatnonzero(tree["axis"] >= 0):
        axis, split = tree["axis"][node], tree["split"][node]
        left, right = (
            tree["order"][tree["start"][c] : tree["stop"][c]] for c in (tree["left"][node], tree["right"][node])
        )
        assert np.all(points[left, axis] <= split) and np.all(points[right, axis] >= split)
    queries = np.vstack([points[:10], rng.uniform(points.min(0), points.max(0), size=(10, points.shape[1]))])
    expected = tree_searches.kdtree_search(nn.kdtree_build(points, 8), points, queries, k=5)
    got = nn.kdtree_knn(tree, points, queries, 5)
    assert np.array_equal(expected[0], got[0]) and np.allclose(expected[1], got[1])


@pytest.mark.parametrize("leaf_size", [1, 3, 16])
def test_the_threaded_build_numbers_its_subtrees_as_one_preorder(leaf_size, rng, monkeypatch):
    """The reference splits its top levels, then builds subtrees in threads with precomputed ids."""
    monkeypatch.setattr(nn, "_PARALLEL_BUILD_POINTS", 0)  # thread even a small cloud
    for points in (rng.uniform(size=(1_001, 3)), np.repeat(rng.uniform(size=(90, 2)), 11, axis=0)):
        expected, got = trees.kdtree(points, leaf_size), nn.kdtree_build(points, leaf_size)
        assert all(np.array_equal(expected[k], got[k], equal_nan=True) for k in expected)


def test_the_threaded_build_equals_the_graders_tree_on_a_large_cloud(rng):
    """Above the threading threshold, with duplicates: the grader's plain build is the oracle."""
    points = np.vstack([rng.uniform(size=(100_000, 3)), np.repeat(rng.uniform(size=(2_000, 3)), 10, axis=0)])
    assert len(points) >= nn._PARALLEL_BUILD_POINTS
    threaded, expected = nn.kdtree_build(points, 16), trees.kdtree(points, 16)
    assert all(np.array_equal(threaded[k], expected[k], equal_nan=True) for k in expected)


def test_the_unguarded_value_split_is_the_students_build_and_endless_only_on_points_equal_on_every_axis(rng):
    from tests.mutants import _plain_trees

    cloud = rng.uniform(size=(400, 3))
    cloud[:, 0] = rng.integers(0, 3, size=400)  # equal x: empty sides, then a split on the next axis
    grader = trees.kdtree(cloud, 4, partition="value", guard=False)
    student = _plain_trees.kdtree_build(cloud, 4, partition="value, unguarded")
    assert any(stop == start for start, stop in zip(grader["start"], grader["stop"]))  # an empty child was made
    for key in grader:
        assert np.array_equal(grader[key], student[key], equal_nan=True), key
    same_on_x_and_y = np.column_stack([np.zeros(30), np.zeros(30), np.arange(30.0)])
    assert np.array_equal(trees.kdtree(same_on_x_and_y, 4, partition="value", guard=False)["order"], np.arange(30))
    duplicates = np.vstack([np.zeros((40, 3)), rng.uniform(size=(10, 3))])
    for build in (
        lambda: trees.kdtree(duplicates, 4, partition="value", guard=False),
        lambda: _plain_trees.kdtree_build(duplicates, 4, partition="value, unguarded"),
    ):
        with pytest.raises(RecursionError):
            build()


def test_a_tree_of_array_subclasses_is_refused_before_a_search_reads_it(rng):
    """A masked array hides entries from the checks (np.any skips them) but not from the kernels,
    which read the raw data: a start of -1000 masked passed the range check."""
    points = rng.uniform(size=(200, 3))
    for build, search in ((nn.kdtree_build, nn.kdtree_knn), (nn.octree_build, nn.octree_knn)):
        tree = build(points, 8)
        start = np.ma.masked_array(tree["start"].copy(), mask=np.zeros(len(tree["start"]), bool))
        start[1], start.mask[1] = -1000, True
        with pytest.raises(ValueError, match=r"\['start'\] must be a NumPy array \(not a subclass\)"):
            search({**tree, "start": start}, points, points[:3], 2)
