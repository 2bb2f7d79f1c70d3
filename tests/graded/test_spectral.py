"""Graded tests of spectral clustering (``pcl_course/cluster.py``: ``knn_graph``, ``spectral_embedding``,
``spectral_clustering``).

Expected answers come from graphs and spectra worked out by hand (a line, the path and the cycle,
whose Laplacians' eigenpairs have closed forms, graphs of several components), from the tests'
brute-force kNN graph and SciPy's dense ``eigh`` (``grading/checks/cluster.py``, written from the
contract, not from the reference), and from the ground truth of well-separated toy sets.
"""

import numpy as np
import pytest
from sklearn.datasets import make_blobs, make_circles, make_moons
from sklearn.metrics import adjusted_rand_score

from grading.checks import CheckFailed, as_list, check_array, check_close, raises
from grading.checks.cluster import laplacian, neighbour_graph, njw_labels, projector_distance

WEIGHTS_RTOL = 1e-12  # exp(-s / (2 sigma^2)) and exp(-0.5 * s / sigma^2) differ by an ulp or two
EIGENVALUES_ATOL = 1e-10
PROJECTOR_ATOL = 1e-8


def _cloud(n=300, seed=0):
    """An anisotropic Gaussian cloud in 3-D (spreads 3, 1 and 0.5): distances rarely tie."""
    return np.random.default_rng(seed).normal(size=(n, 3)) * [3.0, 1.0, 0.5]


# --- knn_graph ------------------------------------------------------------------------------------


def _unpack_graph(result, n):
    if not isinstance(result, tuple) or len(result) != 3:
        raise CheckFailed(f"knn_graph must return a tuple (indptr, indices, weights), got {type(result).__name__}")
    indptr, indices, weights = result
    check_array(indptr, "indptr", shape=(n + 1,), dtype="int64")
    check_array(indices, "indices", shape=(None,), dtype="int64")
    check_array(weights, "weights", shape=(len(indices),))
    return indptr, indices, weights


def _first_difference(actual, expected):
    """The first row whose links differ: a sentence for the failure."""
    (a_ptr, a_idx, _), (e_ptr, e_idx, _) = actual, expected
    if a_ptr[-1] != len(a_idx):
        return f"indptr[N] = {a_ptr[-1]}, but indices holds {len(a_idx)} entries"
    for i in range(len(e_ptr) - 1):
        got = a_idx[a_ptr[i] : a_ptr[i + 1]]
        want = e_idx[e_ptr[i] : e_ptr[i + 1]]
        if not np.array_equal(got, want):
            return f"point {i} is linked to {got[:12].tolist()}, expected {want[:12].tolist()}"
    return "indptr is wrong"


def _check_graph(impl, points, k, sigma=None, mutual=False, what=""):
    expected = neighbour_graph(points, k, sigma, mutual)
    actual = _unpack_graph(impl.knn_graph(points, k, sigma, mutual), len(points))
    if not (np.array_equal(actual[0], expected[0]) and np.array_equal(actual[1], expected[1])):
        kind = "mutual neighbours" if mutual else "a neighbour of the other, either way"
        raise CheckFailed(
            f"the links are wrong{what}: {_first_difference(actual, expected)} (k = {k}; the neighbours of i are "
            f"the k points j != i smallest by (s, j); i and j are linked when one is {kind}; each row increasing)",
            rule="the links are wrong",
        )
    check_close(
        actual[2],
        expected[2],
        f"weights{what}",
        rtol=WEIGHTS_RTOL,
        atol=0,
        hint="the weight is exp(-s / (2 sigma^2)) with s the SQUARED distance, or 1.0 when sigma is None",
    )


@pytest.mark.grades("knn_graph")
@pytest.mark.points(1)
@pytest.mark.interface
def test_knn_graph_returns_csr_arrays(impl):
    points = _cloud(50, seed=1)
    indptr, indices, weights = _unpack_graph(impl.knn_graph(points, 4), 50)
    if indptr[0] != 0 or indptr[-1] != len(indices):
        raise CheckFailed("indptr must start at 0 and end at len(indices) (SciPy's CSR row pointers)")


