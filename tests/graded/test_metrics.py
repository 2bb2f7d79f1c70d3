"""Graded tests of ``chamfer_distance`` (``pcl_course/metrics.py``): hand-computed
cases and a brute-force check with SciPy's pairwise distances."""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from grading.checks import raises


@pytest.mark.grades("chamfer_distance")
@pytest.mark.points(2)
def test_chamfer_distance_hand_computed(impl):
    a = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    b = np.array([[0.0, 2.0, 0]])
    # a -> b: squared distances 4 and 5, mean 4.5; b -> a: nearest is (0,0,0), 4.
    result = impl.chamfer_distance(a, b)
    assert isinstance(result, float), f"chamfer_distance must return a Python float, got {type(result).__name__}"
    assert np.isclose(result, 8.5), (
        f"expected 4.5 + 4.0 = 8.5, got {result}: mean SQUARED nearest distances, both directions, summed"
    )


@pytest.mark.grades("chamfer_distance")
@pytest.mark.points(2)
def test_chamfer_distance_matches_brute_force(impl):
    rng = np.random.default_rng(41)
    a, b = rng.normal(size=(300, 3)), rng.normal(size=(200, 3)) + 0.5
    d = cdist(a, b, "sqeuclidean")
    expected = d.min(axis=1).mean() + d.min(axis=0).mean()
    assert np.isclose(impl.chamfer_distance(a, b), expected, rtol=1e-9)
    assert np.isclose(impl.chamfer_distance(b, a), expected, rtol=1e-9), "the Chamfer distance is symmetric"


@pytest.mark.grades("chamfer_distance")
@pytest.mark.points(1)
def test_chamfer_distance_of_identical_sets_is_zero(impl):
    a = np.random.default_rng(42).normal(size=(50, 3))
    assert impl.chamfer_distance(a, a[::-1]) == pytest.approx(0.0, abs=1e-12)
    # ... and only those: a unit grid moved by 0.1 is 0.1^2 away in both directions.
    grid = np.stack(np.meshgrid(*[np.arange(4.0)] * 3), axis=-1).reshape(-1, 3)
    assert impl.chamfer_distance(grid, grid + [0.1, 0.0, 0.0]) == pytest.approx(0.02, rel=1e-9), (
        "a unit grid and its copy moved by 0.1 along x: 0.01 + 0.01 = 0.02"
    )


@pytest.mark.grades("chamfer_distance")
@pytest.mark.points(1)
@pytest.mark.interface
def test_chamfer_distance_rejects_bad_input(impl):
    a = np.zeros((5, 3))
    with raises(ValueError, naming="b"):
        impl.chamfer_distance(a, np.zeros((5, 2)))
    with raises(ValueError):
        impl.chamfer_distance(np.array([[np.nan, 0.0, 0.0]]), a)


@pytest.mark.grades("depth_metrics")
@pytest.mark.points(2)
def test_depth_metrics_hand_computed(impl):
    gt = np.array([[2.0, 0.0], [4.0, 5.0]])  # metres; 0 = no ground truth
    pred = np.array([[2.5, 9.0], [4.0, 4.0]])
    # Errors at the valid pixels: 0.5, 0, -1 m; inverse errors -0.1, 0, 0.05 1/m.
    result = impl.depth_metrics(pred, gt)
    assert isinstance(result, dict) and set(result) >= {"rmse", "mae", "irmse", "imae"}, (
        "depth_metrics must return a dict with keys rmse, mae, irmse, imae"
    )
    expected = {
        "rmse": 1000 * np.sqrt(1.25 / 3),
        "mae": 500.0,
        "irmse": np.sqrt((100.0**2 + 50.0**2) / 3),
        "imae": 50.0,
    }
    for key, value in expected.items():
        assert np.isclose(result[key], value, rtol=1e-9), (
            f"{key}: expected {value:.4f}, got {result[key]!r}; units: rmse and mae in millimetres, "
            "irmse and imae in 1/km, over the pixels with gt > 0 only"
        )


@pytest.mark.grades("depth_metrics")
@pytest.mark.points(1)
def test_depth_metrics_of_a_perfect_prediction(impl):
    gt = np.random.default_rng(43).uniform(1.0, 80.0, size=(20, 30))
    gt[::3] = 0.0
    result = impl.depth_metrics(np.where(gt > 0, gt, 7.0), gt)
    assert all(abs(result[k]) < 1e-9 for k in ("rmse", "mae", "irmse", "imae")), result
    # ... and a prediction 1 m too far everywhere is 1000 mm off on every valid pixel.
    off = impl.depth_metrics(np.where(gt > 0, gt + 1.0, 7.0), gt)
    assert abs(off["rmse"] - 1000.0) < 1e-6 and abs(off["mae"] - 1000.0) < 1e-6, (
        f"a prediction 1 m too far must give rmse = mae = 1000 mm, got {off}"
    )
