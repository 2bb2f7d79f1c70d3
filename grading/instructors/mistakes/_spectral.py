"""Known mistakes of ``pcl_course/cluster.py``'s spectral functions: the kNN graph, the Laplacian's
eigenpairs and Ng, Jordan and Weiss's clustering: part of :mod:`grading.instructors.mistakes.cluster`,
which lists them in its ``MODELS``.

The truths are the contract's rules by brute force (the dense squared distances, the neighbours by
``(s, j)``, SciPy's dense ``eigh``), written apart from ``solutions/``; each mistake is the same code
with one keyword flag. Graphs and labels are compared exactly, weights to a relative 1e-12, and an
embedding by its eigenvalues and the product ``V V^T`` (a basis of an eigenspace is free).
"""

import numpy as np

from grading.instructors.mistakes import (
    Mistake,
    Model,
    Variants,
    same_integers,
    valid_integer,
    valid_points,
    valid_positive,
)

MAX_GRAPH_POINTS = 4_000  # the truth's dense N x N distances
MAX_EIGEN_POINTS = 2_000  # the truth's dense eigh
RTOL = 1e-12


def _squared(data):
    return sum((data[:, j, None] - data[None, :, j]) ** 2 for j in range(data.shape[1]))


# -- knn_graph -------------------------------------------------------------------------------------


def graph(points, k, sigma=None, mutual=False, itself=False, directed=False, weight="gaussian", mutual_rule=True):
    """The contract's kNN graph, or a mistake's: ``itself`` (the point its own first neighbour, so k - 1
    others), ``directed`` (row i only i's neighbours), ``weight`` ("sigma" for s / (2 sigma), "root" for
    the distance in place of s), ``mutual_rule`` False (the union whatever ``mutual``)."""
    data = valid_points(points, min_rows=2)
    n = len(data)
    if n > MAX_GRAPH_POINTS:
        raise ValueError("too large to replay")
    k = valid_integer(k, 1)
    if k > n - 1 or not isinstance(mutual, bool | np.bool_):
        raise ValueError("outside the contract")
    sigma = None if sigma is None else valid_positive(sigma)
    s = _squared(data)
    links = np.zeros((n, n), dtype=bool)
    for i in range(n):
        others = np.arange(n) if itself else np.delete(np.arange(n), i)
        links[i, others[np.lexsort((others, s[i, others]))[:k]]] = True
    links[np.arange(n), np.arange(n)] = False
    if not directed:
        links = links & links.T if (mutual and mutual_rule) else links | links.T
    rows, columns = np.nonzero(links)
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    if sigma is None:
        weights = np.ones(len(rows))
    elif weight == "sigma":
        weights = np.exp(-s[rows, columns] / (2 * sigma))
    elif weight == "root":
        weights = np.exp(-np.sqrt(s[rows, columns]) / (2 * sigma**2))
    else:
        weights = np.exp(-s[rows, columns] / (2 * sigma**2))
    return indptr, columns.astype(np.int64), weights


def _graph(**flags):
    return lambda points, k, sigma=None, mutual=False: graph(points, k, sigma, mutual, **flags)


def graph_same(a, b, arguments):
    """The CSR arrays exactly, the weights to a relative 1e-12."""
    try:
        if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 3):
            return False
        a = [np.asarray(x) for x in a]
        b = [np.asarray(x) for x in b]
        if any(x.shape != y.shape for x, y in zip(a, b)):
            return False
        return (
            np.array_equal(a[0], b[0])
            and np.array_equal(a[1], b[1])
            and np.allclose(a[2].astype(float), b[2].astype(float), rtol=RTOL, atol=0)
        )
    except (TypeError, ValueError):
        return False


KNN_GRAPH = Model(
    truth=graph,
    same=graph_same,
    output_dtypes=("int64", "int64", "float64"),
    mistakes=(
        Mistake(
            "includes_itself",
            "a point is not its own neighbour: take the k nearest points j != i (a k-d tree's query of k "
            "returns the point itself first: ask for k + 1 and drop it, not a duplicate of it)",
            _graph(itself=True),
        ),
        Mistake(
            "not_symmetric",
            "link i and j when j is a neighbour of i OR i of j, and store every link in both rows: the graph "
            "is undirected (W symmetric)",
            _graph(directed=True),
        ),
        Mistake(
            "mutual_ignored",
            "with mutual=True, link i and j only when each is among the other's k neighbours (the "
            "intersection of the two directions, not their union)",
            _graph(mutual_rule=False),
        ),
        Mistake(
            "sigma_not_squared",
            "the weight is exp(-s / (2 sigma ** 2)): divide by twice sigma SQUARED",
            _graph(weight="sigma"),
        ),
        Mistake(
            "distance_not_squared",
            "the weight is exp(-s / (2 sigma ** 2)) with s the SQUARED distance, not the distance",
            _graph(weight="root"),
        ),
    ),
)


# -- spectral_embedding ----------------------------------------------------------------------------