@pytest.mark.grades("knn_graph")
@pytest.mark.points(2)
def test_knn_graph_on_a_line_worked_by_hand(impl):
    # x = 0, 1, 3, 7 with k = 1: the nearest of 0 is 1, of 1 is 0 (1 < 2), of 3 is 1 (2 < 4), of 7 is 3.
    # Links (either way): {0, 1}, {1, 2}, {2, 3}; mutual: {0, 1} only.
    line = np.array([[0.0], [1.0], [3.0], [7.0]])
    _check_graph(impl, line, 1, what=" (x = 0, 1, 3, 7, k = 1)")
    indptr, indices, weights = impl.knn_graph(line, 1)
    if as_list(indptr, 5) != [0, 1, 3, 5, 6] or as_list(indices, 6) != [1, 0, 2, 1, 3, 2]:
        raise CheckFailed(
            f"x = 0, 1, 3, 7, k = 1: expected indptr [0, 1, 3, 5, 6] and indices [1, 0, 2, 1, 3, 2], got "
            f"{as_list(indptr, 5)} and {as_list(indices, 6)}",
            rule="the links are wrong",
        )
    _check_graph(impl, line, 1, mutual=True, what=" (x = 0, 1, 3, 7, k = 1, mutual)")
    # sigma = 1: the weights are exp(-1/2), exp(-4/2) and exp(-16/2) for gaps 1, 2 and 4.
    _, _, weights = impl.knn_graph(line, 1, 1.0)
    check_close(weights, np.exp(-np.array([1, 1, 4, 4, 16, 16]) / 2.0), "weights (sigma = 1)", rtol=WEIGHTS_RTOL)
    # A tie: 1 and -1 are both 1 from 0: the lower index is the neighbour.
    _check_graph(impl, np.array([[0.0], [1.0], [-1.0]]), 1, what=" (x = 0, 1, -1: a tie, to the lower index)")


@pytest.mark.grades("knn_graph")
@pytest.mark.points(2)
def test_knn_graph_matches_brute_force(impl):
    points = _cloud(300, seed=2)
    for k in (1, 5, 12):
        for mutual in (False, True):
            _check_graph(impl, points, k, mutual=mutual, what=f" (k = {k}, mutual = {mutual})")
    _check_graph(impl, points, 8, sigma=0.8, what=" (sigma = 0.8)")
    _check_graph(impl, points, 299, what=" (k = N - 1: every pair)")


@pytest.mark.grades("knn_graph")
@pytest.mark.points(1)
def test_knn_graph_duplicates_and_ties(impl):
    grid = np.stack(np.meshgrid(np.arange(5.0), np.arange(5.0), np.arange(2.0)), -1).reshape(-1, 3)
    _check_graph(impl, grid, 4, what=" (a grid: equal distances, ties to the lower index)")
    _check_graph(impl, grid, 6, mutual=True, what=" (a grid, mutual)")
    doubled = np.vstack([grid[:20], grid[:20], grid[5:9]])  # every point twice or three times
    _check_graph(impl, doubled, 3, sigma=0.5, what=" (duplicates: a neighbour at distance 0, weight 1)")


@pytest.mark.grades("knn_graph")
@pytest.mark.points(1)
def test_knn_graph_every_column_and_far_from_the_origin(impl):
    points = _cloud(200, seed=3)
    wide = np.hstack([points, np.random.default_rng(3).normal(size=(200, 2)) * 4.0])
    _check_graph(impl, wide, 6, sigma=2.0, what=" (5 columns: every column is a coordinate)")
    _check_graph(impl, wide[:, :1], 3, what=" (one column)")
    far = points * 0.05 + [512_345.0, 4_201_789.0, 35.0]
    _check_graph(impl, far, 7, sigma=0.05, what=" far from the origin (sum (p_j - q_j) ** 2 over the columns)")


