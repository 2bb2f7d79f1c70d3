"""Known mistakes of ``pcl_course/pca.py``: PCA, kernel matrices, kernel PCA."""

import numpy as np
from scipy.spatial.distance import cdist

from grading.instructors.mistakes import Mistake, Model, Raised, Variants, same, valid_points


def _scatter_eigen(points, correlation=False, ddof=0, centring="columns", guard=True):
    """Eigenpairs of the (mis)normalised covariance, ascending (eigh's order)."""
    data = valid_points(points, min_rows=1)
    count = data.shape[0]
    offset = {"columns": data.mean(axis=0), "scalar": data.mean(), "none": 0.0}[centring]
    deviations = data - offset
    if correlation:
        spread = np.sqrt((deviations**2).mean(axis=0))
        if guard:
            flat = data.max(axis=0) == data.min(axis=0)
            deviations = np.where(flat, 0.0, deviations / np.where(flat, 1.0, spread))
        else:
            with np.errstate(invalid="ignore", divide="ignore"):
                deviations = deviations / spread
    moment = np.einsum("ni,nj->ij", deviations, deviations) / (count - ddof)
    if not np.isfinite(moment).all():
        return np.full(moment.shape[0], np.nan), np.full(moment.shape, np.nan)
    return np.linalg.eigh(moment)


def _descending(pair):
    values, vectors = pair
    return values[::-1].copy(), vectors[:, ::-1].copy()


def pca_truth(points, correlation=False, sort=True):
    return _descending(_scatter_eigen(points, correlation))


def _canonical_columns(vectors):
    """Each column with its largest-magnitude entry made positive (the sign is free)."""
    vectors = np.array(vectors, dtype=float)
    if vectors.ndim != 2 or not np.isfinite(vectors).all():
        return vectors
    pivots = np.argmax(np.abs(vectors), axis=0)
    signs = np.sign(vectors[pivots, np.arange(vectors.shape[1])])
    return vectors * np.where(signs == 0, 1.0, signs)


def _simple(values, tolerance=1e-6):
    """Which eigenvalues are simple (their eigenvector is defined up to sign only)."""
    values = np.asarray(values, dtype=float)
    gaps = np.abs(values[:, None] - values[None, :]) <= tolerance * (1.0 + np.abs(values).max(initial=0.0))
    return gaps.sum(axis=1) == 1


def pca_same(a, b, arguments):
    if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 2):
        return same(a, b)
    try:
        values_a, vectors_a = (np.asarray(x) for x in a)
        values_b, vectors_b = (np.asarray(x) for x in b)
    except Exception:
        return False
    if not arguments.get("sort", True) and values_a.shape == values_b.shape and values_a.ndim == 1:
        # sort=False: any order; compare both in descending order of their eigenvalues
        order_a, order_b = np.argsort(-np.real(values_a)), np.argsort(-np.real(values_b))
        values_a, vectors_a = values_a[order_a], vectors_a[:, order_a] if vectors_a.ndim == 2 else vectors_a
        values_b, vectors_b = values_b[order_b], vectors_b[:, order_b] if vectors_b.ndim == 2 else vectors_b
    if not same(np.real_if_close(values_a), values_b):
        return False
    if vectors_a.shape != vectors_b.shape or vectors_a.ndim != 2:
        return False
    if np.iscomplexobj(vectors_a) or np.iscomplexobj(vectors_b):
        vectors_a, vectors_b = np.real_if_close(vectors_a), np.real_if_close(vectors_b)
    columns = _simple(values_b) if np.isfinite(values_b).all() else np.ones(len(values_b), bool)
    return same(_canonical_columns(vectors_a)[:, columns], _canonical_columns(vectors_b)[:, columns])


def _when(condition, answer):
    return answer() if condition else None


def _with_or_without_correlation(make):
    """A PCA mistake's answers: with correlation=True, also as if correlation were not implemented
    (a common second omission that must not hide the first mistake)."""

    def predict(points, correlation=False, sort=True):
        if not correlation:
            return make(points, False, sort)
        return Variants([make(points, True, sort), make(points, False, sort)])

    return predict


