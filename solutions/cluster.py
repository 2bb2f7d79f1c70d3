"""Reference: k-means (Lloyd's algorithm), the k-means++ seeding, Gaussian mixtures by EM, DBSCAN,
Euclidean cluster extraction and spectral clustering (Ng, Jordan and Weiss). The docstrings are the
stubs' (``pcl_course/cluster.py``: the contract)."""

import numpy as np
from scipy import linalg
from scipy.sparse import csr_array, diags_array, identity
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import LinearOperator, eigsh, splu
from scipy.spatial import cKDTree
from threadpoolctl import ThreadpoolController

from pcl_course import cluster as _contract
from pcl_course.validation import (
    as_array,
    as_points,
    check_bool,
    check_graph,
    check_integer,
    check_positive,
    check_rng,
    check_scalar,
)
from solutions._fast.density import density_clusters
from solutions._fast.lloyd import lloyd_pass

# The BLAS libraries loaded (NumPy's and SciPy's OpenBLAS), found once: EM limits their threads.
_BLAS = ThreadpoolController()

__all__ = [
    "kmeans",
    "kmeans_plusplus",
    "gmm_em",
    "dbscan",
    "euclidean_clusters",
    "knn_graph",
    "spectral_embedding",
    "spectral_clustering",
]


def _documented(function):
    # The stub's text; none where this file is itself the module (a reference uploaded as a
    # student's pcl_course/, the project's tests): the contract is then half imported.
    function.__doc__ = getattr(_contract, function.__name__, function).__doc__
    return function


def _squared_distances(points, centers):
    """Squared distances ``s`` (N, K) of every point to every centre, summed over the columns in
    increasing order (the contract's order: a tie is a tie in every correct submission)."""
    s = np.zeros((len(points), len(centers)))
    for j in range(points.shape[1]):
        s += np.square(points[:, j, None] - centers[None, :, j])
    return s


# k-means: a pass that changed more than 1 / _RESUM_FRACTION of the labels is followed by one that
# sums every cluster anew (updated sums would carry the rounding of many additions and subtractions).
_RESUM_FRACTION = 16


def _moved(centers, sums, counts):
    """Each centre moved to the mean of its points; an empty one kept."""
    filled = counts > 0
    moved = centers.copy()
    moved[filled] = sums[filled] / counts[filled, None]
    return moved


@_documented
def kmeans(points, init_centers, max_iter=300):
    points = as_points(points, min_columns=1, allow_empty=False)
    centers = as_array(init_centers, "init_centers", ndim=2)
    if centers.shape[1] != points.shape[1]:
        raise ValueError(f"init_centers must have {points.shape[1]} columns (the width of points), got {centers.shape}")
    if not 1 <= len(centers) <= len(points):
        raise ValueError(f"init_centers must hold 1 to {len(points)} centres (N), got {len(centers)}")
    max_iter = check_integer(max_iter, "max_iter", low=1)
    centers = np.ascontiguousarray(centers, dtype=np.float64).copy()
    columns = np.ascontiguousarray(points.T, dtype=np.float64)  # a pass reads a column at a time
    labels = np.zeros(len(points), dtype=np.int32)  # a pass reads and writes them: half the bytes
    inertia = []
    sums, counts, changed = None, None, len(points)
    for t in range(1, max_iter + 1):
        # Once few labels change, the sums are updated by the points that moved (their rounding
        # is that of those few additions). The first pass, and any after one that moved many
        # (moves dwindle from pass to pass: the last count foretells the next), sum them whole.
        full = changed > len(points) // _RESUM_FRACTION
        found, found_counts, total, changed = lloyd_pass(columns, centers, labels, full)
        sums, counts = (found, found_counts) if full else (sums + found, counts + found_counts)
        inertia.append(total)
        if t > 1 and changed == 0:
            break
        centers = _moved(centers, sums, counts)
        if t == max_iter:
            lloyd_pass(columns, centers, labels)
    return labels.astype(np.int64), centers, np.array(inertia), len(inertia)


