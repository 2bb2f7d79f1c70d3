"""Graded tests of ``kernel_matrix``, ``kernel_pca`` and ``kernel_pca_transform``
(``pcl_course/pca.py``).

Expected values come from the kernels' closed forms, from linear PCA (the
linear kernel must reproduce it) and from scikit-learn's ``KernelPCA``.
Components are compared up to sign. The test data have well-separated
eigenvalues, so every component is unique up to sign.
"""

import numpy as np
import pytest
from sklearn.decomposition import KernelPCA
from sklearn.metrics import pairwise

from grading.checks import check_array, check_close, check_finite, raises


def sklearn_kernel(x, y, kernel, beta=1.0, degree=2):
    """The contract's kernels, computed by scikit-learn."""
    if kernel == "linear":
        return pairwise.linear_kernel(x, y)
    if kernel == "polynomial":
        return pairwise.polynomial_kernel(x, y, degree=degree, gamma=1.0, coef0=1.0)
    if kernel == "gaussian":
        return pairwise.rbf_kernel(x, y, gamma=beta)
    return pairwise.laplacian_kernel(x, y, gamma=beta)


class SklearnKPCA:
    """scikit-learn's KernelPCA on the contract's kernels (precomputed)."""

    def __init__(self, points, n_components, kernel, beta=1.0, degree=2):
        self.points, self.args = points, (kernel, beta, degree)
        self.model = KernelPCA(n_components=n_components, kernel="precomputed", eigen_solver="dense")
        self.projections = self.model.fit_transform(sklearn_kernel(points, points, *self.args))
        self.eigenvalues = self.model.eigenvalues_

    def transform(self, new_points):
        return self.model.transform(sklearn_kernel(new_points, self.points, *self.args))


def align_signs(actual, expected):
    """Flip each column of ``actual`` to agree in sign with ``expected``."""
    signs = np.sign(np.sum(actual * expected, axis=0))
    signs[signs == 0] = 1.0
    return actual * signs


@pytest.fixture
def blob():
    """60 points of an anisotropic 2-D blob with a bend: no symmetry, distinct eigenvalues."""
    rng = np.random.default_rng(21)
    t = rng.uniform(-1.0, 1.0, 60)
    points = np.column_stack([t * 1.5, 0.6 * t**2 + 0.25 * rng.standard_normal(60)])
    return points + [0.3, -0.2]


# --- kernel_matrix ---------------------------------------------------------


@pytest.mark.grades("kernel_matrix")
@pytest.mark.points(2)
@pytest.mark.parametrize("kernel", ["linear", "polynomial", "gaussian", "laplacian"])
def test_kernel_matrix_closed_forms(impl, kernel):
    x = np.array([[0.0, 0.0], [1.0, 2.0], [-1.0, 0.5]])
    y = np.array([[1.0, 1.0], [0.5, -1.0]])
    beta, degree = 0.7, 3
    dot = x @ y.T
    diff = x[:, None, :] - y[None, :, :]
    expected = {
        "linear": dot,
        "polynomial": (1.0 + dot) ** degree,
        "gaussian": np.exp(-beta * np.sum(diff**2, axis=2)),
        "laplacian": np.exp(-beta * np.sum(np.abs(diff), axis=2)),
    }[kernel]
    result = impl.kernel_matrix(x, y, kernel=kernel, beta=beta, degree=degree)
    check_array(result, "K", shape=(3, 2))
    hint = {
        "gaussian": "gaussian: exp(-beta * ||x - y||_2 ** 2), with the square",
        "laplacian": "laplacian: exp(-beta * ||x - y||_1), the L1 norm",
    }.get(kernel, "")
    check_close(result, expected, f"kernel_matrix(kernel={kernel!r})", hint=hint)


@pytest.mark.grades("kernel_matrix")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kernel_matrix_rejects_unknown_kernel_and_bad_beta(impl):
    x = np.zeros((2, 2))
    with raises(ValueError, naming="kernel"):
        impl.kernel_matrix(x, x, kernel="sigmoid")
    with raises(ValueError, naming="beta"):
        impl.kernel_matrix(x, x, kernel="gaussian", beta=0.0)


