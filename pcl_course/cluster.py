"""Exercises of lecture 3: clustering (k-means and its seeding, Gaussian mixtures by EM, DBSCAN,
Euclidean clusters, spectral clustering).

The rules of this module (the course's contract, on top of the general rules):

Points and distances
    ``points`` is (N, D), D >= 1, N >= 1 (N >= 0 for :func:`dbscan` and
    :func:`euclidean_clusters`, whose empty cloud has empty labels); every
    column is a coordinate.
    Everything is computed in float64 (float32 input is converted). The
    squared distance of a point p to a centre (or point) c is
    ``s = sum_j (p_j - c_j) ** 2`` over the columns, in increasing j (as in
    lecture 2).

Labels
    int64, clusters numbered 0, 1, ..., noise -1; each function states its
    numbering, so that answers compare exactly, with no matching of labels.

Ties
    Wherever a rule takes a minimum or a maximum over centres or
    components, **ties go to the lowest index**.

Randomness
    :func:`kmeans` and :func:`gmm_em` are deterministic: they start from
    the centres or parameters they are given.
    Only :func:`kmeans_plusplus` draws, from ``rng`` (``None``, an int seed
    or a ``numpy.random.Generator``, as ``np.random.default_rng(rng)``),
    exactly the draws its docstring lists, in that order: the same seed gives
    the same answer, in every correct submission.

Arguments
    Anything else than the documented shapes, non-finite values, a number of
    clusters or a size outside its range, a ``max_iter`` or ``min_samples``
    below 1 or an ``eps`` or ``tolerance`` that is not a positive finite
    number is a ``ValueError`` naming the argument. Inputs are never
    modified.

Forbidden here
    scikit-learn and Open3D (forbidden everywhere), ``scipy.cluster``,
    ``hdbscan``, ``fast_hdbscan``, ``dbscan``, ``pyclustering``, ``kmeans1d``
    and ``faiss``: this lecture is about writing the algorithms. NumPy, SciPy's other
    modules (``scipy.spatial.distance.cdist``, ...) and numba are yours.
"""

# What every solution needs (NumPy; the course's input checks).
import numpy as np  # noqa: F401

from pcl_course.validation import as_array, as_points, check_integer, check_rng  # noqa: F401

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


def kmeans(points, init_centers, max_iter=300):
    """Lloyd's algorithm from the given centres.

    Iteration t = 1, 2, ...:

    1. **Assign** each point to its nearest centre (smallest squared
       distance, ties to the lowest centre index) and record
       ``inertia[t - 1]``, the sum over the points of the squared distance
       to their centre.
    2. If t > 1 and no label changed from iteration t - 1, **stop**:
       ``n_iter = t``.
    3. Otherwise, if t < ``max_iter``, **update** every centre to the mean
       of its points; **an empty cluster keeps its centre**. If
       t == ``max_iter``, update the centres the same way, then assign the
       points to the updated centres once more (not an iteration: nothing
       is recorded), and stop with ``n_iter = max_iter``.

    So the returned labels are always the assignment to the returned
    centres, and every returned centre with points is their mean.

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 1, D >= 1.
    init_centers : array_like, shape (K, D)
        The initial centres, 1 <= K <= N, with the width of ``points``.
        Equal centres are allowed (ties send every point to the first of
        them; the others start empty).
    max_iter : int, default 300
        Largest number of iterations, >= 1.

    Returns
    -------
    labels : ndarray of int64, shape (N,)
        Each point's centre, in ``0 .. K - 1``.
    centers : ndarray of float64, shape (K, D)
        The final centres.
    inertia : ndarray of float64, shape (n_iter,)
        The sum of squared distances recorded at each iteration's
        assignment; it never increases (in exact arithmetic: the tests
        allow for rounding).
    n_iter : int
        The number of iterations run, ``1 <= n_iter <= max_iter``.

    Raises
    ------
    ValueError
        Bad ``points`` or ``init_centers`` (shape, width, non-finite, K
        outside ``1..N``); ``max_iter`` not an integer >= 1.
    """
    raise NotImplementedError("kmeans: not implemented yet")