@_documented
def kmeans_plusplus(points, n_clusters, rng=None):
    points = as_points(points, min_columns=1, allow_empty=False)
    distinct = len(np.unique(points, axis=0))
    n_clusters = check_integer(n_clusters, "n_clusters", low=1)
    if n_clusters > distinct:
        raise ValueError(f"n_clusters must be at most the number of distinct points ({distinct}), got {n_clusters}")
    rng = check_rng(rng)
    chosen = [int(rng.integers(len(points)))]
    nearest = _squared_distances(points, points[chosen])[:, 0]
    for _ in range(n_clusters - 1):
        cumulative = np.cumsum(nearest)
        chosen.append(int(np.searchsorted(cumulative, rng.random() * cumulative[-1], side="right")))
        nearest = np.minimum(nearest, _squared_distances(points, points[chosen[-1:]])[:, 0])
    return np.array(chosen, dtype=np.int64)


def _mixture(weights, means, covariances, width):
    """The initial parameters as float64 copies, checked as the contract says (ValueError naming each)."""
    weights = as_array(weights, "weights", ndim=1, allow_empty=False).copy()
    if np.any(weights <= 0) or abs(weights.sum() - 1.0) > 1e-8:
        raise ValueError(f"weights must be positive and sum to 1, got sum {weights.sum()!r}")
    k = len(weights)
    means = as_array(means, "means", ndim=2).copy()
    if means.shape != (k, width):
        raise ValueError(f"means must have shape ({k}, {width}) (K weights, the width of points), got {means.shape}")
    covariances = as_array(covariances, "covariances", ndim=3).copy()
    if covariances.shape != (k, width, width):
        raise ValueError(f"covariances must have shape ({k}, {width}, {width}), got {covariances.shape}")
    for c in covariances:
        if np.abs(c - c.T).max() > 1e-10 * np.abs(c).max():
            raise ValueError("covariances must be symmetric")
        try:
            linalg.cholesky(c, lower=True)
        except linalg.LinAlgError:
            raise ValueError("covariances must be positive definite") from None
    return weights, means, covariances


def _precision_factors(covariances):
    """Each covariance's precision Cholesky factor P (``P P^T = Sigma^-1``), shape (K, D, D)."""
    identity = np.eye(covariances.shape[1])
    factors = np.empty_like(covariances)
    for k, covariance in enumerate(covariances):
        lower = linalg.cholesky(covariance, lower=True)
        factors[k] = linalg.solve_triangular(lower, identity, lower=True).T
    return factors


def _e_step(points, weights, means, covariances):
    """``(l, r)``: each point's log-likelihood (N,) and its responsibilities (N, K).

    The log-sum-exp is written out, one exponential per entry: ``r = exp(log rho - max) / sum``
    equals ``exp(log rho - l)`` to rounding, and scipy.special.logsumexp followed by that
    exponential took 22 ms where this takes 9 ms (1e5 points, K = 4: a third of an iteration)."""
    d = points.shape[1]
    log_rho = np.empty((len(points), len(weights)))
    for k, factor in enumerate(_precision_factors(covariances)):
        y = (points - means[k]) @ factor  # centred first: x @ P - mu @ P loses digits far from the origin
        log_det = np.sum(np.log(np.diag(factor)))
        log_rho[:, k] = -0.5 * (d * np.log(2 * np.pi) + np.sum(np.square(y), axis=1)) + log_det + np.log(weights[k])
    largest = log_rho.max(axis=1)
    responsibilities = np.exp(log_rho - largest[:, None])
    total = responsibilities.sum(axis=1)
    responsibilities /= total[:, None]
    return largest + np.log(total), responsibilities


def _m_step(points, responsibilities, reg_covar):
    n_k = responsibilities.sum(axis=0) + 10 * np.finfo(float).eps
    means = responsibilities.T @ points / n_k[:, None]
    covariances = np.empty((len(n_k), points.shape[1], points.shape[1]))
    for k in range(len(n_k)):
        centred = points - means[k]
        covariances[k] = (responsibilities[:, k] * centred.T) @ centred / n_k[k]
        covariances[k].flat[:: points.shape[1] + 1] += reg_covar
    return n_k / n_k.sum(), means, covariances


