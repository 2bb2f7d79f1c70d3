"""Hidden graded tests of lecture 3 (``pcl_course/cluster.py``): the same contract on clouds the
students have not seen. The expected answers come from the contract's rules written here (the
nearest centre by the column-wise squared distance, the D² draws), not from the reference."""

import numpy as np
import pytest

from grading.checks import CheckFailed, check_array, check_close
from grading.checks.cluster import (
    laplacian,
    linked_components,
    lloyd,
    neighbour_graph,
    njw_labels,
    projector_distance,
    scikit_learn_em,
)

# Run by the instructors' grader only; feedback withholds expected values.
pytestmark = pytest.mark.hidden


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
        expected = lloyd(points, start, 100)
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
        expected = lloyd(points, start, max_iter)
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


def _density_clusters(points, eps, min_samples):
    """The contract's DBSCAN from its rules: cores by |N(p)| (itself included, s <= eps^2), clusters the
    components of the cores numbered by their smallest core, a border the smallest label it touches."""
    s = sum((points[:, j, None] - points[None, :, j]) ** 2 for j in range(points.shape[1]))
    near = s <= eps * eps
    is_core = near.sum(axis=1) >= min_samples
    labels = np.full(len(points), -1, dtype=np.int64)
    cluster = 0
    for seed in np.flatnonzero(is_core):
        if labels[seed] >= 0:
            continue
        labels[seed], frontier = cluster, [seed]
        while frontier:
            reached = np.flatnonzero(near[frontier.pop()] & is_core & (labels < 0))
            labels[reached] = cluster
            frontier.extend(reached.tolist())
        cluster += 1
    for p in np.flatnonzero(~is_core):
        touched = labels[near[p] & is_core]
        labels[p] = touched.min() if len(touched) else -1
    return labels, is_core


def _check_dbscan(impl, points, eps, min_samples, what):
    result = impl.dbscan(points, eps, min_samples)
    if not isinstance(result, tuple) or len(result) != 2:
        raise CheckFailed("dbscan must return a tuple (labels, is_core)")
    labels, is_core = result
    check_array(labels, "labels", shape=(len(points),), dtype="int64")
    check_array(is_core, "is_core", shape=(len(points),), dtype="bool")
    expected_labels, expected_core = _density_clusters(points, eps, min_samples)
    if not np.array_equal(is_core, expected_core):
        raise CheckFailed(f"is_core is wrong {what}", rule="core points are those with |N(p)| >= min_samples")
    if not np.array_equal(labels, expected_labels):
        raise CheckFailed(f"the labels are wrong {what}", rule="the labels break a rule of the contract")


@pytest.mark.grades("dbscan")
@pytest.mark.points(3)
def test_dbscan_hidden_random_clouds_with_duplicates(impl):
    rng = np.random.default_rng(301)
    for columns in (2, 3, 4):
        centres = rng.uniform(-10, 10, size=(5, columns))
        points = np.vstack([rng.normal(c, rng.uniform(0.3, 1.2), size=(120, columns)) for c in centres])
        points = np.vstack([points, points[rng.choice(len(points), 150)], rng.uniform(-14, 14, size=(40, columns))])
        points = points[rng.permutation(len(points))]
        for eps, min_samples in ((0.7, 6), (1.2, 12), (0.35, 2)):
            _check_dbscan(impl, points, eps, min_samples, "on a random cloud with duplicate points")


@pytest.mark.grades("dbscan")
@pytest.mark.points(2)
def test_dbscan_hidden_borders_between_clusters(impl):
    # Runs of points 0.25 apart along x, separated by gaps a lone point bridges: each bridge is a border
    # point of the runs on both sides (eps = 0.5: the bridge has 3 points within eps, min_samples 4).
    runs = [np.arange(5) * 0.25 + start for start in (0.0, 2.0, 4.0, 6.0)]
    bridges = [1.5, 3.5, 5.5]
    xs = np.concatenate([*runs, bridges])
    for seed in (302, 303, 304):
        order = np.random.default_rng(seed).permutation(len(xs))
        points = np.column_stack([xs[order], np.zeros(len(xs))])
        _check_dbscan(impl, points, 0.5, 4, "where border points touch two clusters")