PCA = Model(
    truth=pca_truth,
    same=pca_same,
    output_dtypes=("float64", "float64"),
    mistakes=(
        Mistake(
            "sample_covariance",
            "your eigenvalues are N/(N-1) times too large on every input: H = X~^T X~ / N divides by N "
            "(population normalisation), not by N - 1 as np.cov does by default",
            # A correlation matrix is the same whatever the normalisation: only the covariance differs.
            lambda points, correlation=False, sort=True: _when(
                not correlation, lambda: _descending(_scatter_eigen(points, False, ddof=1))
            ),
        ),
        Mistake(
            "ascending",
            "with sort=True the eigenvalues must come in descending order: np.linalg.eigh returns them "
            "ascending, so reverse the eigenvalues and the eigenvector columns",
            _with_or_without_correlation(
                lambda points, correlation, sort: _when(sort, lambda: _scatter_eigen(points, correlation))
            ),
        ),
        Mistake(
            "eig_unsorted",
            "np.linalg.eig returns the eigenpairs unsorted, and eigenvectors that need not be orthogonal: H is "
            "symmetric, so use np.linalg.eigh, then sort descending",
            lambda points, correlation=False, sort=True: _eig_unsorted(points, correlation),
        ),
        Mistake(
            "correlation_ignored",
            "correlation=True must analyse the correlation matrix: divide each centred column by its "
            "population standard deviation first",
            lambda points, correlation=False, sort=True: _when(correlation, lambda: pca_truth(points, False)),
        ),
        Mistake(
            "constant_column_nan",
            "with correlation=True a constant column has standard deviation 0: leave it at zero instead of "
            "dividing by 0 (which gives NaN)",
            lambda points, correlation=False, sort=True: _when(
                correlation, lambda: _nan_or_raised(_descending(_scatter_eigen(points, True, guard=False)))
            ),
        ),
        Mistake(
            "no_centring",
            "the data are not centred: subtract each column's mean before forming H "
            "(X^T X / N is the second moment about the origin, not the covariance)",
            lambda points, correlation=False, sort=True: _when(
                not correlation, lambda: _descending(_scatter_eigen(points, False, centring="none"))
            ),
        ),
        Mistake(
            "scalar_mean",
            "centre each column by its own mean (points.mean(axis=0)), not by one mean of all coordinates",
            lambda points, correlation=False, sort=True: _when(
                not correlation, lambda: _descending(_scatter_eigen(points, False, centring="scalar"))
            ),
        ),
        Mistake(
            "rows_not_columns",
            "the eigenvectors must be the COLUMNS of the returned matrix (eigenvectors[:, i]); yours are its rows",
            lambda points, correlation=False, sort=True: _transposed(pca_truth(points, correlation)),
            same=lambda a, b, arguments: pca_same(_transposed_answer(a), _transposed_answer(b), arguments),
        ),
        Mistake(
            "zero_eigenvectors",
            "the eigenvectors must be unit vectors: a zero vector satisfies H v = lambda v but is not an eigenvector",
            lambda points, correlation=False, sort=True: _zero_vectors(pca_truth(points, correlation)),
        ),
    ),
)


def _eig_unsorted(points, correlation):
    data = valid_points(points, min_rows=1)
    deviations = data - data.mean(axis=0)
    if correlation:
        spread = deviations.std(axis=0)
        deviations = deviations / np.where(spread > 0, spread, 1.0)
    values, vectors = np.linalg.eig(deviations.T @ deviations / len(data))
    return Variants([(values, vectors), (np.real(values), np.real(vectors))])


def _transposed(pair):
    values, vectors = pair
    return values, vectors.T.copy()


def _nan_or_raised(answer):
    """NaN answers, or the LinAlgError that np.linalg.eigh raises on a matrix holding NaN."""
    if np.isnan(answer[0]).any():
        return Variants([answer, Raised("LinAlgError")])
    return answer


def _transposed_answer(answer):
    try:
        values, vectors = answer
        return values, np.asarray(vectors).T
    except (TypeError, ValueError):
        return answer


def _zero_vectors(pair):
    values, vectors = pair
    return values, np.zeros_like(vectors)


