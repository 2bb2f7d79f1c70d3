"""Graded tests of the filters (``pcl_course/filters.py``).

Expected values come from hand-built clouds and images, from the filters'
formulas evaluated by the test at single pixels and points, from brute-force
pairwise distances (SciPy ``cdist``) and from properties: a constant image is
unchanged, a step edge survives, points on a plane stay on it.
"""

import math

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from grading.checks import check_array, check_close, raises

# --- radius_outlier_removal ------------------------------------------------------


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(1)
def test_radius_outlier_removal_counts_a_neighbour_at_exactly_the_radius(impl):
    # A chain 0, 1, 2 with spacing exactly 1.0: each point has a neighbour at distance 1.0.
    points = np.column_stack([np.array([0.0, 1.0, 2.0]), np.zeros(3), np.zeros(3)])
    keep = impl.radius_outlier_removal(points, 1.0, 1)
    check_array(keep, "keep", shape=(3,), dtype="bool")
    assert keep.tolist() == [True, True, True], (
        f"got {keep.tolist()}: a neighbour at distance exactly 1.0 counts (distance <= radius, not <)"
    )


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(1)
def test_radius_outlier_removal_does_not_count_the_point_itself(impl):
    # On a line: 0, 1, 2 are a chain (spacing 1), 5 is alone, 10 and 10 coincide.
    x = np.array([0.0, 1.0, 2.0, 5.0, 10.0, 10.0])
    points = np.column_stack([x, np.zeros(6), np.zeros(6)])
    keep = impl.radius_outlier_removal(points, 1.5, 1)
    check_array(keep, "keep", shape=(6,), dtype="bool")
    assert keep.tolist() == [True, True, True, False, True, True], (
        f"got {keep.tolist()}: the point alone at 5 has no OTHER point within 1.5 (it does not count itself); "
        "a duplicate of a point is another point"
    )
    keep = impl.radius_outlier_removal(points, 1.5, 2)
    check_array(keep, "keep", shape=(len(points),), dtype=None)  # before any .tolist()
    assert keep.tolist() == [False, True, False, False, False, False], (
        f"with min_neighbors=2 only the middle of the chain has 2 OTHER points within 1.5, got {keep.tolist()}"
    )


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(2)
def test_radius_outlier_removal_matches_brute_force(impl):
    rng = np.random.default_rng(51)
    points = np.vstack([rng.normal(size=(400, 3)), rng.uniform(-6, 6, size=(40, 3))])
    d = cdist(points, points)
    expected = (d <= 0.5).sum(axis=1) - 1 >= 3
    check_close(impl.radius_outlier_removal(points, 0.5, 3), expected, "keep mask")


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(0.5)
@pytest.mark.interface
def test_radius_outlier_removal_on_an_empty_cloud(impl):
    check_array(impl.radius_outlier_removal(np.empty((0, 3)), 1.0, 2), "keep", shape=(0,), dtype="bool")


@pytest.mark.grades("radius_outlier_removal")
@pytest.mark.points(0.5)
@pytest.mark.interface
def test_radius_outlier_removal_rejects_a_bad_radius(impl):
    with raises(ValueError, naming="radius"):
        impl.radius_outlier_removal(np.zeros((3, 3)), 0.0, 2)


# --- statistical_outlier_removal ----------------------------------------------------