def _valid_graph(indptr, indices, weights):
    """The dense W of a CSR graph the contract accepts, else ValueError."""
    indptr, indices = np.asarray(indptr), np.asarray(indices)
    weights = np.asarray(weights, dtype=float)
    if indptr.ndim != 1 or indptr.dtype.kind not in "iu" or indices.dtype.kind not in "iu" or len(indptr) < 2:
        raise ValueError("outside the contract")
    n = len(indptr) - 1
    if n > MAX_EIGEN_POINTS or indptr[0] != 0 or np.any(np.diff(indptr) < 0) or indptr[-1] != len(indices):
        raise ValueError("outside the contract")
    if weights.shape != indices.shape or np.any(indices < 0) or np.any(indices >= n):
        raise ValueError("outside the contract")
    if not np.isfinite(weights).all() or np.any(weights < 0):
        raise ValueError("outside the contract")
    rows = np.repeat(np.arange(n), np.diff(indptr))
    if np.any(indices == rows) or np.any((np.diff(indices) <= 0) & (rows[1:] == rows[:-1])):
        raise ValueError("outside the contract")
    w = np.zeros((n, n))
    w[rows, indices] = weights
    if not np.array_equal(w, w.T) or np.any(w.sum(axis=1) <= 0):
        raise ValueError("outside the contract")
    return w


def embedding(indptr, indices, weights, n_components, normalized=True, matrix="laplacian", end="smallest"):
    """The contract's eigenpairs, or a mistake's: ``matrix`` "plain" (L whatever ``normalized``),
    "similarity" (D^-1/2 W D^-1/2, its largest), "random_walk" (L_rw's D-orthonormal vectors);
    ``end`` "largest" (the largest eigenpairs, increasing) or "largest_descending"."""
    from scipy.linalg import eigh

    w = _valid_graph(indptr, indices, weights)
    n = len(w)
    m = valid_integer(n_components, 1)
    if m > n or not isinstance(normalized, bool | np.bool_):
        raise ValueError("outside the contract")
    d = w.sum(axis=1)
    plain = np.diag(d) - w
    if matrix == "similarity" and normalized:
        values, vectors = eigh(w / np.sqrt(np.outer(d, d)))
        return values[::-1][:m], vectors[:, ::-1][:, :m]
    if matrix == "random_walk" and normalized:
        values, vectors = eigh(plain, np.diag(d))  # L v = lambda D v: v^T D v = 1
        return values[:m], vectors[:, :m]
    laplacian = plain if (matrix == "plain" or not normalized) else np.eye(n) - w / np.sqrt(np.outer(d, d))
    values, vectors = eigh(laplacian)
    if end == "largest":
        return values[-m:], vectors[:, -m:]
    if end == "largest_descending":
        return values[::-1][:m], vectors[:, ::-1][:, :m]
    return values[:m], vectors[:, :m]


def _embedding(**flags):
    return lambda indptr, indices, weights, n_components, normalized=True: embedding(
        indptr, indices, weights, n_components, normalized, **flags
    )


def embedding_same(a, b, arguments):
    """The eigenvalues to 1e-10 and ``V V^T`` to 1e-8: the same spaces, whatever their bases."""
    try:
        if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 2):
            return False
        (a_values, a_vectors), (b_values, b_vectors) = [tuple(np.asarray(x, dtype=float) for x in y) for y in (a, b)]
        if a_values.shape != b_values.shape or a_vectors.shape != b_vectors.shape or a_vectors.ndim != 2:
            return False
        if not np.allclose(a_values, b_values, rtol=0, atol=1e-10):
            return False
        return bool(np.abs(a_vectors @ a_vectors.T - b_vectors @ b_vectors.T).max(initial=0) <= 1e-8)
    except (TypeError, ValueError):
        return False


SPECTRAL_EMBEDDING = Model(
    truth=embedding,
    same=embedding_same,
    output_dtypes=("float64", "float64"),
    mistakes=(
        Mistake(
            "largest_eigenpairs",
            "take the n_components SMALLEST eigenvalues of the Laplacian and their vectors (eigh returns them "
            "in increasing order: the first columns)",
            lambda indptr, indices, weights, n_components, normalized=True: Variants(
                [
                    embedding(indptr, indices, weights, n_components, normalized, end=end)
                    for end in ("largest", "largest_descending")
                ]  # fmt: skip
            ),
        ),
        Mistake(
            "normalized_ignored",
            "with normalized=True the matrix is L_sym = I - D^-1/2 W D^-1/2, not L = D - W",
            _embedding(matrix="plain"),
        ),
        Mistake(
            "similarity_not_laplacian",
            "return the eigenpairs of the Laplacian L_sym = I - D^-1/2 W D^-1/2: the largest of D^-1/2 W "
            "D^-1/2 have the same vectors but eigenvalues 1 - lambda",
            _embedding(matrix="similarity"),
        ),
        Mistake(
            "random_walk_vectors",
            "the vectors are L_sym's, orthonormal: eigh(L, D) solves L v = lambda D v (L_rw's vectors, "
            "D^-1/2 times L_sym's, orthonormal for D only)",
            _embedding(matrix="random_walk"),
        ),
    ),
)