def kmeans_plusplus(points, n_clusters, rng=None):
    """The k-means++ seeding (D² sampling) of Arthur and Vassilvitskii.

    ``rng = np.random.default_rng(rng)``, then:

    1. The first index is ``rng.integers(N)``.
    2. Each next index: let ``w[i]`` be the squared distance of point i to
       its nearest chosen point (0 for the chosen points and their
       duplicates), ``cum = np.cumsum(w)`` (in index order) and
       ``u = rng.random()``; the index is the smallest i with
       ``cum[i] > u * cum[-1]``. (A point is drawn with probability
       proportional to ``w``: ``rng.choice(N, p=w / w.sum())`` makes the
       same single draw and, but for rounding where ``u * cum[-1]`` falls
       on a boundary, returns the same index.)

    No other draw is made. Points at distance 0 from a chosen point are
    never drawn, so the indices are distinct and no two chosen points are
    equal.

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 1, D >= 1.
    n_clusters : int
        Number of seeds, ``1 <= n_clusters <=`` the number of distinct
        points.
    rng : None, int or numpy.random.Generator, default None
        The source of the draws.

    Returns
    -------
    indices : ndarray of int64, shape (n_clusters,)
        The chosen points' indices, in the order they were drawn.

    Raises
    ------
    ValueError
        Bad ``points``; ``n_clusters`` not an integer in
        ``1 ..`` the number of distinct points; a bad ``rng``.
    """
    raise NotImplementedError("kmeans_plusplus: not implemented yet")


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    """A Gaussian mixture fitted by expectation-maximisation, from the given parameters.

    The mixture has K components, each with a weight ``pi_k``, a mean
    ``mu_k`` and a full covariance ``Sigma_k``. Iteration t = 1, 2, ...:

    1. **E-step**, with the current parameters, in the log domain:
       ``log rho[n, k] = log pi_k + log N(x_n; mu_k, Sigma_k)``, where
       ``log N(x; mu, Sigma) = -(D log(2 pi) + |L^-1 (x - mu)|^2) / 2 - sum_j
       log L_jj`` with L the lower Cholesky factor of Sigma;
       ``l[n] = logsumexp_k log rho[n, k]`` and
       ``log r[n, k] = log rho[n, k] - l[n]`` (the responsibilities).
       Record ``lower_bounds[t - 1] = mean_n l[n]``, the average
       log-likelihood of the parameters the step started from.
    2. **M-step**: ``N_k = sum_n r[n, k] + 10 eps`` (eps the float64
       machine epsilon, ``np.finfo(float).eps``: an empty component's
       mean stays finite), ``mu_k = sum_n r[n, k] x_n / N_k``,
       ``Sigma_k = sum_n r[n, k] (x_n - mu_k)(x_n - mu_k)^T / N_k +
       reg_covar I`` and ``pi_k = N_k / sum_j N_j``.
    3. If t > 1 and ``|lower_bounds[t - 1] - lower_bounds[t - 2]| < tol``,
       **stop**: ``n_iter = t``. Otherwise go on, up to ``max_iter``
       iterations (then ``n_iter = max_iter``).

    The returned responsibilities are those of the returned parameters: one
    more E-step after the last M-step (not an iteration: nothing is
    recorded). These are scikit-learn's ``GaussianMixture(covariance_type=
    "full")`` rules, started from ``weights_init``, ``means_init`` and the
    covariances' inverses as ``precisions_init``.

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 1, D >= 1.
    weights : array_like, shape (K,)
        The initial weights, positive, summing to 1 (within 1e-8), K >= 1.
    means : array_like, shape (K, D)
        The initial means.
    covariances : array_like, shape (K, D, D)
        The initial covariances, each symmetric (``|Sigma - Sigma^T|``
        at most 1e-10 times its largest absolute entry) and positive
        definite.
    max_iter : int, default 100
        Largest number of iterations, >= 1.
    tol : float, default 1e-3
        The change of the average log-likelihood below which EM stops,
        >= 0 (0: always run ``max_iter`` iterations, as ``|change| < 0``
        never holds).
    reg_covar : float, default 1e-6
        Added to the diagonal of every covariance the M-step computes
        (keeps a component on too few points positive definite), >= 0.
        With 0, a covariance the M-step computes may be singular (a
        component on fewer than D + 1 distinct points): then a
        ``ValueError`` naming ``reg_covar``, as scikit-learn raises.

    Returns
    -------
    weights : ndarray of float64, shape (K,)
    means : ndarray of float64, shape (K, D)
    covariances : ndarray of float64, shape (K, D, D)
        The final parameters.
    responsibilities : ndarray of float64, shape (N, K)
        ``r[n, k]`` of the final parameters; each row sums to 1. A point's
        cluster is its row's argmax (ties to the lowest index).
    lower_bounds : ndarray of float64, shape (n_iter,)
        The average log-likelihood recorded at each iteration's E-step; it
        never decreases in exact arithmetic for ``reg_covar = 0`` and without
        the ``10 eps`` (with it, the M-step is not exactly the maximiser, and
        the bound can fall by a small amount, of second order in eps unless
        a component is nearly empty; the Gaussian mixtures chapter bounds it).
    n_iter : int
        The number of iterations run, ``1 <= n_iter <= max_iter``.

    Raises
    ------
    ValueError
        Bad ``points``; ``weights``, ``means`` or ``covariances`` of the
        wrong shape, not finite, weights not positive or not summing to 1,
        a covariance not symmetric or not positive definite; ``max_iter``
        not an integer >= 1; ``tol`` or ``reg_covar`` not a finite number
        >= 0; a covariance computed by an M-step not positive definite
        (``reg_covar`` too small).
    """
    raise NotImplementedError("gmm_em: not implemented yet")