@pytest.mark.grades("dbscan")
@pytest.mark.points(1)
def test_dbscan_hidden_extreme_parameters_and_scales(impl):
    rng = np.random.default_rng(305)
    points = rng.normal(size=(200, 3))
    _check_dbscan(impl, points, 0.5, 201, "when no point can be core")
    _check_dbscan(impl, points, 100.0, 5, "when eps covers the whole cloud")
    _check_dbscan(impl, points * 1e-6, 0.4e-6, 4, "at a micrometre scale")


@pytest.mark.grades("euclidean_clusters")
@pytest.mark.points(2)
def test_euclidean_clusters_hidden_random_clouds(impl):
    rng = np.random.default_rng(311)
    for columns in (2, 3):
        centres = rng.uniform(-8, 8, size=(6, columns))
        sizes = rng.integers(10, 120, size=len(centres))
        points = np.vstack([rng.normal(c, rng.uniform(0.2, 0.8), size=(n, columns)) for c, n in zip(centres, sizes)])
        points = np.vstack([points, points[rng.choice(len(points), 60)], rng.uniform(-10, 10, size=(30, columns))])
        points = points[rng.permutation(len(points))]
        for tolerance, min_size, max_size in ((0.5, 1, None), (0.8, 5, None), (0.6, 3, 100), (1.5, 10, 250)):
            labels = impl.euclidean_clusters(points, tolerance, min_size, max_size)
            check_array(labels, "labels", shape=(len(points),), dtype="int64")
            if not np.array_equal(labels, linked_components(points, tolerance, min_size, max_size)):
                raise CheckFailed(
                    "the labels are wrong on a random cloud with duplicate points",
                    rule="the labels break a rule of the contract",
                )


def _check_em(impl, points, start, max_iter, tol, reg_covar, what, rtol=1e-9):
    result = impl.gmm_em(points, *start, max_iter, tol, reg_covar)
    if not isinstance(result, tuple) or len(result) != 6:
        raise CheckFailed("gmm_em must return a tuple of six")
    expected = scikit_learn_em(points, *start, max_iter, tol, reg_covar)
    if result[5] != expected[5]:
        raise CheckFailed(f"n_iter is wrong {what}", rule="EM stops when the lower bound changes by less than tol")
    for name, got, want in zip(("weights", "means", "covariances", "responsibilities"), result, expected):
        check_close(got, want, name, rtol=rtol, atol=rtol, hint=what)
    check_close(result[4], expected[4], "lower_bounds", rtol=rtol, atol=rtol, hint=what)


@pytest.mark.grades("gmm_em")
@pytest.mark.points(3)
def test_gmm_em_hidden_new_mixtures_and_utm_like_coordinates(impl):
    rng = np.random.default_rng(321)
    for columns, k in ((2, 4), (3, 3), (4, 2)):
        parts = [rng.normal(size=(150, columns)) @ (rng.normal(size=(columns, columns)) * 0.5 + np.eye(columns))
                 + rng.uniform(-8, 8, columns) for _ in range(k)]  # fmt: skip
        points = np.vstack(parts)
        means = points[rng.choice(len(points), k, replace=False)]
        start = (rng.dirichlet(np.full(k, 3.0)), means, np.stack([np.eye(columns) * 4.0] * k))
        _check_em(impl, points, start, 150, 1e-6, 1e-6, f"on a new mixture of {k} in {columns} columns")
        # The same, shifted to UTM-like coordinates: a covariance computed as E[x x^T] - mu mu^T loses
        # every digit there; (x - mu)(x - mu)^T keeps them. scikit-learn's own x @ P - mu @ P loses
        # about 7 digits of the distances (1e-9 relative in the bounds, against (x - mu) @ P): 1e-7.
        offset = np.array([525_000.0, 4_200_000.0, 35.0, 10.0])[:columns]
        shifted = (start[0], start[1] + offset, start[2])
        _check_em(impl, points + offset, shifted, 150, 1e-6, 1e-6, "far from the origin", rtol=1e-7)