@pytest.mark.grades("knn_graph")
@pytest.mark.points(1)
@pytest.mark.interface
def test_knn_graph_converts_float32_and_rejects_bad_arguments(impl):
    points = _cloud(60, seed=4)
    single = points.astype(np.float32)
    actual = _unpack_graph(impl.knn_graph(single, 5, 1.0), 60)
    impl.knn_graph(np.ascontiguousarray(points, dtype=np.float64), 5)  # no conversion copies these
    expected = neighbour_graph(single.astype(np.float64), 5, 1.0)
    if not (np.array_equal(actual[0], expected[0]) and np.array_equal(actual[1], expected[1])):
        raise CheckFailed("float32 points must be converted to float64 first", rule="the links are wrong")
    nan = points.copy()
    nan[2, 1] = np.nan
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"points": nan}, "points"),
        ({"k": 0}, "k"),
        ({"k": 60}, "k"),
        ({"k": 2.0}, "k"),
        ({"k": True}, "k"),
        ({"sigma": 0.0}, "sigma"),
        ({"sigma": -1.0}, "sigma"),
        ({"sigma": np.inf}, "sigma"),
        ({"mutual": 1}, "mutual"),
        ({"mutual": "yes"}, "mutual"),
    ]
    for change, name in cases:
        arguments = {"points": points, "k": 3, "sigma": None, "mutual": False, **change}
        with raises(ValueError, naming=name):
            impl.knn_graph(**arguments)


# --- spectral_embedding ---------------------------------------------------------------------------


def _unpack_embedding(result, n, m):
    if not isinstance(result, tuple) or len(result) != 2:
        raise CheckFailed(f"spectral_embedding must return a tuple (eigenvalues, vectors), got {type(result).__name__}")
    eigenvalues, vectors = result
    check_array(eigenvalues, "eigenvalues", shape=(m,))
    check_array(vectors, "vectors", shape=(n, m))
    return eigenvalues, vectors


def _path(n, weight=1.0):
    """The path 0 - 1 - ... - n-1 in CSR form."""
    rows = [[j for j in (i - 1, i + 1) if 0 <= j < n] for i in range(n)]
    indptr = np.cumsum([0] + [len(r) for r in rows])
    return indptr, np.concatenate(rows).astype(np.int64), np.full(indptr[-1], weight)


def _cycle(n):
    rows = [sorted({(i - 1) % n, (i + 1) % n}) for i in range(n)]
    indptr = np.cumsum([0] + [len(r) for r in rows])
    return indptr, np.concatenate(rows).astype(np.int64), np.ones(indptr[-1])


