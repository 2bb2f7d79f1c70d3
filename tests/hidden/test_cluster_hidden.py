"""Hidden graded tests of lecture 3 (``pcl_course/cluster.py``): the same contract on clouds the
students have not seen. The expected answers come from the contract's rules written here (the
nearest centre by the column-wise squared distance, the D² draws), not from the reference."""

import numpy as np
import pytest

from grading.checks import CheckFailed, check_array, check_close

# Run by the instructors' grader only; feedback withholds expected values.
pytestmark = pytest.mark.hidden


def _nearest(points, centers):
    s = sum((points[:, j, None] - centers[None, :, j]) ** 2 for j in range(points.shape[1]))
    return np.argmin(s, axis=1)


def _lloyd(points, centers, max_iter):
    """The contract's Lloyd iterations: labels, centres, inertia list, n_iter."""
    centers = centers.copy()
    previous, inertia = None, []
    for t in range(1, max_iter + 1):
        labels = _nearest(points, centers)
        inertia.append(float(((points - centers[labels]) ** 2).sum()))
        if previous is not None and np.array_equal(labels, previous):
            return labels, centers, inertia, t
        for c in range(len(centers)):
            if np.any(labels == c):
                centers[c] = points[labels == c].mean(axis=0)
        previous = labels
    return _nearest(points, centers), centers, inertia, max_iter


def _street_like(seed):
    """Elongated, unequal clusters in metres at UTM-like coordinates (about 4e6 m): a squared
    distance expanded as |x|^2 - 2 x.c + |c|^2 loses every digit there."""
    rng = np.random.default_rng(seed)
    parts = [
        rng.normal(0, 1, size=(n, 3)) * scale + centre
        for n, scale, centre in [
            (400, [4.0, 1.0, 0.5], [0, 0, 0]),
            (120, [0.8, 0.8, 0.8], [9, 3, 0]),
            (60, [0.3, 0.3, 1.5], [-6, 7, 1]),
            (250, [2.0, 2.0, 0.3], [3, -8, -1]),
        ]
    ]
    return np.vstack(parts) + [512_345.0, 4_201_789.0, 35.0]


@pytest.mark.grades("kmeans")
@pytest.mark.points(3)
def test_kmeans_hidden_far_from_the_origin(impl):
    for seed, k in ((1, 4), (2, 6), (3, 9)):
        points = _street_like(seed)
        start = points[np.random.default_rng(seed).choice(len(points), k, replace=False)].copy()
        labels, centers, inertia, n_iter = impl.kmeans(points, start, 100)
        check_array(labels, "labels", shape=(len(points),), dtype="int64")
        expected = _lloyd(points, start, 100)
        if not np.array_equal(labels, expected[0]):
            raise CheckFailed("labels are wrong on a cloud far from the origin", rule="labels are wrong")
        check_close(centers, expected[1], "centers", rtol=1e-12, atol=1e-9)
        assert n_iter == expected[3], "n_iter is wrong on a cloud far from the origin"
        check_close(inertia, expected[2], "inertia", rtol=1e-8)


@pytest.mark.grades("kmeans")
@pytest.mark.points(2)
def test_kmeans_hidden_truncated_and_with_empty_clusters(impl):
    rng = np.random.default_rng(77)
    points = rng.uniform(-1, 1, size=(300, 2)) * [3.0, 1.0]
    # Two centres far out: they never get a point, and keep their places, at every max_iter.
    start = np.vstack([points[:5], [[40.0, 40.0], [-40.0, 40.0]]])
    for max_iter in (1, 2, 3, 7, 300):
        labels, centers, inertia, n_iter = impl.kmeans(points, start, max_iter)
        expected = _lloyd(points, start, max_iter)
        check_array(labels, "labels", shape=(300,), dtype="int64")
        if not np.array_equal(labels, expected[0]):
            raise CheckFailed(f"labels are wrong with max_iter = {max_iter}", rule="labels are wrong")
        check_close(centers, expected[1], f"centers with max_iter = {max_iter}", rtol=1e-12, atol=1e-12)
        assert n_iter == expected[3], f"n_iter is wrong with max_iter = {max_iter}"


def _d2(points, n_clusters, seed):
    rng = np.random.default_rng(seed)
    chosen = [int(rng.integers(len(points)))]
    w = ((points - points[chosen[0]]) ** 2).sum(axis=1)
    while len(chosen) < n_clusters:
        cumulative = np.cumsum(w)
        chosen.append(int(np.searchsorted(cumulative, rng.random() * cumulative[-1], side="right")))
        w = np.minimum(w, ((points - points[chosen[-1]]) ** 2).sum(axis=1))
    return chosen


@pytest.mark.grades("kmeans_plusplus")
@pytest.mark.points(2)
def test_kmeans_plusplus_hidden_draws(impl):
    points = _street_like(9)
    points = np.vstack([points, points[:50]])  # duplicates
    for seed, k in ((5, 12), (6, 3), (7, 25)):
        result = impl.kmeans_plusplus(points, k, rng=seed)
        check_array(result, "indices", shape=(k,), dtype="int64")
        if result.tolist() != _d2(points, k, seed):
            raise CheckFailed(f"the draws are wrong (rng = {seed})", rule="the draws are wrong")
