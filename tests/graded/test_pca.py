"""Graded tests of ``pca`` (exercise module ``pcl_course/pca.py``).

Expected values come from closed forms (data built with a known covariance)
and from NumPy's covariance / correlation, never from the reference alone.
Eigenvectors are compared up to sign, as the contract allows.
"""

import numpy as np
import pytest

from grading.checks import (
    check_array,
    check_close,
    check_orthonormal_columns,
    check_unit_columns_match,
    raises,
)


def random_rotation(rng, d):
    """A random orthogonal matrix that is not symmetric."""
    q, r = np.linalg.qr(rng.standard_normal((d, d)))
    return q * np.sign(np.diag(r))


def cloud_with_covariance(n, variances, rotation, mean, rng):
    """``n`` points whose population covariance is exactly ``R diag(variances) R^T``."""
    d = len(variances)
    z = rng.standard_normal((n, d))
    z -= z.mean(axis=0)
    # Whiten so that z^T z / n is the identity to rounding error.
    z = z @ np.linalg.inv(np.linalg.cholesky(z.T @ z / n)).T
    return z * np.sqrt(variances) @ rotation.T + mean


def population_covariance(points):
    return np.cov(np.asarray(points, dtype=float).T, bias=True)


@pytest.fixture
def known():
    """A 3-D cloud with known principal axes, far from the origin, small N."""
    rng = np.random.default_rng(7)
    variances = np.array([9.0, 4.0, 1.0])
    rotation = random_rotation(rng, 3)
    mean = np.array([120.0, -45.0, 30.0])  # different per axis, and large
    points = cloud_with_covariance(8, variances, rotation, mean, rng)
    return points, variances, rotation


@pytest.mark.grades("pca")
@pytest.mark.points(1)
@pytest.mark.interface
def test_pca_returns_plain_float64_arrays(impl, known):
    points, _, _ = known
    result = impl.pca(points)
    assert isinstance(result, tuple) and len(result) == 2, (
        f"pca must return a tuple (eigenvalues, eigenvectors), got {type(result).__name__}"
    )
    check_array(result[0], "eigenvalues", shape=(3,))
    check_array(result[1], "eigenvectors", shape=(3, 3))


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_eigenvalues_match_known_variances(impl, known):
    points, variances, _ = known
    eigenvalues, _ = impl.pca(points)
    check_close(
        eigenvalues,
        variances,
        "eigenvalues",
        rtol=1e-6,
        hint="centre each column on its own mean, divide by N (not N - 1), sort descending",
    )


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_eigenvectors_are_the_principal_axes(impl, known):
    points, _, rotation = known
    _, eigenvectors = impl.pca(points)
    check_unit_columns_match(
        eigenvectors, rotation, "eigenvectors", hint="eigenvectors must be the COLUMNS, in the order of the eigenvalues"
    )


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_columns_satisfy_the_eigen_equation(impl):
    rng = np.random.default_rng(11)
    points = rng.standard_normal((200, 4)) @ rng.standard_normal((4, 4)) + [5.0, -2.0, 0.5, 9.0]
    eigenvalues, eigenvectors = impl.pca(points)
    h = population_covariance(points)
    # H @ 0 == 0 * lambda: the eigen-equation alone lets zero (or NaN) columns through.
    check_orthonormal_columns(
        eigenvectors,
        "eigenvectors",
        atol=1e-8,
        hint="the contract: eigenvectors are orthonormal columns (np.linalg.eigh gives them)",
    )
    check_close(
        h @ eigenvectors,
        eigenvectors * eigenvalues,
        "H @ eigenvectors",
        atol=1e-8,
        hint="H @ eigenvectors[:, i] must equal eigenvalues[i] * eigenvectors[:, i]",
    )


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_centres_each_column_on_its_own_mean(impl):
    rng = np.random.default_rng(3)
    points = rng.standard_normal((500, 3)) * [1.0, 2.0, 0.5] + [1000.0, -300.0, 50.0]
    eigenvalues, _ = impl.pca(points)
    expected = np.sort(np.linalg.eigvalsh(population_covariance(points)))[::-1]
    check_close(
        eigenvalues,
        expected,
        "eigenvalues",
        rtol=1e-6,
        hint="subtract each column's own mean (points.mean(axis=0)) before forming H",
    )


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_uses_population_normalisation(impl):
    rng = np.random.default_rng(5)
    points = rng.standard_normal((5, 3)) * [3.0, 2.0, 1.0]
    eigenvalues, _ = impl.pca(points)
    expected = np.sort(np.linalg.eigvalsh(population_covariance(points)))[::-1]
    check_close(eigenvalues, expected, "eigenvalues", rtol=1e-6, hint="H = X~^T X~ / N: divide by N, not N - 1")


@pytest.mark.grades("pca")
@pytest.mark.points(1)
def test_pca_sorts_eigenvalues_descending(impl):
    rng = np.random.default_rng(9)
    # The smallest variance is on x, the largest on z: an unsorted solver
    # returns them in axis order.
    points = rng.standard_normal((300, 3)) * [0.1, 1.0, 10.0]
    eigenvalues, eigenvectors = impl.pca(points)
    assert np.all(np.diff(eigenvalues) <= 0), (
        f"with sort=True eigenvalues must be in descending order, got {eigenvalues}"
    )
    assert abs(eigenvectors[2, 0]) > 0.99, "the first column must be the axis of largest variance (z)"