def mean_distances(points, k):
    """Mean distance to the k nearest OTHER points (by index), brute force."""
    d = cdist(points, points)
    np.fill_diagonal(d, np.inf)
    return np.sort(d, axis=1)[:, :k].mean(axis=1)


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(3)
def test_statistical_outlier_removal_matches_its_definition(impl):
    rng = np.random.default_rng(52)
    points = np.vstack([rng.normal(size=(300, 3)), rng.uniform(-8, 8, size=(15, 3))])
    mean_d = mean_distances(points, 6)
    expected = mean_d <= mean_d.mean() + 1.0 * mean_d.std(ddof=1)
    keep = impl.statistical_outlier_removal(points, 6, 1.0)
    check_array(keep, "keep", shape=(315,), dtype="bool")
    wrong = np.flatnonzero(keep != expected)
    assert not wrong.size, (
        f"{wrong.size} points decided differently from the definition, e.g. point {wrong[:1].tolist()}; "
        "d_i = MEAN distance to the k nearest OTHER points; keep d_i <= mu + std_ratio * sigma (ddof=1)"
    )


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(1)
def test_statistical_outlier_removal_with_every_other_point_as_a_neighbour(impl):
    # k = N - 1, the largest k the contract allows: d_i is the mean distance to ALL other points.
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 12.0])
    points = np.column_stack([x, np.zeros(6), np.zeros(6)])
    mean_d = np.abs(x[:, None] - x[None, :]).sum(axis=1) / 5  # 4.4, 3.6, 3.2, 3.2, 3.6, 10.0
    expected = mean_d <= mean_d.mean() + 1.0 * mean_d.std(ddof=1)
    keep = impl.statistical_outlier_removal(points, 5, 1.0)
    check_array(keep, "keep", shape=(6,), dtype="bool")
    assert keep.tolist() == expected.tolist() == [True] * 5 + [False], (
        f"with k = N - 1 = 5 (allowed: every other point is a neighbour) expected {expected.tolist()}, "
        f"got {keep.tolist()}"
    )


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(2)
def test_statistical_outlier_removal_hand_built(impl):
    # Six points on a line, k = 1: nearest-other distances 1, 1, 1, 1, 1, 4.
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 8.0])
    points = np.column_stack([x, np.zeros(6), np.zeros(6)])
    # mean 1.5, sample std sqrt(1.5) = 1.2247: threshold at std_ratio 1 is 2.72
    keep = impl.statistical_outlier_removal(points, 1, 1.0)
    check_array(keep, "keep", shape=(len(points),), dtype=None)  # before any .tolist()
    assert keep.tolist() == [True] * 5 + [False], f"expected only the last point removed, got {keep.tolist()}"


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(2)
def test_statistical_outlier_removal_counts_duplicates_not_itself(impl):
    # Points 0 and 1 coincide: each is the other's nearest neighbour at 0.
    x = np.array([0.0, 0.0, 3.0, 6.0, 9.0, 12.0, 15.0])
    points = np.column_stack([x, np.zeros(7), np.zeros(7)])
    # k = 1: d = 0, 0, 3, 3, 3, 3, 3 -> mean 15/7, sample std 1.5119;
    # threshold at std_ratio 0.5 = 2.898: the five spaced points are removed.
    keep = impl.statistical_outlier_removal(points, 1, 0.5)
    check_array(keep, "keep", shape=(len(points),), dtype=None)  # before any .tolist()
    assert keep.tolist() == [True, True, False, False, False, False, False], (
        f"got {keep.tolist()}: a duplicate of point i is a neighbour at distance 0, the point itself is not"
    )


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(2)
def test_statistical_outlier_removal_is_one_sided(impl):
    # A tight clump inside a sparse cloud has a mean distance far BELOW mu:
    # the lecture's two-sided variant would remove it, the filter must not.
    rng = np.random.default_rng(53)
    sparse = rng.uniform(-5, 5, size=(200, 3))
    clump = rng.normal(scale=0.01, size=(10, 3))
    points = np.vstack([sparse, clump])
    keep = impl.statistical_outlier_removal(points, 4, 1.0)
    check_array(keep, "keep", shape=(210,), dtype="bool")
    mean_d = mean_distances(points, 4)
    assert np.all(mean_d[-10:] < mean_d.mean() - 1.0 * mean_d.std(ddof=1)), "test set-up"
    assert keep[-10:].all(), "points with a small mean distance (a dense clump) must be kept: one-sided test"
    far = mean_d > mean_d.mean() + 1.0 * mean_d.std(ddof=1)
    assert far.any() and not keep[far].any(), "points with a mean distance above mu + std_ratio * sigma go"


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(2)
def test_statistical_outlier_removal_uses_the_sample_standard_deviation(impl):
    # k = 1 on a line: d = 1, 1, 1, 1, 2.5. The last point's z-score is 2.0
    # with the population std (ddof=0) and 1.79 with the sample std (ddof=1):
    # at std_ratio 1.9 only the sample std keeps it.
    x = np.array([0.0, 1.0, 2.0, 3.0, 5.5])
    points = np.column_stack([x, np.zeros(5), np.zeros(5)])
    d = np.array([1.0, 1.0, 1.0, 1.0, 2.5])
    assert d.mean() + 1.9 * d.std(ddof=0) < 2.5 <= d.mean() + 1.9 * d.std(ddof=1), "test set-up"
    keep = impl.statistical_outlier_removal(points, 1, 1.9)
    check_array(keep, "keep", shape=(len(points),), dtype=None)  # before any .tolist()
    assert keep.tolist() == [True] * 5, (
        f"got {keep.tolist()}: sigma is the SAMPLE standard deviation (ddof=1): 2.5 <= 1.3 + 1.9 * 0.6708"
    )


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(2)
def test_statistical_outlier_removal_keeps_an_evenly_spaced_cloud(impl):
    # k = 1 on integers 0..9: every mean distance is exactly 1.0, so sigma = 0
    # and the threshold mu + std_ratio * sigma is 1.0 itself: d_i <= 1.0 keeps
    # every point (a strict < would remove them all).
    points = np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)])
    keep = impl.statistical_outlier_removal(points, 1, 1.0)
    check_array(keep, "keep", shape=(10,), dtype="bool")
    assert keep.all(), (
        f"got {keep.tolist()}: with equal mean distances sigma = 0 and every point is at the threshold: "
        "keep where d_i <= mu + std_ratio * sigma (<=, not <)"
    )