def _check_embedding(impl, graph, m, normalized, expected_values=None, expected_vectors=None, what=""):
    """spectral_embedding against SciPy's dense eigh (or the given closed forms): the eigenvalues and
    the projector onto the span of the vectors (any orthonormal basis of it is right)."""
    from scipy.linalg import eigh

    n = len(graph[0]) - 1
    values, vectors = eigh(laplacian(*graph, normalized=normalized))
    expected_values = values[:m] if expected_values is None else expected_values
    expected_vectors = vectors[:, :m] if expected_vectors is None else expected_vectors
    matrix = "L_sym = I - D^-1/2 W D^-1/2" if normalized else "L = D - W"
    actual_values, actual_vectors = _unpack_embedding(impl.spectral_embedding(*graph, m, normalized), n, m)
    check_close(
        actual_values,
        expected_values,
        f"eigenvalues{what}",
        rtol=0,
        atol=EIGENVALUES_ATOL,
        hint=f"the {m} SMALLEST eigenvalues of {matrix}, increasing",
    )
    gram = actual_vectors.T @ actual_vectors
    if not np.allclose(gram, np.eye(m), atol=1e-8):
        raise CheckFailed(
            f"the vectors are not orthonormal{what}: V^T V differs from I by {np.abs(gram - np.eye(m)).max():.3g}",
            rule="the eigenvectors are not orthonormal",
        )
    distance = projector_distance(actual_vectors, expected_vectors)
    if distance > PROJECTOR_ATOL:
        raise CheckFailed(
            f"the vectors span the wrong space{what}: their projector V V^T differs from the eigenvectors' by "
            f"{distance:.3g} (the eigenvectors of the {m} smallest eigenvalues of {matrix}; signs and the basis "
            "of an eigenspace are free)",
            rule="the eigenvectors span the wrong space",
        )


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(1)
@pytest.mark.interface
def test_spectral_embedding_returns_eigenvalues_and_vectors(impl):
    _unpack_embedding(impl.spectral_embedding(*_path(8), 3), 8, 3)
    _unpack_embedding(impl.spectral_embedding(*_path(8), 1, False), 8, 1)


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(2)
def test_spectral_embedding_of_the_path_and_the_cycle_worked_by_hand(impl):
    # The path of n vertices: L has eigenvalues 2 - 2 cos(pi j / n), j = 0 .. n-1, and eigenvectors
    # cos(pi j (i + 1/2) / n) (a discrete cosine transform).
    n = 9
    j, i = np.arange(n), np.arange(n)[:, None]
    cosines = np.cos(np.pi * j * (i + 0.5) / n)
    cosines /= np.linalg.norm(cosines, axis=0)
    _check_embedding(impl, _path(n), 4, False, 2 - 2 * np.cos(np.pi * j[:4] / n), cosines[:, :4], " (path of 9, L)")
    # The cycle of n vertices is 2-regular, so L_sym = L / 2: eigenvalues 1 - cos(2 pi j / n), each
    # twice but 0 (and 2 for even n). Four of them: 0 and the pair at j = 1, then j = 2 (paired too,
    # with its partner the fifth): ask for 3 so that the span is unique.
    n = 10
    values = np.sort(1 - np.cos(2 * np.pi * np.arange(n) / n))[:3]
    _check_embedding(impl, _cycle(n), 3, True, values, what=" (cycle of 10, L_sym = L / 2)")
    # A weighted path: L scales with the weights, L_sym does not.
    _check_embedding(impl, _path(6, 2.5), 3, False, what=" (path of 6, every weight 2.5, L)")
    _check_embedding(impl, _path(6, 2.5), 3, True, what=" (path of 6, every weight 2.5, L_sym)")


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(2)
def test_spectral_embedding_matches_scipy_on_knn_graphs(impl):
    points = make_blobs(300, centers=4, cluster_std=0.9, random_state=5)[0]
    graph = neighbour_graph(points, 8, sigma=1.5)
    for normalized in (True, False):
        for m in (3, 4, 5):  # three components, then clear gaps
            _check_embedding(impl, graph, m, normalized, what=f" (blobs, k = 8, sigma = 1.5, {m} eigenpairs)")
    _check_embedding(impl, neighbour_graph(points, 6), 4, True, what=" (blobs, k = 6, weights 1)")


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(2)
def test_spectral_embedding_counts_the_components(impl):
    # Three separate groups: eigenvalue 0 three times; its eigenspace is spanned by the groups'
    # indicators (L), or by D^1/2 times them (L_sym).
    points = np.vstack([_cloud(40, seed=6) + offset for offset in ([0, 0, 0], [60, 0, 0], [0, 60, 0])])
    graph = neighbour_graph(points, 6, sigma=2.0)
    indicators = np.kron(np.eye(3), np.ones((40, 1)))
    degrees = laplacian(*graph, normalized=False).diagonal()
    for normalized, basis in ((False, indicators), (True, indicators * np.sqrt(degrees)[:, None])):
        basis = basis / np.linalg.norm(basis, axis=0)
        _check_embedding(impl, graph, 3, normalized, np.zeros(3), basis, " (three components)")