def dbscan(points, eps, min_samples):
    """DBSCAN: clusters of density-connected points, and noise.

    With ``N(p) = {q : s(p, q) <= eps ** 2}``, the points within ``eps`` of
    p, **p itself included** (and every duplicate of p):

    1. p is a **core** point iff ``|N(p)| >= min_samples``.
    2. The **clusters** are the connected components of the core points,
       two core points p and q being linked when q is in N(p). They are
       numbered by their smallest core index: the cluster of the lowest
       core point is 0, the cluster of the lowest core point not in it is
       1, and so on.
    3. A point that is not core but has a core point in N(p) is a
       **border** point: it takes the **smallest** label among the
       clusters of its core neighbours (it may touch several).
    4. Every other point is **noise**, labelled -1.

    The answer depends on no visiting order. The neighbourhood is
    inclusive: two points exactly ``eps`` apart (``s == eps ** 2``) are
    neighbours. scikit-learn's ``DBSCAN`` follows these rules, except where
    a distance lies within rounding of ``eps``: there its answer depends on
    the neighbour search it picks (its brute force expands the squared
    distance as ``|p|^2 - 2 p.q + |q|^2``; its trees may take a whole node
    at once). Open3D's ``cluster_dbscan`` takes ``s < eps ** 2``.

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 0, D >= 1.
    eps : float
        The neighbourhood's radius, in the points' units; positive and
        finite.
    min_samples : int
        The number of points (itself included) within ``eps`` that makes a
        point core, >= 1 (1: every point is core, and the clusters are the
        connected components of the ``eps``-graph).

    Returns
    -------
    labels : ndarray of int64, shape (N,)
        Each point's cluster (numbered as in 2.), or -1 for noise.
    is_core : ndarray of bool, shape (N,)
        Whether each point is a core point.

    Raises
    ------
    ValueError
        Bad ``points`` (shape, non-finite); ``eps`` not a positive finite
        number; ``min_samples`` not an integer >= 1.
    """
    raise NotImplementedError("dbscan: not implemented yet")


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    """Euclidean cluster extraction (PCL's ``EuclideanClusterExtraction``).

    1. Two points p and q are **linked** when ``s(p, q) <= tolerance ** 2``
       (inclusive: points exactly ``tolerance`` apart are linked).
    2. The clusters are the connected components of the links (a point
       alone is a component of size 1).
    3. A component of fewer than ``min_size`` points, or of more than
       ``max_size`` points, is dropped: its points are labelled -1.
    4. The kept clusters are numbered 0, 1, ... by **decreasing size**;
       clusters of equal size by their smallest point index.

    This is :func:`dbscan` with ``min_samples = 1`` (every point core),
    size filters and another numbering (PCL's: largest first). Two rules
    are the contract's, not PCL's: the links are inclusive (PCL's k-d tree
    keeps ``s < tolerance ** 2``, in float32), and clusters of equal size
    are ordered by their smallest index (PCL's sort leaves them in no fixed
    order).

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 0, D >= 1.
    tolerance : float
        The largest distance between linked points, in the points' units;
        positive and finite.
    min_size : int, default 1
        The smallest cluster kept, >= 1.
    max_size : int or None, default None
        The largest cluster kept (None: no limit), >= ``min_size``.

    Returns
    -------
    labels : ndarray of int64, shape (N,)
        Each point's cluster (numbered as in 4.), or -1 for a point of a
        dropped component.

    Raises
    ------
    ValueError
        Bad ``points`` (shape, non-finite); ``tolerance`` not a positive
        finite number; ``min_size`` not an integer >= 1; ``max_size``
        neither None nor an integer >= ``min_size``.
    """
    raise NotImplementedError("euclidean_clusters: not implemented yet")