# --- kernel_pca -------------------------------------------------------------


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kernel_pca_returns_arrays_of_the_right_shapes(impl, blob):
    result = impl.kernel_pca(blob, 3)
    assert isinstance(result, tuple) and len(result) == 3, "kernel_pca returns (projections, eigenvalues, alphas)"
    projections, eigenvalues, alphas = result
    check_array(projections, "projections", shape=(60, 3))
    check_array(eigenvalues, "eigenvalues", shape=(3,))
    check_array(alphas, "alphas", shape=(60, 3))


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(3)
@pytest.mark.parametrize("kernel", ["gaussian", "polynomial", "laplacian"])
def test_kernel_pca_eigenvalues_match_sklearn(impl, blob, kernel):
    expected = SklearnKPCA(blob, 4, kernel, beta=0.8).eigenvalues
    _, eigenvalues, _ = impl.kernel_pca(blob, 4, kernel=kernel, beta=0.8)
    check_close(
        eigenvalues,
        expected,
        "eigenvalues",
        rtol=1e-6,
        hint="eigenvalues of K~ = K - 1_N K - K 1_N + 1_N K 1_N, not divided by N, descending",
    )


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(3)
@pytest.mark.parametrize("kernel", ["gaussian", "polynomial"])
def test_kernel_pca_projections_match_sklearn(impl, blob, kernel):
    expected = SklearnKPCA(blob, 3, kernel, beta=0.8).projections
    projections, _, _ = impl.kernel_pca(blob, 3, kernel=kernel, beta=0.8)
    check_close(
        align_signs(projections, expected),
        expected,
        "projections (up to sign)",
        rtol=1e-5,
        atol=1e-8,
        hint="projections = K~ @ alphas with ||alphas[:, r]||^2 = 1 / eigenvalues[r]",
    )


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(2)
def test_kernel_pca_alphas_are_scaled_eigenvectors(impl, blob):
    projections, eigenvalues, alphas = impl.kernel_pca(blob, 3, kernel="gaussian", beta=0.5)
    check_finite(eigenvalues, "eigenvalues")
    check_finite(alphas, "alphas")
    check_close(
        np.sum(alphas**2, axis=0),
        1.0 / eigenvalues,
        "||alphas[:, r]||^2",
        rtol=1e-6,
        hint="scale each unit eigenvector by 1 / sqrt(eigenvalue)",
    )
    k = np.exp(-0.5 * np.sum((blob[:, None] - blob[None]) ** 2, axis=2))
    n = len(blob)
    one = np.full((n, n), 1.0 / n)
    centred = k - one @ k - k @ one + one @ k @ one
    check_close(
        centred @ alphas,
        alphas * eigenvalues,
        "K~ @ alphas[:, r] vs eigenvalues[r] * alphas[:, r]",
        rtol=1e-6,
        atol=1e-9,
    )
    check_close(projections, centred @ alphas, "projections vs K~ @ alphas", rtol=1e-6, atol=1e-9)


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(2)
def test_kernel_pca_with_the_linear_kernel_is_linear_pca(impl):
    rng = np.random.default_rng(22)
    points = rng.standard_normal((50, 3)) * [3.0, 1.5, 0.5] + [10.0, -4.0, 2.0]
    projections, eigenvalues, _ = impl.kernel_pca(points, 2, kernel="linear")
    centred = points - points.mean(axis=0)
    values, vectors = np.linalg.eigh(centred.T @ centred / len(points))
    values, vectors = values[::-1], vectors[:, ::-1]
    check_close(
        eigenvalues,
        len(points) * values[:2],
        "eigenvalues (linear kernel)",
        rtol=1e-6,
        hint="the centred Gram matrix's eigenvalues are N times the covariance's",
    )
    expected = centred @ vectors[:, :2]
    check_close(
        align_signs(projections, expected),
        expected,
        "projections (linear kernel)",
        rtol=1e-6,
        atol=1e-8,
        hint="with the linear kernel the projections are the linear-PCA coordinates",
    )


@pytest.mark.grades("kernel_pca")
@pytest.mark.points(1)
@pytest.mark.interface
def test_kernel_pca_rejects_bad_n_components(impl, blob):
    for bad in (0, 61):
        with raises(ValueError, naming="n_components"):
            impl.kernel_pca(blob, bad)


# --- kernel_pca_transform ----------------------------------------------------


@pytest.mark.grades("kernel_pca_transform")
@pytest.mark.points(2)
def test_kernel_pca_transform_of_the_training_points_gives_the_projections(impl, blob):
    projections, _, alphas = impl.kernel_pca(blob, 3, kernel="gaussian", beta=0.8)
    result = impl.kernel_pca_transform(blob, blob, alphas, kernel="gaussian", beta=0.8)
    check_array(result, "projections", shape=(60, 3))
    check_close(result, projections, "kernel_pca_transform(points, points, alphas)", rtol=1e-6, atol=1e-9)


@pytest.mark.grades("kernel_pca_transform")
@pytest.mark.points(3)
@pytest.mark.parametrize("kernel", ["gaussian", "laplacian"])
def test_kernel_pca_transform_of_new_points_matches_sklearn(impl, blob, kernel):
    rng = np.random.default_rng(23)
    new_points = rng.uniform(-2.0, 2.0, size=(7, 2)) + [1.0, 0.5]
    model = SklearnKPCA(blob, 3, kernel, beta=0.8)
    projections, _, alphas = impl.kernel_pca(blob, 3, kernel=kernel, beta=0.8)
    signs = np.sign(np.sum(projections * model.projections, axis=0))
    result = impl.kernel_pca_transform(new_points, blob, alphas, kernel=kernel, beta=0.8)
    check_array(result, "projections", shape=(7, 3))
    check_close(
        result * signs,
        model.transform(new_points),
        "projections of new points",
        rtol=1e-5,
        atol=1e-8,
        hint="centre the new kernel rows with THEIR row means and the TRAINING K's column and grand means",
    )


@pytest.mark.grades("kernel_pca_transform")
@pytest.mark.points(2)
def test_kernel_pca_transform_of_one_new_point_with_the_linear_kernel(impl):
    rng = np.random.default_rng(24)
    points = rng.standard_normal((40, 3)) * [2.0, 1.0, 0.4] + [1.0, 2.0, 3.0]
    new_point = np.array([[4.0, -1.0, 2.5]])
    projections, _, alphas = impl.kernel_pca(points, 2, kernel="linear")
    result = impl.kernel_pca_transform(new_point, points, alphas, kernel="linear")
    centred = points - points.mean(axis=0)
    vectors = np.linalg.eigh(centred.T @ centred)[1][:, ::-1][:, :2]
    signs = np.sign(np.sum(projections * (centred @ vectors), axis=0))
    check_close(
        result * signs,
        (new_point - points.mean(axis=0)) @ vectors,
        "projection of a new point (linear kernel)",
        rtol=1e-6,
        atol=1e-9,
        hint="a new point is centred with the TRAINING mean: x - m, projected on the principal axes",
    )