@pytest.mark.grades("spectral_embedding")
@pytest.mark.points(1)
@pytest.mark.interface
def test_spectral_embedding_rejects_bad_graphs(impl):
    indptr, indices, weights = _path(6)
    impl.spectral_embedding(indptr, indices, weights.astype(np.float32), 2)
    impl.spectral_embedding(indptr, indices, np.ascontiguousarray(weights, dtype=np.float64), 2)
    asymmetric = weights.copy()
    asymmetric[0] = 2.0
    unsorted = indices.copy()
    unsorted[[3, 4]] = unsorted[[4, 3]]  # row 2 holds 3, 1
    # Each of these graphs breaks one rule only (a symmetric graph otherwise).
    self_loop = (np.array([0, 1, 4, 5]), np.array([1, 0, 1, 2, 1]), np.ones(5))  # 1 linked to itself
    isolated = (np.array([0, 1, 2, 2]), np.array([1, 0]), np.ones(2))  # vertex 2 has no link
    cases = [
        ({"indptr": indptr[:-1]}, "indptr"),
        ({"indptr": indptr.astype(float)}, "indptr"),
        ({"indptr": indptr[::-1]}, "indptr"),
        ({"indices": indices[:-1]}, "indices"),
        ({"indices": np.where(indices == 5, 6, indices)}, "indices"),
        (dict(zip(("indptr", "indices", "weights"), self_loop)), "indices"),
        ({"indices": unsorted}, "indices"),
        ({"weights": weights[:-1]}, "weights"),
        ({"weights": -weights}, "weights"),
        ({"weights": np.where(np.arange(10) == 3, np.nan, weights)}, "weights"),
        ({"weights": asymmetric}, "weights"),
        ({"weights": np.zeros(10)}, "weights"),
        (dict(zip(("indptr", "indices", "weights"), isolated)), "weights"),
        ({"n_components": 0}, "n_components"),
        ({"n_components": 7}, "n_components"),
        ({"n_components": 2.0}, "n_components"),
        ({"normalized": 0}, "normalized"),
    ]
    for change, name in cases:
        arguments = {"indptr": indptr, "indices": indices, "weights": weights, "n_components": 2, **change}
        with raises(ValueError, naming=name):
            impl.spectral_embedding(**arguments)


# --- spectral_clustering --------------------------------------------------------------------------


def _check_clustering(impl, points, n_clusters, k=10, sigma=None, truth=None, what=""):
    expected = njw_labels(points, n_clusters, k, sigma)
    labels = impl.spectral_clustering(points, n_clusters, k, sigma)
    check_array(labels, "labels", shape=(len(points),), dtype="int64")
    if not np.array_equal(labels, expected):
        first = int(np.argmax(labels != expected))
        same_partition = adjusted_rand_score(expected, labels) == 1.0
        raise CheckFailed(
            f"labels are wrong{what}: point {first} has label {labels[first]}, expected {expected[first]}"
            + (
                " (the same clusters, numbered otherwise: renumber them by first appearance, point 0's cluster 0)"
                if same_partition
                else " (another partition)"
            ),
            rule="labels are numbered by first appearance" if same_partition else "labels are wrong",
        )
    if truth is not None and adjusted_rand_score(truth, labels) < 0.99:
        raise CheckFailed(f"the clusters{what} are not the true ones", rule="labels are wrong")


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(1)
@pytest.mark.interface
def test_spectral_clustering_returns_int64_labels(impl):
    points = make_blobs(120, centers=3, random_state=7)[0]
    check_array(impl.spectral_clustering(points, 3), "labels", shape=(120,), dtype="int64")
    one = make_blobs(120, centers=1, random_state=7)[0]  # a connected kNN graph
    labels = impl.spectral_clustering(one, 1, 5)
    if not np.array_equal(labels, np.zeros(120, dtype=np.int64)):
        raise CheckFailed("with n_clusters = 1 every point is in cluster 0", rule="labels are wrong")


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(2)
def test_spectral_clustering_separates_two_moons(impl):
    points, truth = make_moons(400, noise=0.06, random_state=8)
    _check_clustering(impl, points, 2, truth=truth, what=" (two moons, k = 10)")
    _check_clustering(impl, points, 2, 7, 0.2, truth=truth, what=" (two moons, k = 7, sigma = 0.2)")


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(2)
def test_spectral_clustering_separates_two_circles(impl):
    points, truth = make_circles(400, factor=0.45, noise=0.04, random_state=9)
    _check_clustering(impl, points, 2, truth=truth, what=" (two circles)")
    three = np.vstack([points, 2.2 * points[truth == 0][:150]])  # a third ring around them
    truth3 = np.concatenate([truth, np.full(150, 2)])
    _check_clustering(impl, three, 3, 8, truth=truth3, what=" (three circles, k = 8)")


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(1)
def test_spectral_clustering_of_blobs_in_three_and_five_columns(impl):
    points, truth = make_blobs(500, n_features=3, centers=5, cluster_std=0.7, random_state=10)
    _check_clustering(impl, points, 5, 10, 1.0, truth=truth, what=" (five blobs in 3-D, sigma = 1)")
    points, truth = make_blobs(300, n_features=5, centers=3, cluster_std=0.5, random_state=11)
    _check_clustering(impl, points, 3, truth=truth, what=" (three blobs in 5 columns)")


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(1)
def test_spectral_clustering_numbers_by_first_appearance_and_starts_farthest_first(impl):
    # Shuffled blobs: the clusters appear in no particular order, and four are close enough that a
    # start at the first rows would merge two of them.
    points, _ = make_blobs(400, centers=[[0, 0], [3, 0], [0, 3], [3, 3], [10, 10]], cluster_std=0.5, random_state=12)
    _check_clustering(impl, points, 5, 8, what=" (five shuffled blobs)")
    _check_clustering(impl, points[::-1].copy(), 5, 8, what=" (the same, points reversed)")
    far = points + [4.2e6, 5.1e5]
    _check_clustering(impl, far, 5, 8, what=" (far from the origin)")