@_documented
def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    points = as_points(points, min_columns=1, allow_empty=False)
    weights, means, covariances = _mixture(weights, means, covariances, points.shape[1])
    max_iter = check_integer(max_iter, "max_iter", low=1)
    tol = check_scalar(tol, "tol", low=0.0)
    reg_covar = check_scalar(reg_covar, "reg_covar", low=0.0)
    # EM's products are (N, D) x (D, D) and (K, N) x (N, D): waking BLAS's threads costs more than
    # they save (benchmarks/cases.py's _gmm_case: 20 iterations at 1e5 points took 1.2-1.5 s on
    # OpenBLAS's two threads, 0.56-0.68 s on one), as scikit-learn's k-means limits them too.
    with _BLAS.limit(limits=1, user_api="blas"):
        return _em(points, weights, means, covariances, max_iter, tol, reg_covar)


def _em(points, weights, means, covariances, max_iter, tol, reg_covar):
    """The EM iterations of :func:`gmm_em`, on checked float64 arguments: its return value."""
    lower_bounds = []
    try:
        for t in range(1, max_iter + 1):
            log_likelihood, responsibilities = _e_step(points, weights, means, covariances)
            lower_bounds.append(float(log_likelihood.mean()))
            weights, means, covariances = _m_step(points, responsibilities, reg_covar)
            if t > 1 and abs(lower_bounds[-1] - lower_bounds[-2]) < tol:
                break
        _, responsibilities = _e_step(points, weights, means, covariances)
    except linalg.LinAlgError:  # only an M-step's covariance can fail: the initial ones were checked
        raise ValueError(
            f"a covariance became singular in iteration {len(lower_bounds)}: reg_covar = {reg_covar} is too small"
        ) from None
    return weights, means, covariances, responsibilities, np.array(lower_bounds), len(lower_bounds)


def _candidate_pairs(points, eps):
    """Every pair ``(i, j)``, i < j, a k-d tree finds within a slightly larger radius than ``eps``
    (its own rounding never decides: :func:`density_clusters` keeps those with the contract's
    ``s <= eps ** 2``): shape (P, 2), int64."""
    if len(points) < 2:
        return np.empty((0, 2), dtype=np.int64)
    pairs = cKDTree(points).query_pairs(eps * (1 + 1e-9), output_type="ndarray")
    return np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)


@_documented
def dbscan(points, eps, min_samples):
    points = np.ascontiguousarray(as_points(points, min_columns=1))
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    return density_clusters(points, _candidate_pairs(points, eps), eps * eps, min_samples)


@_documented
def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    points = np.ascontiguousarray(as_points(points, min_columns=1))
    tolerance = check_positive(tolerance, "tolerance")
    min_size = check_integer(min_size, "min_size", low=1)
    if max_size is not None:
        max_size = check_integer(max_size, "max_size", low=min_size)
    # Every point core: the components, numbered by their smallest index.
    components, _ = density_clusters(points, _candidate_pairs(points, tolerance), tolerance * tolerance, 1)
    sizes = np.bincount(components, minlength=0)
    kept = (sizes >= min_size) & (sizes <= (len(points) if max_size is None else max_size))
    order = np.flatnonzero(kept)[np.argsort(-sizes[kept], kind="stable")]  # largest first, then smallest index
    renumbered = np.full(len(sizes), -1, dtype=np.int64)
    renumbered[order] = np.arange(len(order))
    return renumbered[components]


_BLOCK = 1024  # rows of squared distances at a time: (1024, N) float64
_DENSE_EIGH = 2000  # vertices: LAPACK's dense eigh up to here (about 0.4 s at 2,000), ARPACK's beyond
_SPARE = 8  # candidates a k-d tree gives beyond the k + 1 nearest (the point itself among them)


def _brute_neighbours(points, rows, k):
    """The k neighbours by ``(s, j)`` of the points ``rows``, each itself left out, from every
    point's squared distance: (len(rows), k) int64."""
    neighbours = np.empty((len(rows), k), dtype=np.int64)
    for start in range(0, len(rows), _BLOCK):
        block = rows[start : start + _BLOCK]
        s = _squared_distances(points[block], points)
        s[np.arange(len(block)), block] = np.inf  # the point itself, not its duplicates
        kth = np.partition(s, k - 1, axis=1)[:, k - 1]
        found, columns = np.nonzero(s <= kth[:, None])  # the k nearest and every tie of the k-th
        order = np.lexsort((columns, s[found, columns], found))  # by row, then (s, j)
        found, columns = found[order], columns[order]
        rank = np.arange(len(found)) - np.searchsorted(found, found)
        neighbours[start : start + len(block)] = columns[rank < k].reshape(len(block), k)
    return neighbours