@pytest.mark.grades("pca")
@pytest.mark.points(1)
def test_pca_unsorted_result_is_still_an_eigendecomposition(impl):
    rng = np.random.default_rng(10)
    points = rng.standard_normal((100, 3)) * [0.5, 3.0, 1.0]
    eigenvalues, eigenvectors = impl.pca(points, sort=False)
    check_array(eigenvalues, "eigenvalues", shape=(3,))
    check_array(eigenvectors, "eigenvectors", shape=(3, 3))
    h = population_covariance(points)
    check_close(np.sort(eigenvalues), np.sort(np.linalg.eigvalsh(h)), "sorted eigenvalues", rtol=1e-6)
    # H @ 0 == 0 * lambda: without orthonormality, zero columns would pass the eigen-equation.
    check_orthonormal_columns(eigenvectors, "eigenvectors", atol=1e-8)
    check_close(h @ eigenvectors, eigenvectors * eigenvalues, "H @ eigenvectors", atol=1e-8)


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_eigenvectors_are_orthonormal_for_repeated_eigenvalues(impl):
    rng = np.random.default_rng(12)
    # Variances (4, 4, 1): a repeated eigenvalue, where np.linalg.eig may
    # return eigenvectors that are not orthogonal.
    points = cloud_with_covariance(60, [4.0, 4.0, 1.0], random_rotation(rng, 3), 0.0, rng)
    eigenvalues, eigenvectors = impl.pca(points)
    check_close(eigenvalues, [4.0, 4.0, 1.0], "eigenvalues", rtol=1e-6)
    check_close(
        eigenvectors.T @ eigenvectors,
        np.eye(3),
        "eigenvectors.T @ eigenvectors",
        atol=1e-8,
        hint="use a symmetric eigensolver (np.linalg.eigh): H is symmetric",
    )


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_correlation_matrix(impl):
    rng = np.random.default_rng(13)
    # Columns of very different scales: covariance and correlation differ.
    base = rng.standard_normal((400, 3))
    points = np.column_stack([base[:, 0] * 100.0, base[:, 0] + 0.5 * base[:, 1], base[:, 2] * 0.01])
    eigenvalues, eigenvectors = impl.pca(points, correlation=True)
    corr = np.corrcoef(points.T)
    check_close(
        eigenvalues,
        np.sort(np.linalg.eigvalsh(corr))[::-1],
        "eigenvalues",
        rtol=1e-6,
        hint="with correlation=True divide each centred column by its standard deviation",
    )
    check_orthonormal_columns(eigenvectors, "eigenvectors", atol=1e-8)
    check_close(corr @ eigenvectors, eigenvectors * eigenvalues, "R @ eigenvectors", atol=1e-8)


@pytest.mark.grades("pca")
@pytest.mark.points(1)
def test_pca_correlation_leaves_a_constant_column_at_zero(impl):
    rng = np.random.default_rng(14)
    points = np.column_stack([rng.standard_normal(50), np.full(50, 2.5), rng.standard_normal(50)])
    eigenvalues, eigenvectors = impl.pca(points, correlation=True)
    assert np.all(np.isfinite(eigenvalues)) and np.all(np.isfinite(eigenvectors)), (
        "a constant column must be left at zero, not divided by its zero standard deviation"
    )
    expected = np.linalg.eigvalsh(np.corrcoef(points[:, [0, 2]].T))[::-1]
    check_close(eigenvalues, [expected[0], expected[1], 0.0], "eigenvalues", atol=1e-9)


@pytest.mark.grades("pca")
@pytest.mark.points(1)
def test_pca_principal_axis_of_a_cylinder(impl):
    # Ground truth from geometry: a long thin cylinder's first principal axis
    # is its own axis, here the direction (1, 2, 2) / 3.
    rng = np.random.default_rng(15)
    t = rng.uniform(-5.0, 5.0, 2000)
    angle = rng.uniform(0.0, 2.0 * np.pi, 2000)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    u = np.array([2.0, -1.0, 0.0]) / np.sqrt(5.0)
    v = np.cross(axis, u)
    points = t[:, None] * axis + 0.3 * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
    _, eigenvectors = impl.pca(points + [10.0, 20.0, 30.0])
    check_orthonormal_columns(eigenvectors, "eigenvectors", atol=1e-8)
    assert abs(eigenvectors[:, 0] @ axis) > 0.999, (
        f"the first principal axis of a long cylinder along {axis.round(3)} must be that axis, "
        f"got {eigenvectors[:, 0].round(3)}"
    )


@pytest.mark.grades("pca")
@pytest.mark.points(1)
def test_pca_accepts_lists_and_other_dimensions(impl):
    points = [[0.0, 0.0], [2.0, 0.0], [0.0, 1.0], [2.0, 1.0]]  # variances 1 and 1/4
    eigenvalues, eigenvectors = impl.pca(points)
    check_array(eigenvalues, "eigenvalues", shape=(2,))
    check_array(eigenvectors, "eigenvectors", shape=(2, 2))
    check_close(eigenvalues, [1.0, 0.25], "eigenvalues")


@pytest.mark.points(0.5)
@pytest.mark.parametrize(
    "bad, why",
    [
        (np.zeros(6), "1-D"),
        (np.zeros((2, 3, 3)), "3-D"),
        (np.array([[0.0, 1.0, 2.0], [np.nan, 1.0, 0.0], [1.0, 1.0, 1.0]]), "NaN"),
        (np.array([[0.0, 1.0, 2.0], [np.inf, 1.0, 0.0], [1.0, 1.0, 1.0]]), "inf"),
    ],
    ids=["1d", "3d", "nan", "inf"],
)
@pytest.mark.grades("pca")
@pytest.mark.interface
def test_pca_rejects_bad_points(impl, bad, why):
    with raises(ValueError, naming="points"):  # the input is bad by `why` (the test id says which)
        impl.pca(bad)
