"""NJW with the eigenvectors turned by a random rotation (another eigensolver's basis: the contract's
labels do not depend on it), a vectorised farthest-first start and a Lloyd loop of bincount sums; the
graph and Laplacian by scipy.sparse.csgraph, the eigenvectors by NumPy."""

import numpy as np
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components, laplacian
from scipy.stats import ortho_group

from pcl_course.validation import as_points, check_integer
from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import knn_graph as _knn_graph


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    x = as_points(points, min_columns=1, allow_empty=False)
    m = check_integer(n_clusters, "n_clusters", low=1, high=max(len(x), 1))
    indptr, indices, weights = _knn_graph(x, k, sigma)
    n = len(x)
    w = csr_array((weights, indices, indptr), shape=(n, n))
    if np.any(w.sum(axis=1) == 0):
        raise ValueError(f"sigma = {sigma} makes every link of a point weigh 0")
    w.eliminate_zeros()
    if connected_components(w)[0] > m:
        raise ValueError(f"n_clusters = {m} is below the number of connected components of the graph")
    lsym = laplacian(w, normed=True).toarray()
    u = np.linalg.eigh(lsym)[1][:, :m]
    if m > 1:
        u = u @ ortho_group.rvs(m, random_state=12345)
    y = u / np.linalg.norm(u, axis=1)[:, None]
    picked = [0]
    far = np.sum((y - y[0]) ** 2, axis=1)
    while len(picked) < m:
        picked.append(int(np.argmax(far)))
        far = np.minimum(far, np.sum((y - y[picked[-1]]) ** 2, axis=1))
    centres = y[picked].copy()
    labels = None
    for _ in range(300):
        d = np.zeros((n, m))
        for c in range(m):
            d += (y[:, c, None] - centres[None, :, c]) ** 2
        new = np.argmin(d, axis=1)
        if labels is not None and np.array_equal(new, labels):
            break
        labels = new
        counts = np.bincount(labels, minlength=m)
        for c in range(m):
            sums = np.bincount(labels, weights=y[:, c], minlength=m)
            centres[counts > 0, c] = sums[counts > 0] / counts[counts > 0]
    order = {}
    for label in labels:
        order.setdefault(int(label), len(order))
    return np.array([order[int(label)] for label in labels], dtype=np.int64)