def _nearest_neighbours(points, k):
    """Each point's k neighbours by ``(s, j)``, itself left out: (N, k) int64.

    A k-d tree gives each point its k + 1 + _SPARE nearest as candidates, ranked again by the
    contract's ``s`` and index. A row is settled when every point left out is farther, by the
    tree's own distance with a margin for its rounding, than the k-th neighbour chosen; the few
    others (ties at the k-th distance on a grid, many duplicates) are found by brute force.
    """
    n = len(points)
    m = min(n, k + 1 + _SPARE)
    reach, candidates = cKDTree(points).query(points, m)
    candidates = candidates.reshape(n, m)
    s = np.zeros((n, m))
    for j in range(points.shape[1]):  # the contract's s: summed column by column
        s += np.square(points[candidates, j] - points[:, j, None])
    s[candidates == np.arange(n)[:, None]] = np.inf  # the point itself, not its duplicates
    order = np.lexsort((candidates, s), axis=-1)[:, :k]
    neighbours = np.take_along_axis(candidates, order, axis=1)
    kth = np.take_along_axis(s, order[:, -1:], axis=1)[:, 0]
    farthest = np.square(np.asarray(reach).reshape(n, m)[:, -1])
    unsettled = np.flatnonzero(~(farthest > kth * (1 + 1e-9) + 1e-300)) if m < n else np.array([], dtype=np.int64)
    if len(unsettled):
        neighbours[unsettled] = _brute_neighbours(points, unsettled, k)
    return neighbours


@_documented
def knn_graph(points, k, sigma=None, mutual=False):
    points = as_points(points, min_columns=1, allow_empty=False)
    n = len(points)
    if n < 2:
        raise ValueError(f"points must hold at least 2 points (a graph needs neighbours), got {n}")
    k = check_integer(k, "k", low=1, high=n - 1)
    if sigma is not None:
        sigma = check_positive(sigma, "sigma")
    mutual = check_bool(mutual, "mutual")
    heads = np.repeat(np.arange(n, dtype=np.int64), k)
    tails = _nearest_neighbours(points, k).ravel()
    # Each directed edge i -> j as the code i N + j; the undirected links as codes in both directions.
    forward, backward = heads * n + tails, tails * n + heads
    codes = np.intersect1d(forward, backward) if mutual else np.union1d(forward, backward)
    rows, columns = codes // n, codes % n  # sorted by row, then column
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    if sigma is None:
        weights = np.ones(len(codes))
    else:
        s = np.zeros(len(codes))
        for j in range(points.shape[1]):  # the contract's order: s(i, j) == s(j, i) exactly
            s += np.square(points[rows, j] - points[columns, j])
        weights = np.exp(-s / (2.0 * sigma * sigma))
    return indptr, columns.astype(np.int64), weights


@_documented
def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    indptr, indices, weights, degrees = check_graph(indptr, indices, weights)
    n = len(degrees)
    n_components = check_integer(n_components, "n_components", low=1, high=n)
    normalized = check_bool(normalized, "normalized")
    rows = np.repeat(np.arange(n), np.diff(indptr))
    scale = 1.0 / np.sqrt(degrees) if normalized else np.ones(n)
    off_diagonal = -weights * scale[rows] * scale[indices]
    diagonal = np.ones(n) if normalized else degrees
    if n <= _DENSE_EIGH or n_components > n // 2:
        laplacian = np.zeros((n, n))
        laplacian[rows, indices] = off_diagonal
        laplacian[np.diag_indices(n)] = diagonal
        return linalg.eigh(laplacian, subset_by_index=[0, n_components - 1])
    # ARPACK in shift-invert mode about a shift just below the spectrum (L - shift I is positive
    # definite, factorised once): the smallest eigenvalues converge first. A fixed start vector
    # makes the run repeatable; a QR makes the vectors orthonormal to rounding, not to ARPACK's
    # tolerance.
    laplacian = (csr_array((off_diagonal, indices, indptr), shape=(n, n)) + diags_array(diagonal)).tocsc()
    start = np.random.default_rng(0).uniform(0.5, 1.5, n)
    shifted = _invert_shifted(laplacian, _SHIFT)
    eigenvalues, vectors = eigsh(
        laplacian, k=n_components, sigma=_SHIFT, which="LM", tol=1e-14, v0=start, OPinv=shifted
    )
    order = np.argsort(eigenvalues)
    q, r = np.linalg.qr(vectors[:, order])
    return eigenvalues[order], q * np.sign(np.diag(r))


