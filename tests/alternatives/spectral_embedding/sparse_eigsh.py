"""The smallest eigenpairs by ARPACK in shift-invert mode (scipy.sparse.linalg.eigsh around a small
negative shift, a tight tolerance), on a sparse Laplacian built by scipy.sparse.csgraph; NumPy's dense
eigh where ARPACK cannot (a handful of vertices, or nearly all the eigenpairs)."""

import numpy as np
from scipy.sparse import csr_array
from scipy.sparse.csgraph import laplacian
from scipy.sparse.linalg import eigsh

from pcl_course.validation import check_bool, check_graph, check_integer
from solutions.cluster import *  # noqa: F401,F403


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    indptr, indices, weights, degrees = check_graph(indptr, indices, weights)
    n = len(degrees)
    m = check_integer(n_components, "n_components", low=1, high=n)
    normalized = check_bool(normalized, "normalized")
    matrix = laplacian(csr_array((weights, indices, indptr), shape=(n, n)), normed=normalized).tocsc()
    if n <= 60 or m >= n - 2:
        values, vectors = np.linalg.eigh(matrix.toarray())
        return values[:m].copy(), vectors[:, :m].copy()
    start = np.random.default_rng(0).uniform(0.5, 1.5, n)
    values, vectors = eigsh(matrix, k=m, sigma=-1e-2, which="LM", tol=1e-14, v0=start)
    order = np.argsort(values)
    vectors = vectors[:, order]
    # ARPACK's vectors are orthonormal to its tolerance: a QR makes them so to rounding.
    q, r = np.linalg.qr(vectors)
    return values[order], q * np.sign(np.diag(r))