def knn_graph(points, k, sigma=None, mutual=False):
    """The symmetric k-nearest-neighbour similarity graph, in CSR form.

    1. The **neighbours** of point i are the k points j != i smallest by
       ``(s(i, j), j)``: the nearest first, ties to the lowest index. An
       exact duplicate of i is a neighbour at distance 0 (only i itself is
       left out).
    2. Points i and j are **linked** when j is a neighbour of i *or* i a
       neighbour of j (``mutual=False``), or when each is a neighbour of the
       other (``mutual=True``). No point is linked to itself.
    3. A link's **weight** is ``exp(-s(i, j) / (2 * sigma ** 2))`` (a
       Gaussian similarity: 1 for a duplicate, towards 0 far away; it may
       underflow to 0.0, and the link is kept), or 1.0 with
       ``sigma=None``.

    The graph is returned as SciPy's CSR arrays: the links of point i are
    ``indices[indptr[i]:indptr[i + 1]]``, in increasing order, with their
    weights at the same places. Every link appears in both rows with the
    same weight (``scipy.sparse.csr_array((weights, indices, indptr))`` is
    a symmetric matrix).

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 2, D >= 1.
    k : int
        Number of neighbours of each point, ``1 <= k <= N - 1``.
    sigma : float or None, default None
        The Gaussian's width, in the points' units; positive and finite.
        None: every link weighs 1.0.
    mutual : bool, default False
        Link only mutual neighbours (a point may then have no link at
        all: :func:`spectral_embedding` refuses such a graph).

    Returns
    -------
    indptr : ndarray of int64, shape (N + 1,)
        Row pointers: ``indptr[0] == 0``, ``indptr[N]`` the number of
        stored entries (twice the number of links).
    indices : ndarray of int64, shape (indptr[N],)
        Each row's linked points, increasing within the row.
    weights : ndarray of float64, shape (indptr[N],)
        The links' weights, in (0, 1] (or 0.0 where the Gaussian
        underflows).

    Raises
    ------
    ValueError
        Bad ``points`` (shape, non-finite, N < 2); ``k`` not an integer in
        ``1 .. N - 1``; ``sigma`` neither None nor a positive finite
        number; ``mutual`` not a bool.
    """
    raise NotImplementedError("knn_graph: not implemented yet")


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    """The smallest eigenpairs of a graph's Laplacian.

    With W the symmetric weight matrix of the graph (CSR, as
    :func:`knn_graph` returns it), D the diagonal of its degrees
    ``d_i = sum_j w_ij`` and I the identity:

    * ``normalized=False``: the Laplacian ``L = D - W``;
    * ``normalized=True``: the normalised Laplacian
      ``L_sym = I - D^(-1/2) W D^(-1/2)``.

    Return its ``n_components`` smallest eigenvalues, in increasing order,
    and orthonormal real eigenvectors for them. An eigenvector's sign, and
    the basis of an eigenspace of several dimensions, are free: the tests
    compare the projector ``V V^T`` onto the span of the vectors (on
    graphs whose eigenvalue ``n_components + 1`` is well above eigenvalue
    ``n_components``, where that span is unique), to 1e-8, and the
    eigenvalues to 1e-10 (absolute: they lie in [0, 2] for L_sym).

    Parameters
    ----------
    indptr : array_like of int, shape (N + 1,)
        Row pointers, N >= 1: ``indptr[0] == 0``, non-decreasing, and
        ``indptr[N] == len(indices)``.
    indices : array_like of int, shape (indptr[N],)
        Each row's columns, in ``0 .. N - 1``, strictly increasing within a
        row (no entry twice), and never the row itself (no self-loop).
    weights : array_like of float, shape (indptr[N],)
        The entries of W: finite, >= 0, symmetric (``w_ij == w_ji``, an
        entry of row i in column j stored in row j at column i too), every
        vertex of positive degree.
    n_components : int
        Number of eigenpairs, ``1 <= n_components <= N``.
    normalized : bool, default True
        Use L_sym (True) or L (False).

    Returns
    -------
    eigenvalues : ndarray of float64, shape (n_components,)
        The smallest eigenvalues, increasing (the first is 0 up to
        rounding: the constant vector, or ``D^(1/2)`` times it, is in the
        kernel).
    vectors : ndarray of float64, shape (N, n_components)
        Orthonormal eigenvectors, column m for eigenvalue m.

    Raises
    ------
    ValueError
        Bad ``indptr`` (shape, not integers, not a valid set of row
        pointers); bad ``indices`` (length, not integers, out of range,
        unsorted or repeated within a row, a self-loop); bad ``weights``
        (length, non-finite, negative, not symmetric, a vertex of degree
        0); ``n_components`` not an integer in ``1 .. N``; ``normalized``
        not a bool.
    """
    raise NotImplementedError("spectral_embedding: not implemented yet")