# -- spectral_clustering ---------------------------------------------------------------------------


def _lloyd(rows, centres):
    """The contract's k-means (labels only): nearest centre by s, ties lowest, stop on unchanged labels."""
    previous = None
    for _ in range(300):
        s = sum((rows[:, j, None] - centres[None, :, j]) ** 2 for j in range(rows.shape[1]))
        labels = np.argmin(s, axis=1)
        if previous is not None and np.array_equal(labels, previous):
            return labels
        for c in range(len(centres)):
            if np.any(labels == c):
                centres[c] = rows[labels == c].mean(axis=0)
        previous = labels
    s = sum((rows[:, j, None] - centres[None, :, j]) ** 2 for j in range(rows.shape[1]))
    return np.argmin(s, axis=1)


def _components_at_most(indptr, indices, weights, count):
    """ValueError where the contract's does: a point whose links all weigh 0, or more connected
    components of the positive links than ``count``."""
    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import connected_components

    n = len(indptr) - 1
    w = csr_array((weights, indices, indptr), shape=(n, n))
    w.eliminate_zeros()
    if np.any(np.diff(w.indptr) == 0) or connected_components(w)[0] > count:
        raise ValueError("outside the contract")


def clustering(points, n_clusters, k=10, sigma=None, unit_rows=True, start="farthest", renumber=True, **embed):
    """The contract's NJW labels, or a mistake's: ``unit_rows`` False (k-means on U), ``start`` "first"
    (the first rows as centres: not in the catalogue, as where two first rows share a cluster, rounding
    splits it), ``renumber`` False (k-means' own numbers), ``normalized`` False (L)."""
    data = valid_points(points, min_rows=2)
    m = valid_integer(n_clusters, 1)
    if m > len(data) or len(data) > MAX_EIGEN_POINTS:
        raise ValueError("outside the contract")
    links = graph(data, k, sigma)
    _components_at_most(*links, m)
    vectors = embedding(*links, m, embed.get("normalized", True))[1]
    rows = vectors / np.linalg.norm(vectors, axis=1, keepdims=True) if unit_rows else vectors
    if start == "first":
        picked = list(range(m))
    else:
        picked, nearest = [0], ((rows - rows[0]) ** 2).sum(axis=1)
        for _ in range(m - 1):
            picked.append(int(np.argmax(nearest)))
            nearest = np.minimum(nearest, ((rows - rows[picked[-1]]) ** 2).sum(axis=1))
    labels = _lloyd(rows, rows[picked].copy())
    if not renumber:
        return labels.astype(np.int64)
    _, first = np.unique(labels, return_index=True)
    renumbered = np.full(m, -1, dtype=np.int64)
    renumbered[labels[np.sort(first)]] = np.arange(len(first))
    return renumbered[labels]


def _clustering(**flags):
    return lambda points, n_clusters, k=10, sigma=None: clustering(points, n_clusters, k, sigma, **flags)


def _labels_same(a, b, arguments):
    return same_integers(a, b)


def _first_appearance(labels):
    _, first = np.unique(labels, return_index=True)
    return bool(np.array_equal(labels[np.sort(first)], np.arange(len(first))))


def _renumbered_alike(a, b, arguments):
    """The same partition, both numbered otherwise than by first appearance (k-means' numbers follow
    the farthest-first picks, whose order between clusters equally far apart rounding decides), or
    the same labels."""
    if not _labels_same(a, a, arguments) or not _labels_same(b, b, arguments) or np.shape(a) != np.shape(b):
        return False
    a, b = np.asarray(a), np.asarray(b)
    if np.array_equal(a, b):
        return True
    pairs = np.unique(np.stack([a, b]), axis=1)
    one_to_one = len(np.unique(pairs[0])) == len(np.unique(pairs[1])) == pairs.shape[1]
    return one_to_one and not _first_appearance(a) and not _first_appearance(b)


SPECTRAL_CLUSTERING = Model(
    truth=clustering,
    same=_labels_same,
    output_dtypes=("int64",),
    mistakes=(
        Mistake(
            "rows_not_normalised",
            "divide each row of U by its length before k-means (Ng, Jordan and Weiss's step: the rows then "
            "lie on the unit sphere)",
            _clustering(unit_rows=False),
        ),
        Mistake(
            "not_renumbered",
            "renumber the clusters by first appearance: point 0's cluster is 0, the cluster of the first "
            "point not in it 1, and so on (k-means numbers them by their starting rows)",
            _clustering(renumber=False),
            same=_renumbered_alike,
        ),
        Mistake(
            "unnormalised_laplacian",
            "Ng, Jordan and Weiss embed with the normalised Laplacian L_sym (spectral_embedding's "
            "normalized=True), not L = D - W",
            _clustering(normalized=False),
        ),
    ),
)

__all__ = ["KNN_GRAPH", "SPECTRAL_EMBEDDING", "SPECTRAL_CLUSTERING", "graph", "embedding", "clustering"]
