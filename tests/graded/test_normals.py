"""Graded tests of ``fit_plane`` and ``estimate_normals`` (``pcl_course/normals.py``).

Expected values come from geometry (planes and spheres with known normals,
hand-built neighbourhoods), from NumPy's eigen-decomposition of covariances
the test forms itself, and from scikit-learn's neighbours (checked
against Open3D by the project's tests). Normals are compared up to sign
unless a viewpoint fixes it.
"""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from grading.checks import check_array, check_close, raises


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def abs_cos(a, b):
    return np.abs(np.sum(unit(a) * unit(b), axis=-1))


def plane_points(n, normal, offset, rng, spread=1.0):
    normal = unit(normal)
    u = unit(np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0]))
    v = np.cross(normal, u)
    coords = rng.uniform(-spread, spread, size=(n, 2)) * [1.0, 0.4]  # anisotropic in the plane
    return offset + coords[:, :1] * u + coords[:, 1:] * v


def sphere_points(n, rng, radius=2.0, centre=(0.0, 0.0, 0.0)):
    directions = unit(rng.standard_normal((n, 3)))
    return np.asarray(centre) + radius * directions, directions


# --- fit_plane -----------------------------------------------------------


@pytest.mark.grades("fit_plane")
@pytest.mark.points(2)
def test_fit_plane_recovers_a_known_plane(impl):
    rng = np.random.default_rng(0)
    normal = unit([1.0, -2.0, 0.5])
    points = plane_points(200, normal, np.array([3.0, -1.0, 7.0]), rng)
    centroid, result = impl.fit_plane(points)
    check_array(centroid, "centroid", shape=(3,))
    check_array(result, "normal", shape=(3,))
    check_close(centroid, points.mean(axis=0), "centroid")
    check_close(np.linalg.norm(result), 1.0, "||normal||")
    assert abs_cos(result, normal) > 1 - 1e-9, (
        f"normal {result.round(4)} is not the plane's normal {normal.round(4)} (up to sign); "
        "hint: the normal is the eigenvector of the SMALLEST eigenvalue, a COLUMN of eigh's output"
    )


@pytest.mark.grades("fit_plane")
@pytest.mark.points(2)
def test_fit_plane_normal_is_the_least_variance_direction_of_noisy_points(impl):
    rng = np.random.default_rng(1)
    points = rng.standard_normal((300, 3)) @ np.diag([3.0, 1.5, 0.2]) @ unit(rng.standard_normal((3, 3))).T
    points += [10.0, 20.0, -5.0]
    _, normal = impl.fit_plane(points)
    centred = points - points.mean(axis=0)
    expected = np.linalg.eigh(centred.T @ centred)[1][:, 0]
    assert abs_cos(normal, expected) > 1 - 1e-9, (
        f"normal {normal.round(4)} is not the least-variance direction {expected.round(4)} (up to sign)"
    )


@pytest.mark.grades("fit_plane")
@pytest.mark.points(2)
def test_fit_plane_uses_the_weights(impl):
    rng = np.random.default_rng(2)
    normal = unit([0.3, 0.2, 1.0])
    on_plane = plane_points(50, normal, np.zeros(3), rng)
    off_plane = rng.uniform(-1, 1, size=(10, 3)) + 3.0 * normal  # far from the plane
    points = np.vstack([on_plane, off_plane])
    weights = np.concatenate([rng.uniform(0.5, 2.0, 50), np.zeros(10)])
    centroid, result = impl.fit_plane(points, weights)
    check_close(
        centroid,
        weights @ points / weights.sum(),
        "weighted centroid",
        hint="the centroid is the WEIGHTED mean sum(w x) / sum(w)",
    )
    assert abs_cos(result, normal) > 1 - 1e-9, "points of weight 0 must not move the plane"
    # scaling all weights changes nothing
    centroid2, result2 = impl.fit_plane(points, weights * 7.5)
    check_close(centroid2, centroid, "centroid with weights x 7.5")
    assert abs_cos(result2, result) > 1 - 1e-9