@pytest.mark.grades("knn_graph")
@pytest.mark.points(2)
def test_knn_graph_hidden_street_like_clouds_with_duplicates(impl):
    for seed, k, sigma, mutual in ((11, 6, None, False), (12, 9, 0.7, False), (13, 4, 1.5, True)):
        points = _street_like(seed)[::3]
        points = np.vstack([points, points[:30]])  # duplicates: neighbours at distance 0
        expected = neighbour_graph(points, k, sigma, mutual)
        result = impl.knn_graph(points, k, sigma, mutual)
        if not isinstance(result, tuple) or len(result) != 3:
            raise CheckFailed("knn_graph must return a tuple of three")
        indptr, indices, weights = result
        check_array(indptr, "indptr", shape=(len(points) + 1,), dtype="int64")
        if not (np.array_equal(indptr, expected[0]) and np.array_equal(indices, expected[1])):
            raise CheckFailed(
                f"the links are wrong on a new cloud (k = {k}, mutual = {mutual})", rule="the links are wrong"
            )
        check_close(weights, expected[2], "weights", rtol=1e-12, atol=0, hint="on a new cloud")


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(2)
def test_spectral_embedding_hidden_weighted_random_graphs(impl):
    from scipy.linalg import eigh
    from scipy.sparse import csr_array, random_array

    rng = np.random.default_rng(14)
    for n, density, m in ((120, 0.05, 3), (200, 0.02, 5)):
        upper = random_array((n, n), density=density, rng=rng, data_sampler=lambda size: rng.uniform(0.1, 2.0, size))
        dense = np.triu(upper.toarray(), 1)
        dense = dense + dense.T
        dense[np.arange(n - 1), np.arange(1, n)] = dense[np.arange(1, n), np.arange(n - 1)] = 0.5  # connected
        graph = csr_array(dense)
        graph.sort_indices()
        arrays = (graph.indptr.astype(np.int64), graph.indices.astype(np.int64), graph.data)
        for normalized in (True, False):
            values, vectors = eigh(laplacian(*arrays, normalized=normalized))
            result = impl.spectral_embedding(*arrays, m, normalized)
            if not isinstance(result, tuple) or len(result) != 2:
                raise CheckFailed("spectral_embedding must return a tuple of two")
            check_close(result[0], values[:m], "eigenvalues", rtol=0, atol=1e-10, hint="on a new weighted graph")
            check_array(result[1], "vectors", shape=(n, m))
            if projector_distance(result[1], vectors[:, :m]) > 1e-8:
                raise CheckFailed(
                    "the vectors span the wrong space on a new weighted graph",
                    rule="the eigenvectors span the wrong space",
                )


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(2)
def test_spectral_clustering_hidden_new_shapes(impl):
    from sklearn.datasets import make_blobs, make_moons

    moons, _ = make_moons(300, noise=0.05, random_state=15)
    blobs, _ = make_blobs(360, centers=6, n_features=3, cluster_std=0.6, random_state=16)
    for points, n_clusters, k, sigma in ((moons + [3.0e5, 4.0e6], 2, 9, None), (blobs, 6, 12, 2.0)):
        labels = impl.spectral_clustering(points, n_clusters, k, sigma)
        check_array(labels, "labels", shape=(len(points),), dtype="int64")
        if not np.array_equal(labels, njw_labels(points, n_clusters, k, sigma)):
            raise CheckFailed(f"labels are wrong on a new cloud of {n_clusters} clusters", rule="labels are wrong")