@pytest.mark.grades("statistical_outlier_removal")
@pytest.mark.points(1)
@pytest.mark.interface
def test_statistical_outlier_removal_rejects_bad_k(impl):
    points = np.random.default_rng(54).normal(size=(10, 3))
    for bad in (0, 10):
        with raises(ValueError, naming="k"):
            impl.statistical_outlier_removal(points, bad, 1.0)


# --- bilateral_filter_image ---------------------------------------------------------


def bilateral_pixel(image, y, x, sigma_s, sigma_r, r):
    """The filter's formula at one pixel, with plain loops over its window."""
    num = den = 0.0
    for qy in range(max(0, y - r), min(image.shape[0], y + r + 1)):
        for qx in range(max(0, x - r), min(image.shape[1], x + r + 1)):
            w = math.exp(-((qy - y) ** 2 + (qx - x) ** 2) / (2 * sigma_s**2))
            w *= math.exp(-((image[y, x] - image[qy, qx]) ** 2) / (2 * sigma_r**2))
            num += w * image[qy, qx]
            den += w
    return num / den


@pytest.mark.grades("bilateral_filter_image")
@pytest.mark.points(3)
def test_bilateral_filter_image_matches_its_formula(impl):
    image = np.random.default_rng(55).uniform(0, 1, size=(9, 11))
    result = impl.bilateral_filter_image(image, 1.2, 0.3, radius=2)
    check_array(result, "filtered", shape=(9, 11))
    for y, x in ((0, 0), (4, 5), (8, 10), (0, 6), (7, 1)):
        expected = bilateral_pixel(image, y, x, 1.2, 0.3, 2)
        assert np.isclose(result[y, x], expected, rtol=1e-9), (
            f"pixel ({y}, {x}): expected {expected:.6f}, got {result[y, x]:.6f}; every output pixel is computed "
            "from the INPUT image, over the window's pixels that are inside the image"
        )


@pytest.mark.grades("bilateral_filter_image")
@pytest.mark.points(1)
def test_bilateral_filter_image_default_radius(impl):
    image = np.random.default_rng(56).uniform(0, 1, size=(8, 8))
    result = impl.bilateral_filter_image(image, 0.7, 0.5)  # r = ceil(1.4) = 2
    check_close(
        result[3, 4],
        bilateral_pixel(image, 3, 4, 0.7, 0.5, 2),
        "pixel (3, 4) with radius=None",
        hint="radius=None means r = ceil(2 * sigma_s)",
    )