def _unequal_blobs(seed):
    """Blobs of unequal sizes and spreads that touch: a connected kNN graph, where the rows' lengths
    (NJW's normalisation) and the Laplacian (L_sym, not L) change a few labels at the borders. The
    labels are canonical still: the same under 20 random rotations of the eigenvectors' basis."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(2, 5))
    sizes, spreads = rng.integers(30, 200, m), rng.uniform(0.2, 1.5, m)
    points, _ = make_blobs(sizes, centers=rng.uniform(-6, 6, (m, 2)), cluster_std=spreads, random_state=seed)
    return points, m, int(rng.integers(5, 12))


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(2)
def test_spectral_clustering_of_touching_blobs_of_unequal_spread(impl):
    for seed in (14, 45):
        points, n_clusters, k = _unequal_blobs(seed)
        _check_clustering(
            impl, points, n_clusters, k, what=f" ({n_clusters} touching blobs of unequal spread, k = {k})"
        )


@pytest.mark.grades("spectral_clustering")
@pytest.mark.points(1)
@pytest.mark.interface
def test_spectral_clustering_rejects_bad_arguments(impl):
    points = make_blobs(60, centers=2, random_state=13)[0]
    three_groups = np.vstack([points[:20], points[:20] + 100.0, points[:20] - 100.0])
    impl.spectral_clustering(points.astype(np.float32), 2, 5)
    impl.spectral_clustering(np.ascontiguousarray(points, dtype=np.float64), 2)  # no conversion copies these
    cases = [
        ({"points": points[:, 0]}, "points"),
        ({"n_clusters": 0}, "n_clusters"),
        ({"n_clusters": 61}, "n_clusters"),
        ({"n_clusters": 2.0}, "n_clusters"),
        ({"k": 0}, "k"),
        ({"k": 60}, "k"),
        ({"sigma": 0.0}, "sigma"),
        ({"sigma": 1e-3}, "sigma"),  # every weight exp(-s / 2e-6) underflows to 0.0
        ({"points": three_groups, "n_clusters": 2}, "n_clusters"),  # three components
    ]
    for change, name in cases:
        arguments = {"points": points, "n_clusters": 2, "k": 5, "sigma": None, **change}
        with raises(ValueError, naming=name):
            impl.spectral_clustering(**arguments)