@pytest.mark.points(1)
@pytest.mark.parametrize(
    "weights",
    [
        "negative",
        "zero-sum",
        "wrong-length",
    ],
)
@pytest.mark.grades("fit_plane")
@pytest.mark.interface
def test_fit_plane_rejects_bad_weights(impl, weights):
    points = np.random.default_rng(3).standard_normal((6, 3))
    bad = {"negative": [1, 1, -1, 1, 1, 1], "zero-sum": np.zeros(6), "wrong-length": np.ones(5)}[weights]
    with raises(ValueError, naming="weights"):
        impl.fit_plane(points, bad)


# --- estimate_normals ------------------------------------------------------


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(1)
def test_estimate_normals_returns_unit_float64_arrays(impl):
    rng = np.random.default_rng(4)
    points, _ = sphere_points(300, rng)
    result = impl.estimate_normals(points, k=10)
    assert isinstance(result, tuple) and len(result) == 2, "estimate_normals must return (normals, curvature)"
    normals, curvature = result
    check_array(normals, "normals", shape=(300, 3))
    check_array(curvature, "curvature", shape=(300,))
    check_close(np.linalg.norm(normals, axis=1), np.ones(300), "||normals||", atol=1e-9)


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(3)
def test_estimate_normals_of_a_whole_cloud_neighbourhood(impl):
    # With k = N every neighbourhood is the whole cloud: every normal is the
    # least-variance direction of the cloud, every curvature l_min / trace.
    rng = np.random.default_rng(5)
    rotation = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    points = rng.standard_normal((40, 3)) * [2.0, 1.0, 0.3] @ rotation.T + [5.0, -3.0, 8.0]
    normals, curvature = impl.estimate_normals(points, k=40)
    values, vectors = np.linalg.eigh(np.cov(points.T, bias=True))
    assert np.all(abs_cos(normals, vectors[:, 0]) > 1 - 1e-8), (
        f"normal {normals[0].round(4)} is not the least-variance direction {vectors[:, 0].round(4)}; "
        "hint: smallest eigenvalue, a COLUMN of the eigenvector matrix, neighbourhood centred on its mean"
    )
    check_close(
        curvature, np.full(40, values[0] / values.sum()), "curvature", hint="curvature = l_min / (l_1 + l_2 + l_3)"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_on_a_sphere_match_the_true_normals(impl):
    rng = np.random.default_rng(6)
    points, truth = sphere_points(2000, rng)
    normals, curvature = impl.estimate_normals(points, k=15)
    errors = np.degrees(np.arccos(np.clip(abs_cos(normals, truth), 0, 1)))
    # Measured with the reference: median 1.0 deg, max 4.6 deg (sampling noise
    # and the sphere's curvature over the patch); a wrong eigenvector is ~90 deg off.
    assert np.median(errors) < 3.0 and errors.max() < 15.0, (
        f"angular error to the true sphere normals: median {np.median(errors):.2f} deg, max {errors.max():.2f} deg"
    )
    assert np.all((curvature > 0) & (curvature < 0.05)), "curvature of a sphere patch must be small and positive"


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_on_a_plane_are_exact_and_flat(impl):
    rng = np.random.default_rng(7)
    normal = unit([2.0, 1.0, 3.0])
    points = plane_points(500, normal, np.array([1.0, 2.0, 3.0]), rng)
    normals, curvature = impl.estimate_normals(points, k=8)
    assert np.all(abs_cos(normals, normal) > 1 - 1e-9), "normals of a plane must be the plane's normal"
    check_close(curvature, np.zeros(500), "curvature of a plane", atol=1e-9)


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_far_from_the_origin(impl):
    # One-pass covariance E[pp^T] - mu mu^T cancels catastrophically here.
    rng = np.random.default_rng(8)
    normal = unit([0.2, -0.4, 1.0])
    points = plane_points(400, normal, np.array([1.0e6, -2.0e6, 3.0e6]), rng, spread=0.2)
    points += rng.normal(scale=1e-4, size=points.shape)
    normals, _ = impl.estimate_normals(points, k=20)
    errors = np.degrees(np.arccos(np.clip(abs_cos(normals, normal), 0, 1)))
    assert errors.max() < 2.0, (
        f"normals of a plane at 1e6 m are off by up to {errors.max():.1f} deg; "
        "hint: centre each neighbourhood on its mean before multiplying (two-pass covariance)"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_neighbourhood_includes_the_point_itself(impl):
    # With k = 3 the neighbourhood of p is {p, a, b}: its plane contains p.
    rng = np.random.default_rng(9)
    points = rng.uniform(size=(30, 3))
    normals, _ = impl.estimate_normals(points, k=3)
    order = np.argsort(cdist(points, points), axis=1)
    a, b = points[order[:, 1]], points[order[:, 2]]
    expected = unit(np.cross(a - points, b - points))
    assert np.all(abs_cos(normals, expected) > 1 - 1e-6), (
        "with k=3 the normal must be perpendicular to the plane through the point and its 2 nearest "
        "other points: the neighbourhood includes the point itself"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(1)
def test_estimate_normals_with_a_radius_is_inclusive(impl):
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0], [5.0, 5, 5]])
    normals, curvature = impl.estimate_normals(points, k=None, radius=1.0)
    assert np.allclose(abs_cos(normals[0], [0, 0, 1]), 1.0), (
        "the points at distance exactly 1.0 are in the radius-1.0 neighbourhood (<= radius)"
    )
    assert np.all(np.isnan(normals[3])) and np.isnan(curvature[3]), (
        "an isolated point (fewer than 3 neighbours) must get a NaN normal and NaN curvature"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_radius_neighbourhood_matches_its_definition(impl):
    rng = np.random.default_rng(10)
    points = rng.uniform(size=(150, 3)) * [1.0, 1.0, 0.2]
    normals, curvature = impl.estimate_normals(points, k=None, radius=0.3)
    d = cdist(points, points)
    for i in range(0, 150, 7):
        members = points[d[i] <= 0.3]
        values, vectors = np.linalg.eigh(np.cov(members.T, bias=True))
        assert abs_cos(normals[i], vectors[:, 0]) > 1 - 1e-8, f"normal of point {i} (radius 0.3, k=None)"
        assert np.isclose(curvature[i], values[0] / values.sum(), rtol=1e-6, atol=1e-12)


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_hybrid_keeps_only_the_k_nearest(impl):
    # The 9 nearest points of the centre lie on z = 0; the radius also reaches
    # points far above and below, which k must exclude.
    grid = np.array([[x, y, 0.0] for x in (-0.1, 0.0, 0.1) for y in (-0.1, 0.0, 0.1)]) * [1.0, 1.3, 1.0]
    angles = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    ring = np.column_stack([0.3 * np.cos(angles), 0.3 * np.sin(angles), 0.6 * np.resize([1, -1], 8)])
    points = np.vstack([grid, ring])
    centre = 4  # (0, 0, 0)
    normals, _ = impl.estimate_normals(points, k=9, radius=1.0)
    assert abs_cos(normals[centre], [0, 0, 1]) > 1 - 1e-9, (
        "with k=9 and radius=1.0 the neighbourhood is the 9 nearest points within the radius"
    )
    normals_all, _ = impl.estimate_normals(points, k=None, radius=1.0)
    assert abs_cos(normals_all[centre], [0, 0, 1]) < 0.5, "with k=None every point within the radius counts"


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(1)
def test_estimate_normals_fewer_than_three_neighbours_give_nan(impl):
    points = np.random.default_rng(11).uniform(size=(20, 3))
    normals, curvature = impl.estimate_normals(points, k=2)
    assert np.all(np.isnan(normals)) and np.all(np.isnan(curvature)), (
        "a neighbourhood of fewer than 3 points must give a NaN normal and NaN curvature"
    )
    normals, curvature = impl.estimate_normals(points, k=3)
    assert np.all(np.isfinite(normals)) and np.all(np.isfinite(curvature)), (
        "with 3 neighbours (the point itself included) every normal and curvature must be finite"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(1)
def test_estimate_normals_curvature_is_zero_where_the_points_coincide(impl):
    # Three spots of four duplicates each (a scanner returns the same point several times): with k = 3,
    # every neighbourhood is one spot, whose covariance is 0.
    points = np.repeat([[0.0, 0.0, 0.0], [5.0, 1.0, 2.0], [1.0, 7.0, 3.0]], 4, axis=0)
    normals, curvature = impl.estimate_normals(points, k=3)
    check_close(
        curvature,
        np.zeros(12),
        "curvature",
        hint="where the trace l_1 + l_2 + l_3 is 0 the curvature is defined as 0, not 0 / 0 = NaN",
    )
    check_close(
        np.linalg.norm(normals, axis=1),
        np.ones(12),
        "norm of each normal",
        hint="3 neighbours define a normal, here any unit vector: it must not be NaN",
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_orients_towards_the_viewpoint(impl):
    rng = np.random.default_rng(12)
    points, truth = sphere_points(800, rng, centre=(1.0, 2.0, 3.0))
    for viewpoint, sign in (((1.0, 2.0, 3.0), -1.0), ((1.0, 2.0, 50.0), None)):
        normals, _ = impl.estimate_normals(points, k=12, viewpoint=np.array(viewpoint))
        facing = np.sum(normals * (np.asarray(viewpoint) - points), axis=1)
        assert np.all(facing >= 0), f"{np.sum(facing < 0)} normals point away from the viewpoint {viewpoint}"
        if sign is not None:  # viewpoint at the centre: every normal points inwards
            assert np.all(np.sum(normals * truth, axis=1) < -0.9)


def sklearn_normals(points, k):
    """Normals from scikit-learn's k nearest neighbours (the point itself
    included, ``NearestNeighbors``) and the least-variance eigenvector of each
    neighbourhood's covariance (NumPy's ``eigh``). tests/project/test_oracles.py
    checks them against Open3D's ``estimate_normals``."""
    from sklearn.neighbors import NearestNeighbors

    _, neighbours = NearestNeighbors(n_neighbors=k).fit(points).kneighbors(points)
    groups = points[neighbours] - points[neighbours].mean(axis=1, keepdims=True)
    return np.linalg.eigh(np.einsum("nki,nkj->nij", groups, groups))[1][:, :, 0]


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(2)
def test_estimate_normals_match_sklearn(impl):
    rng = np.random.default_rng(13)
    points, _ = sphere_points(1500, rng)
    points = points * [1.0, 0.7, 0.4] + rng.normal(scale=0.01, size=points.shape)
    normals, _ = impl.estimate_normals(points, k=20)
    agreement = abs_cos(normals, sklearn_normals(points, 20))
    assert np.mean(agreement > 1 - 1e-6) > 0.99, (
        f"only {np.mean(agreement > 1 - 1e-6):.1%} of the normals agree with the least-variance direction of "
        "each point's 20 nearest neighbours (itself included)"
    )


@pytest.mark.grades("estimate_normals")
@pytest.mark.points(1)
@pytest.mark.interface
def test_estimate_normals_of_an_empty_cloud(impl):
    normals, curvature = impl.estimate_normals(np.empty((0, 3)), k=5)
    check_array(normals, "normals", shape=(0, 3))
    check_array(curvature, "curvature", shape=(0,))


@pytest.mark.points(0.5)
@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"points": np.zeros((5, 2))}, "points"),
        ({"points": np.array([[0.0, 0, 0], [np.nan, 0, 0], [1, 1, 1]])}, "points"),
        ({"radius": 0.0, "k": None}, "radius"),
        ({"radius": -1.0}, "radius"),
        ({"k": 0}, "k"),
        ({"viewpoint": np.zeros(2)}, "viewpoint"),
    ],
    ids=["width", "nan", "radius-zero", "radius-negative", "k-zero", "viewpoint-shape"],
)
@pytest.mark.grades("estimate_normals")
@pytest.mark.interface
def test_estimate_normals_rejects_bad_input(impl, kwargs, name):
    arguments = {"points": np.random.default_rng(15).uniform(size=(10, 3)), "k": 5, **kwargs}
    with raises(ValueError, naming=name):
        impl.estimate_normals(**arguments)