@pytest.mark.grades("bilateral_filter_image")
@pytest.mark.points(2)
def test_bilateral_filter_image_leaves_a_constant_image_unchanged(impl):
    image = np.full((7, 9), 5.0)
    check_close(
        impl.bilateral_filter_image(image, 2.0, 10.0),
        image,
        "filtered constant image",
        hint="pixels outside the image do not count (no zero padding)",
    )
    noisy = image + np.random.default_rng(60).normal(scale=0.1, size=image.shape)
    smoothed = impl.bilateral_filter_image(noisy, 2.0, 10.0)
    assert np.abs(smoothed - 5.0).max() < 0.5 * np.abs(noisy - 5.0).max(), (
        "with sigma_r = 10 the filter is a Gaussian blur: noise on a constant image must shrink"
    )


@pytest.mark.grades("bilateral_filter_image")
@pytest.mark.points(2)
def test_bilateral_filter_image_keeps_a_step_edge(impl):
    image = np.zeros((6, 10))
    image[:, 5:] = 1.0
    result = impl.bilateral_filter_image(image, 2.0, 0.1)
    assert np.abs(result - image).max() < 1e-6, (
        f"a step of 1 with sigma_r = 0.1 must survive, but moved by up to {np.abs(result - image).max():.3f}; "
        "hint: the range weight exp(-(I_p - I_q)^2 / (2 sigma_r^2))"
    )
    noisy = image + np.random.default_rng(61).normal(scale=0.01, size=image.shape)
    result = impl.bilateral_filter_image(noisy, 2.0, 0.1)
    assert np.abs(result - image).max() < 0.05 and (result - image).std() < 0.8 * (noisy - image).std(), (
        "a noisy step with sigma_r = 0.1: the edge must survive and the noise on each side must shrink"
    )


# --- bilateral_filter_points ------------------------------------------------------------


@pytest.mark.grades("bilateral_filter_points")
@pytest.mark.points(2)
def test_bilateral_filter_points_leaves_a_plane_on_its_plane(impl):
    rng = np.random.default_rng(57)
    points = np.column_stack([rng.uniform(-1, 1, size=(300, 2)), np.full(300, 2.0)])
    normals = np.tile([0.0, 0.0, 1.0], (300, 1))
    result = impl.bilateral_filter_points(points, normals, 0.3, 0.2, 0.1)
    check_array(result, "filtered", shape=(300, 3))
    check_close(
        result,
        points,
        "filtered plane",
        atol=1e-12,
        hint="on a plane every h = n_p . (q - p) is 0: points must not move",
    )
    lifted = points.copy()
    lifted[0, 2] += 0.05
    result = impl.bilateral_filter_points(lifted, normals, 0.3, 0.2, 0.1)
    assert abs(result[0, 2] - 2.0) < 0.04, (
        f"a point 0.05 above the plane must be pulled towards it, got height {result[0, 2] - 2.0:.4f}"
    )