# ARPACK's shift: below the Laplacian's spectrum (its eigenvalues are >= 0), near its smallest.
_SHIFT = -1e-2


def _invert_shifted(matrix, shift):
    """``(matrix - shift I)^-1`` as an operator, for a symmetric ``matrix`` (CSC) with ``matrix -
    shift I`` positive definite: SuperLU in symmetric mode (a minimum-degree ordering of A^T + A and
    the diagonal as pivots, stable for a positive definite matrix). eigsh's own factorisation
    (COLAMD, partial pivoting) filled 5.8 million entries for a 1e4-point 10-neighbour graph where
    this fills 2.4 million, and took 0.38 s where this takes 0.12 s."""
    n = matrix.shape[0]
    factor = splu(
        (matrix - shift * identity(n, format="csc")).tocsc(),
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    return LinearOperator((n, n), matvec=factor.solve, dtype=float)


def _check_components(indptr, indices, weights, n_clusters, sigma):
    """The contract's two checks of the graph before its embedding (ValueError naming sigma, n_clusters).

    The degrees are summed here, not taken from ``check_graph``: a vertex of degree 0 is the
    contract's error naming ``sigma`` (the weights underflowed), where check_graph names ``weights``."""
    n = len(indptr) - 1
    rows = np.repeat(np.arange(n), np.diff(indptr))
    positive = weights > 0
    degrees = np.bincount(rows, weights=weights, minlength=n)
    if np.any(degrees <= 0):
        raise ValueError(
            f"sigma = {sigma} is too small: every link of point {int(np.argmax(degrees <= 0))} weighs "
            "exp(-s / (2 sigma^2)) = 0.0"
        )
    count, _ = connected_components(csr_array((weights[positive], (rows[positive], indices[positive])), shape=(n, n)))
    if count > n_clusters:
        raise ValueError(
            f"n_clusters = {n_clusters} is below the {count} connected components of the kNN graph: its "
            "embedding is not unique (raise n_clusters or k)"
        )


def _farthest_first(rows, count):
    """``count`` rows picked farthest first from row 0 (by s, ties to the lowest index)."""
    picked = [0]
    nearest = _squared_distances(rows, rows[:1])[:, 0]
    for _ in range(count - 1):
        picked.append(int(np.argmax(nearest)))
        nearest = np.minimum(nearest, _squared_distances(rows, rows[picked[-1:]])[:, 0])
    return np.array(picked)


def _by_first_appearance(labels):
    """Labels renumbered 0, 1, ... in the order their clusters first appear."""
    _, first = np.unique(labels, return_index=True)
    renumbered = np.empty(labels.max() + 1, dtype=np.int64)
    renumbered[labels[np.sort(first)]] = np.arange(len(first))
    return renumbered[labels]


@_documented
def spectral_clustering(points, n_clusters, k=10, sigma=None):
    points = as_points(points, min_columns=1, allow_empty=False)
    n_clusters = check_integer(n_clusters, "n_clusters", low=1, high=max(len(points), 1))
    graph = knn_graph(points, k, sigma)
    _check_components(*graph, n_clusters, sigma)
    _, vectors = spectral_embedding(*graph, n_clusters, normalized=True)
    rows = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    labels, _, _, _ = kmeans(rows, rows[_farthest_first(rows, n_clusters)])
    return _by_first_appearance(labels)