def spectral_clustering(points, n_clusters, k=10, sigma=None):
    """Spectral clustering by Ng, Jordan and Weiss, made canonical.

    1. ``graph = knn_graph(points, k, sigma)`` (``mutual=False``).
    2. ``_, U = spectral_embedding(*graph, n_clusters, normalized=True)``.
    3. **Rows to the unit sphere:** Y is U with each row divided by its
       length.
    4. **Initial centres, farthest first:** row 0 of Y; then, n_clusters - 1
       times, the row whose squared distance to its nearest chosen row is
       the largest (ties to the lowest index).
    5. ``labels = kmeans(Y, those rows)`` (the contract's k-means, with
       its ``max_iter=300``).
    6. **Renumber by first appearance:** point 0's cluster becomes 0, the
       cluster of the first point not in it 1, and so on.

    Before step 2, two checks: a point whose links all weigh 0.0 (the
    Gaussian underflows: ``sigma`` too small for its nearest neighbours)
    is a ``ValueError`` naming ``sigma``; a graph whose links of positive
    weight make more than ``n_clusters`` connected components is a
    ``ValueError`` naming ``n_clusters`` (eigenvalue 0 then has more than
    ``n_clusters`` independent eigenvectors: U, and the labels, would
    depend on the eigensolver, and rows of U could be 0).

    Steps 3 to 6 depend on Y only through the distances between its rows,
    which a rotation of the eigenvectors' basis (``U R``, R orthogonal:
    another eigensolver's answer, or other signs) does not change: the
    labels are the same for any orthonormal basis of the eigenspace (the
    book proves it). They are canonical when that eigenspace is unique:
    when eigenvalue ``n_clusters + 1`` of L_sym is above eigenvalue
    ``n_clusters`` (the tests' clouds have a clear gap).

    Parameters
    ----------
    points : array_like, shape (N, D)
        The points, N >= 2, D >= 1.
    n_clusters : int
        Number of clusters, ``1 <= n_clusters <= N``.
    k : int, default 10
        Neighbours of the kNN graph, ``1 <= k <= N - 1``.
    sigma : float or None, default None
        The graph's Gaussian width (None: weights 1).

    Returns
    -------
    labels : ndarray of int64, shape (N,)
        Each point's cluster, numbered by first appearance.

    Raises
    ------
    ValueError
        As :func:`knn_graph` for ``points``, ``k`` and ``sigma``;
        ``n_clusters`` not an integer in ``1 .. N``; a point whose links
        all weigh 0.0 (``sigma``); more connected components than
        ``n_clusters`` (``n_clusters``).
    """
    raise NotImplementedError("spectral_clustering: not implemented yet")