# -- kernel_matrix -----------------------------------------------------------------------


def kernel_truth(x, y, kernel="gaussian", beta=1.0, degree=2, l2_laplacian=False, gaussian_square=True, one=1.0):
    left, right = valid_points(x, min_rows=1), valid_points(y, min_rows=1)
    if left.shape[1] != right.shape[1]:
        raise ValueError("widths differ")
    if kernel == "linear":
        return left @ right.T
    if kernel == "polynomial":
        return (one + left @ right.T) ** degree
    if kernel == "gaussian":
        gaps = cdist(left, right, "sqeuclidean") if gaussian_square else cdist(left, right)
        return np.exp(-beta * gaps)
    if kernel == "laplacian":
        return np.exp(-beta * cdist(left, right, "euclidean" if l2_laplacian else "cityblock"))
    raise ValueError("unknown kernel")


def _kernel_when(kind, **changes):
    def predict(x, y, kernel="gaussian", beta=1.0, degree=2):
        return kernel_truth(x, y, kernel, beta, degree, **changes) if kernel == kind else None

    return predict


KERNEL_MATRIX = Model(
    truth=kernel_truth,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "gaussian_without_square",
            "the Gaussian kernel is exp(-beta * ||x - y||^2): the distance is SQUARED (the lecture's formula "
            "drops the square)",
            _kernel_when("gaussian", gaussian_square=False),
        ),
        Mistake(
            "laplacian_with_l2_norm",
            "the Laplacian kernel uses the L1 (Manhattan) norm, exp(-beta * ||x - y||_1), not the Euclidean one",
            _kernel_when("laplacian", l2_laplacian=True),
        ),
        Mistake(
            "polynomial_without_one",
            "the polynomial kernel is (1 + x . y) ** degree: the + 1 is missing",
            _kernel_when("polynomial", one=0.0),
        ),
    ),
)


# -- kernel_pca ----------------------------------------------------------------------------


def _double_centred(gram):
    return gram - gram.mean(axis=0)[None, :] - gram.mean(axis=1)[:, None] + gram.mean()


def _kernel_pca(points, n_components, kernel, beta, degree, gram=None, scale=1.0, order="largest", unit=False):
    raw = kernel_truth(points, points, kernel, beta, degree)
    if not 1 <= int(n_components) <= len(raw):
        raise ValueError("n_components out of range")
    centred = _double_centred(raw) if gram is None else gram(raw)
    values, vectors = np.linalg.eigh(centred / scale)
    picked = slice(None, int(n_components)) if order == "smallest" else slice(-int(n_components), None)
    values, vectors = values[picked], vectors[:, picked]
    if order == "largest":
        values, vectors = values[::-1], vectors[:, ::-1]
    alphas = vectors if unit else vectors / np.sqrt(np.abs(values))
    return centred @ alphas, values.copy(), alphas


def kernel_pca_truth(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    return _kernel_pca(points, n_components, kernel, beta, degree)


def kernel_pca_same(a, b, arguments):
    if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 3):
        return same(a, b)
    try:
        projections_a, values_a, alphas_a = (np.asarray(x, dtype=float) for x in a)
        projections_b, values_b, alphas_b = (np.asarray(x, dtype=float) for x in b)
    except Exception:
        return False
    if not same(values_a, values_b, rtol=1e-5, atol=1e-7) or alphas_a.shape != alphas_b.shape:
        return False
    if projections_a.shape != projections_b.shape or alphas_a.ndim != 2:
        return False
    columns = _simple(values_b, 1e-5)
    signs = np.sign(np.sum(alphas_a * alphas_b, axis=0))
    signs = np.where(signs == 0, 1.0, signs)
    return same(alphas_a[:, columns] * signs[columns], alphas_b[:, columns], rtol=1e-4, atol=1e-6) and same(
        projections_a[:, columns] * signs[columns], projections_b[:, columns], rtol=1e-4, atol=1e-6
    )


def _lecture_centring(raw):
    ones = np.full_like(raw, 1.0 / len(raw))
    return raw - 2 * ones @ raw + ones @ raw @ ones