@pytest.mark.grades("bilateral_filter_points")
@pytest.mark.points(3)
def test_bilateral_filter_points_matches_its_formula(impl):
    rng = np.random.default_rng(58)
    points = np.column_stack([rng.uniform(-1, 1, size=(200, 2)), rng.normal(scale=0.05, size=200)])
    normals = np.tile([0.0, 0.0, 1.0], (200, 1)) + rng.normal(scale=0.05, size=(200, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    result = impl.bilateral_filter_points(points, normals, 0.25, 0.15, 0.04)
    d = cdist(points, points)
    for i in (0, 17, 99, 150):
        near = d[i] <= 0.25
        offsets = points[near] - points[i]
        h = offsets @ normals[i]
        w = np.exp(-(d[i, near] ** 2) / (2 * 0.15**2)) * np.exp(-(h**2) / (2 * 0.04**2))
        expected = points[i] + normals[i] * np.sum(w * h) / np.sum(w)
        check_close(
            result[i],
            expected,
            f"point {i}",
            hint="p' = p + n_p * sum(w h) / sum(w), over ||q - p|| <= radius, p included",
        )


@pytest.mark.grades("bilateral_filter_points")
@pytest.mark.points(2)
def test_bilateral_filter_points_moves_only_along_the_normal(impl):
    rng = np.random.default_rng(59)
    points = rng.normal(size=(150, 3)) * [1.0, 1.0, 0.1]
    normals = rng.normal(size=(150, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    moved = impl.bilateral_filter_points(points, normals, 0.8, 0.4, 0.2) - points
    assert np.abs(moved).max() > 1e-3, "points of a noisy, curved cloud must move"
    sideways = np.linalg.norm(np.cross(moved, normals), axis=1)
    assert sideways.max() < 1e-9, (
        f"points moved {sideways.max():.3g} across their normal: p' = p + n_p * (a scalar), "
        "not towards the neighbours' weighted centroid"
    )


# --- joint_bilateral_upsample ----------------------------------------------------------


@pytest.mark.grades("joint_bilateral_upsample")
@pytest.mark.points(2)
def test_joint_bilateral_upsample_hand_built(impl):
    depth = np.zeros((3, 3))
    depth[0, 0], depth[2, 2] = 2.0, 4.0
    guide = np.zeros((3, 3))
    result = impl.joint_bilateral_upsample(depth, guide, 1.0, 1.0, 1)
    check_array(result, "dense depth", shape=(3, 3))
    # Centre: both samples at distance^2 = 2, equal weights -> 3.0.
    # (0, 1): only (0, 0) is in its window -> 2.0. (0, 2): no valid pixel -> 0.
    assert np.isclose(result[1, 1], 3.0), (
        f"centre: expected 3.0 (mean of the two valid pixels), got {result[1, 1]}; missing pixels (0) do not count"
    )
    assert np.isclose(result[0, 1], 2.0), f"(0, 1): expected 2.0, got {result[0, 1]}"
    assert result[0, 2] == 0.0, f"(0, 2): its window holds no valid pixel: expected 0, got {result[0, 2]}"


@pytest.mark.grades("joint_bilateral_upsample")
@pytest.mark.points(2)
def test_joint_bilateral_upsample_follows_the_guide_edge(impl):
    # Depth 10 left of a colour edge, 20 right of it; sparse samples on both sides.
    depth = np.zeros((8, 8))
    depth[::2, :4:2] = 10.0
    depth[::2, 5::2] = 20.0
    guide = np.zeros((8, 8, 3))
    guide[:, 4:] = [0.0, 0.8, 0.3]  # the edge is in the 2nd and 3rd channels only
    result = impl.joint_bilateral_upsample(depth, guide, 3.0, 0.1, 3)
    check_array(result, "dense depth", shape=(8, 8), dtype=None)
    assert np.allclose(result[:, :4], 10.0, atol=1e-3) and np.allclose(result[:, 4:], 20.0, atol=1e-3), (
        "the range weight on the GUIDE (colour distance ||g_p - g_q||^2 over the channels) must keep the "
        f"depth edge where the guide has one; got row 1: {np.round(result[1], 2).tolist()}"
    )


@pytest.mark.grades("joint_bilateral_upsample")
@pytest.mark.points(1)
def test_joint_bilateral_upsample_matches_its_formula(impl):
    rng = np.random.default_rng(60)
    depth = np.where(rng.uniform(size=(7, 9)) < 0.3, rng.uniform(5, 50, size=(7, 9)), 0.0)
    guide = rng.uniform(size=(7, 9))
    result = impl.joint_bilateral_upsample(depth, guide, 1.5, 0.3, 2)
    y, x = 3, 4
    num = den = 0.0
    for qy in range(1, 6):
        for qx in range(2, 7):
            if depth[qy, qx] > 0:
                w = math.exp(-((qy - y) ** 2 + (qx - x) ** 2) / (2 * 1.5**2))
                w *= math.exp(-((guide[y, x] - guide[qy, qx]) ** 2) / (2 * 0.3**2))
                num, den = num + w * depth[qy, qx], den + w
    check_close(result[y, x], num / den if den else 0.0, "pixel (3, 4)")
