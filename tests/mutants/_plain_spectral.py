"""Plain spectral clustering for the lecture-3 mutants of ``knn_graph``, ``spectral_embedding`` and
``spectral_clustering``: each mutant is this code with one keyword flag (a student's loop over the
points, NumPy's ``eigh``, a k-means of their own), written apart from the grader's catalogue
(``grading/instructors/mistakes/_spectral.py``): a mutant and its diagnosis are two independent
codings of one mistake. Trusted code: only the project's tests import it.
"""

import numpy as np
import scipy.linalg
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components

from pcl_course.validation import as_points, check_bool, check_graph, check_integer, check_positive

__all__ = ["knn_graph", "spectral_embedding", "spectral_clustering"]


def _squared(x):
    s = np.zeros((len(x), len(x)))
    for j in range(x.shape[1]):
        s += (x[:, None, j] - x[None, :, j]) ** 2
    return s


def knn_graph(points, k, sigma=None, mutual=False, *, itself=False, directed=False, weight="s", mutual_rule=True):
    """The contract's graph, or with ``itself`` (a point its own first neighbour), ``directed`` (no
    symmetrisation), ``weight`` ("sigma": s / (2 sigma); "distance": sqrt(s) / (2 sigma^2)) or
    ``mutual_rule`` False (the union always)."""
    x = as_points(points, min_columns=1, allow_empty=False)
    n = len(x)
    if n < 2:
        raise ValueError("points must hold at least 2 points")
    k = check_integer(k, "k", low=1, high=n - 1)
    if sigma is not None:
        sigma = check_positive(sigma, "sigma")
    mutual = check_bool(mutual, "mutual")
    s = _squared(x)
    linked = np.zeros((n, n), dtype=bool)
    for i in range(n):
        order = np.argsort(s[i], kind="stable")
        if not itself:
            order = order[order != i]
        linked[i, order[:k]] = True
    np.fill_diagonal(linked, False)
    if not directed:
        linked = linked & linked.T if mutual and mutual_rule else linked | linked.T
    rows, columns = np.nonzero(linked)
    indptr = np.searchsorted(rows, np.arange(n + 1))
    if sigma is None:
        weights = np.ones(len(rows))
    elif weight == "sigma":
        weights = np.exp(-s[rows, columns] / (2 * sigma))
    elif weight == "distance":
        weights = np.exp(-np.sqrt(s[rows, columns]) / (2 * sigma**2))
    else:
        weights = np.exp(-s[rows, columns] / (2 * sigma**2))
    return indptr.astype(np.int64), columns.astype(np.int64), weights


def spectral_embedding(indptr, indices, weights, n_components, normalized=True, *, matrix="laplacian", end="first"):
    """The contract's eigenpairs, or of ``matrix`` "plain" (always D - W), "similarity" (the largest of
    D^-1/2 W D^-1/2), "random_walk" (eigh(L, D)); or the last columns of eigh (``end="last"``)."""
    indptr, indices, weights, degrees = check_graph(indptr, indices, weights)
    n = len(degrees)
    n_components = check_integer(n_components, "n_components", low=1, high=n)
    normalized = check_bool(normalized, "normalized")
    w = np.zeros((n, n))
    w[np.repeat(np.arange(n), np.diff(indptr)), indices] = weights
    plain = np.diag(degrees) - w
    scaled = w / np.sqrt(np.outer(degrees, degrees))
    if normalized and matrix == "similarity":
        values, vectors = np.linalg.eigh(scaled)
        return values[::-1][:n_components].copy(), vectors[:, ::-1][:, :n_components].copy()
    if normalized and matrix == "random_walk":
        values, vectors = scipy.linalg.eigh(plain, np.diag(degrees))
        return values[:n_components], vectors[:, :n_components]
    laplacian = np.eye(n) - scaled if normalized and matrix == "laplacian" else plain
    values, vectors = np.linalg.eigh(laplacian)
    if end == "last":
        return values[-n_components:].copy(), vectors[:, -n_components:].copy()
    return values[:n_components].copy(), vectors[:, :n_components].copy()


def _kmeans(y, centres):
    labels = None
    for _ in range(300):
        new = np.argmin(((y[:, None, :] - centres[None]) ** 2).sum(axis=2), axis=1)
        if labels is not None and np.array_equal(new, labels):
            break
        labels = new
        for c in range(len(centres)):
            if np.any(labels == c):
                centres[c] = y[labels == c].mean(axis=0)
    return labels


def spectral_clustering(
    points, n_clusters, k=10, sigma=None, *, unit_rows=True, start="farthest", renumber=True, normalized=True
):
    """The contract's labels, or without ``unit_rows``, from the first rows (``start="first"``), without
    ``renumber``, or from L (``normalized`` False)."""
    x = as_points(points, min_columns=1, allow_empty=False)
    n_clusters = check_integer(n_clusters, "n_clusters", low=1, high=max(len(x), 1))
    indptr, indices, weights = knn_graph(x, k, sigma)
    if np.any(np.bincount(np.repeat(np.arange(len(x)), np.diff(indptr)), weights, len(x)) == 0):
        raise ValueError("sigma is too small: a point's links all weigh 0")
    w = csr_array((weights, indices, indptr), shape=(len(x), len(x)))
    w.eliminate_zeros()
    if connected_components(w)[0] > n_clusters:
        raise ValueError("n_clusters is below the number of connected components")
    _, u = spectral_embedding(indptr, indices, weights, n_clusters, normalized)
    y = u / np.linalg.norm(u, axis=1, keepdims=True) if unit_rows else u
    if start == "first":
        chosen = list(range(n_clusters))
    else:
        chosen = [0]
        while len(chosen) < n_clusters:
            d = np.min(((y[:, None, :] - y[chosen][None]) ** 2).sum(axis=2), axis=1)
            chosen.append(int(np.argmax(d)))
    labels = _kmeans(y, y[chosen].copy())
    if not renumber:
        return labels.astype(np.int64)
    mapping = {}
    for label in labels:
        mapping.setdefault(int(label), len(mapping))
    return np.array([mapping[int(label)] for label in labels], dtype=np.int64)