def _lecture_centring_variants(points, n_components, kernel="gaussian", beta=1.0, degree=2):
    # eigh reads the lower triangle (its default) or the upper one of the unsymmetric matrix.
    lower = _kernel_pca(points, n_components, kernel, beta, degree, gram=_lecture_centring)
    upper = _kernel_pca(points, n_components, kernel, beta, degree, gram=lambda raw: _lecture_centring(raw).T)
    return Variants([lower, upper])


KERNEL_PCA = Model(
    truth=kernel_pca_truth,
    same=kernel_pca_same,
    output_dtypes=("float64", "float64", "float64"),
    mistakes=(
        Mistake(
            "ascending_order",
            "you kept the SMALLEST components: np.linalg.eigh sorts ascending, so take its last n_components "
            "eigenpairs and reverse them",
            lambda points, n_components, kernel="gaussian", beta=1.0, degree=2: _kernel_pca(
                points, n_components, kernel, beta, degree, order="smallest"
            ),
        ),
        Mistake(
            "eigenvalues_divided_by_n",
            "your eigenvalues are those of K~ / N, N times too small: the contract's eigenvalues are K~'s own",
            lambda points, n_components, kernel="gaussian", beta=1.0, degree=2: _kernel_pca(
                points, n_components, kernel, beta, degree, scale=len(points)
            ),
        ),
        Mistake(
            "lecture_centring",
            "centre the Gram matrix as K - 1_N K - K 1_N + 1_N K 1_N (1_N: the N x N matrix of 1/N); "
            "the slides' 'K - 2 (1/N) K + ...' read as matrices is not symmetric and wrong",
            _lecture_centring_variants,
        ),
        Mistake(
            "uncentred_gram",
            "the Gram matrix must be centred in feature space before the eigendecomposition: "
            "K~ = K - 1_N K - K 1_N + 1_N K 1_N",
            lambda points, n_components, kernel="gaussian", beta=1.0, degree=2: _kernel_pca(
                points, n_components, kernel, beta, degree, gram=lambda raw: raw
            ),
        ),
        Mistake(
            "unit_eigenvectors",
            "scale each eigenvector a_r to squared norm 1/lambda_r (divide eigh's unit vectors by "
            "sqrt(lambda_r)): your projections are off by sqrt(lambda_r)",
            lambda points, n_components, kernel="gaussian", beta=1.0, degree=2: _kernel_pca(
                points, n_components, kernel, beta, degree, unit=True
            ),
        ),
    ),
)


# -- kernel_pca_transform ---------------------------------------------------------------------


def kernel_pca_transform_truth(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2, centring="train"):
    train = kernel_truth(points, points, kernel, beta, degree)
    rows = kernel_truth(new_points, points, kernel, beta, degree)
    weights = np.asarray(alphas, dtype=float)
    if weights.ndim != 2 or weights.shape[0] != train.shape[0]:
        raise ValueError("alphas do not fit")
    if centring == "train":
        rows = rows - rows.mean(axis=1)[:, None] - train.mean(axis=0)[None, :] + train.mean()
    elif centring == "own":
        rows = _double_centred(rows)
    return rows @ weights


KERNEL_PCA_TRANSFORM = Model(
    truth=kernel_pca_transform_truth,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "no_centring",
            "centre the new kernel rows before projecting: subtract their row means and the training Gram "
            "matrix's column means, add its grand mean",
            lambda new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2: kernel_pca_transform_truth(
                new_points, points, alphas, kernel, beta, degree, centring="none"
            ),
        ),
        Mistake(
            "own_column_means",
            "centre the new rows against the TRAINING Gram matrix (its column means and grand mean), "
            "not against the new rows' own column means",
            lambda new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2: kernel_pca_transform_truth(
                new_points, points, alphas, kernel, beta, degree, centring="own"
            ),
        ),
    ),
)


MODELS = {
    "pca": PCA,
    "kernel_matrix": KERNEL_MATRIX,
    "kernel_pca": KERNEL_PCA,
    "kernel_pca_transform": KERNEL_PCA_TRANSFORM,
}
