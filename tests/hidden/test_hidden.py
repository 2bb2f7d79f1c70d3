"""Hidden graded tests: they run only when an instructor grades (python -m
grading grade), never ship in the student release, and their feedback shows
no expected values. They test the same contract as the public tests, on
inputs the students have not seen."""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from grading.checks import check_close, check_orthonormal_columns

# Run by the instructors' grader only; feedback withholds expected values.
pytestmark = pytest.mark.hidden


@pytest.mark.grades("pca")
@pytest.mark.points(2)
def test_pca_hidden_random_clouds(impl):
    rng = np.random.default_rng(2026)
    for d in (2, 3, 6):
        points = rng.standard_normal((40, d)) @ rng.standard_normal((d, d)) + rng.uniform(-50, 50, d)
        eigenvalues, eigenvectors = impl.pca(points)
        h = np.cov(points.T, bias=True)
        check_close(eigenvalues, np.sort(np.linalg.eigvalsh(h))[::-1], "eigenvalues", rtol=1e-6)
        check_orthonormal_columns(eigenvectors, "eigenvectors")
        check_close(h @ eigenvectors, eigenvectors * eigenvalues, "H @ eigenvectors", atol=1e-7)


@pytest.mark.grades("chamfer_distance")
@pytest.mark.points(2)
def test_chamfer_distance_hidden_random_sets(impl):
    rng = np.random.default_rng(2027)
    a, b = rng.uniform(size=(123, 3)), rng.uniform(size=(77, 3)) * 2
    d = cdist(a, b, "sqeuclidean")
    assert np.isclose(impl.chamfer_distance(a, b), d.min(1).mean() + d.min(0).mean(), rtol=1e-9)


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(2)
def test_radius_outlier_removal_hidden_random_cloud(impl):
    rng = np.random.default_rng(2028)
    points = np.vstack([rng.normal(size=(300, 3)), rng.uniform(-5, 5, size=(30, 3))])
    expected = (cdist(points, points) <= 0.4).sum(axis=1) - 1 >= 2
    check_close(impl.radius_outlier_removal(points, 0.4, 2), expected, "keep mask")
