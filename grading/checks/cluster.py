"""The contract's answers of lecture 3's functions, for its graded and hidden tests.

Each is written from the contract's rules (or is scikit-learn where its
rules are the contract's), apart from ``solutions/``: the graded tests
compare a submission with them and say where it differs; the hidden tests
compare on other data and withhold the values.
"""

import warnings

import numpy as np

__all__ = [
    "nearest_centres",
    "lloyd",
    "linked_components",
    "scikit_learn_em",
    "neighbour_graph",
    "laplacian",
    "projector_distance",
    "njw_labels",
]


def nearest_centres(points, centers):
    """Each point's nearest centre by the contract's squared distance (summed over every column),
    ties to the lowest index: ``(labels, s)``, s of shape (N, K)."""
    s = sum((points[:, j, None] - centers[None, :, j]) ** 2 for j in range(points.shape[1]))
    return np.argmin(s, axis=1), s


def lloyd(points, centers, max_iter=300):
    """The contract's Lloyd iterations from ``centers``: ``(labels, centers, inertia, n_iter)``,
    inertia the list recorded at each assignment."""
    centers = np.array(centers, dtype=float)
    previous, inertia = None, []
    for t in range(1, max_iter + 1):
        labels, s = nearest_centres(points, centers)
        inertia.append(float(s[np.arange(len(points)), labels].sum()))
        if previous is not None and np.array_equal(labels, previous):
            return labels, centers, inertia, t
        for c in range(len(centers)):
            if np.any(labels == c):
                centers[c] = points[labels == c].mean(axis=0)
        previous = labels
    return nearest_centres(points, centers)[0], centers, inertia, max_iter


def linked_components(points, tolerance, min_size=1, max_size=None):
    """The contract's Euclidean clusters: SciPy's connected components of the links s <= tolerance^2,
    components outside the sizes dropped (-1), the rest numbered by decreasing size, then smallest index."""
    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import connected_components

    points = np.asarray(points, dtype=float)
    s = sum((points[:, j, None] - points[None, :, j]) ** 2 for j in range(points.shape[1]))
    _, component = connected_components(csr_array(s <= tolerance * tolerance), directed=False)
    labels = np.full(len(points), -1, dtype=np.int64)
    members = [np.flatnonzero(component == c) for c in range(component.max(initial=-1) + 1)]
    kept = [m for m in members if min_size <= len(m) <= (len(points) if max_size is None else max_size)]
    for label, m in enumerate(sorted(kept, key=lambda m: (-len(m), m[0]))):
        labels[m] = label
    return labels


def scikit_learn_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    """scikit-learn's GaussianMixture from the same parameters (its rules are the contract's):
    ``(weights, means, covariances, responsibilities, lower_bounds, n_iter)``."""
    from sklearn.mixture import GaussianMixture

    fitted = GaussianMixture(
        len(weights),
        covariance_type="full",
        tol=tol,
        reg_covar=reg_covar,
        max_iter=max_iter,
        weights_init=weights,
        means_init=means,
        precisions_init=np.linalg.inv(covariances),
        init_params="random_from_data",
        random_state=0,
    )
    with warnings.catch_warnings():  # "did not converge": a truncated run is the point of some tests
        warnings.simplefilter("ignore")
        fitted.fit(points)
    parameters = (fitted.weights_, fitted.means_, fitted.covariances_)
    return (*parameters, fitted.predict_proba(points), np.array(fitted.lower_bounds_), fitted.n_iter_)


def _squared_matrix(points):
    """(N, N) squared distances, summed over the columns in increasing order."""
    return sum((points[:, j, None] - points[None, :, j]) ** 2 for j in range(points.shape[1]))


def neighbour_graph(points, k, sigma=None, mutual=False):
    """The contract's kNN graph by brute force: ``(indptr, indices, weights)``, rows sorted (SciPy's
    CSR of the dense link matrix)."""
    from scipy.sparse import csr_array

    points = np.asarray(points, dtype=float)
    n = len(points)
    s = _squared_matrix(points)
    directed = np.zeros((n, n), dtype=bool)
    for i in range(n):
        others = np.delete(np.arange(n), i)
        nearest = others[np.lexsort((others, s[i, others]))[:k]]  # by (s, j)
        directed[i, nearest] = True
    links = directed & directed.T if mutual else directed | directed.T
    graph = csr_array(links)
    graph.sort_indices()
    rows = np.repeat(np.arange(n), np.diff(graph.indptr))
    weights = np.ones(len(graph.indices)) if sigma is None else np.exp(-s[rows, graph.indices] / (2 * sigma**2))
    return graph.indptr.astype(np.int64), graph.indices.astype(np.int64), weights


def laplacian(indptr, indices, weights, normalized=True):
    """The dense L = D - W, or L_sym = I - D^-1/2 W D^-1/2, of a CSR graph."""
    from scipy.sparse import csr_array

    n = len(indptr) - 1
    w = csr_array((weights, indices, indptr), shape=(n, n)).toarray()
    d = w.sum(axis=1)
    if not normalized:
        return np.diag(d) - w
    return np.eye(n) - w / np.sqrt(np.outer(d, d))


def projector_distance(a, b):
    """The largest entry of |A A^T - B B^T|: how far apart the spans of two orthonormal bases are."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.abs(a @ a.T - b @ b.T).max())


def njw_labels(points, n_clusters, k=10, sigma=None):
    """The contract's canonical NJW labels, from SciPy's eigh of the dense L_sym."""
    from scipy.linalg import eigh

    u = eigh(laplacian(*neighbour_graph(points, k, sigma), normalized=True), subset_by_index=[0, n_clusters - 1])[1]
    y = u / np.linalg.norm(u, axis=1, keepdims=True)
    picked = [0]
    nearest = ((y - y[0]) ** 2).sum(axis=1)
    for _ in range(n_clusters - 1):
        picked.append(int(np.argmax(nearest)))
        nearest = np.minimum(nearest, nearest_centres(y, y[picked[-1:]])[1][:, 0])
    labels = lloyd(y, y[picked])[0]
    _, first = np.unique(labels, return_index=True)
    renumbered = np.full(n_clusters, -1, dtype=np.int64)
    renumbered[labels[np.sort(first)]] = np.arange(len(first))  # the r-th cluster to appear becomes r
    return renumbered[labels]
