"""Known mistakes of ``pcl_course/filters.py``: outlier removal, bilateral filters."""

import math

import numpy as np
from scipy.spatial import cKDTree

from grading.instructors.mistakes import Mistake, Model, Raised, valid_points

MAX_LOOPED_POINTS = 20_000  # larger calls are not replayed by the loops below
MAX_LOOPED_PIXELS = 10_000


def _cloud(points):
    return valid_points(points, min_columns=3)[:, :3]


# -- radius_outlier_removal ----------------------------------------------------------------


def radius_keep(points, radius, min_neighbors, strict=False, itself=False):
    xyz = _cloud(points)
    if not radius > 0:
        raise ValueError("radius")
    reach = np.nextafter(radius, 0.0) if strict else radius  # the ball query includes its boundary
    counts = cKDTree(xyz).query_ball_point(xyz, reach, return_length=True) - (0 if itself else 1)
    return np.asarray(counts) >= int(min_neighbors)


RADIUS_OUTLIER_REMOVAL = Model(
    truth=radius_keep,
    output_dtypes=("bool",),
    mistakes=(
        Mistake(
            "counts_itself",
            "count only the OTHER points within the radius: the point itself is at distance 0 and does not count",
            lambda points, radius, min_neighbors: radius_keep(points, radius, min_neighbors, itself=True),
        ),
        Mistake(
            "strict_radius",
            "a neighbour at distance exactly radius counts: use distance <= radius, not <",
            lambda points, radius, min_neighbors: radius_keep(points, radius, min_neighbors, strict=True),
        ),
    ),
)


# -- statistical_outlier_removal --------------------------------------------------------------


def statistical_keep(points, k, std_ratio, itself=False, ddof=1, total=False, two_sided=False, strict=False):
    xyz = _cloud(points)
    k = int(k)
    if not 1 <= k <= len(xyz) - 1:
        raise ValueError("k")
    nearest = np.sort(cKDTree(xyz).query(xyz, k=k + 1)[0], axis=1)
    # The k + 1 nearest include the point itself at distance 0 (a duplicate is another 0).
    mean = nearest[:, :k].mean(axis=1) if itself else nearest[:, 1:].mean(axis=1)
    centre, spread = mean.mean(), mean.std(ddof=ddof)
    score = mean * k if total else mean
    upper = centre + std_ratio * spread
    keep = score < upper if strict else score <= upper
    if two_sided:
        keep &= score >= centre - std_ratio * spread
    return keep


def _statistical(**changes):
    return lambda points, k, std_ratio: statistical_keep(points, k, std_ratio, **changes)


def _rejects_the_largest_k(points, k, std_ratio):
    """A range check one short: ``k = N - 1`` (every other point) refused."""
    return Raised("ValueError") if int(k) == len(_cloud(points)) - 1 else None


STATISTICAL_OUTLIER_REMOVAL = Model(
    truth=statistical_keep,
    output_dtypes=("bool",),
    mistakes=(
        Mistake(
            "includes_itself",
            "average the distances to the k nearest OTHER points: the point itself (distance 0) is not one of "
            "them, though a duplicate of it is",
            _statistical(itself=True),
        ),
        Mistake(
            "population_std",
            "sigma is the SAMPLE standard deviation of the mean distances: np.std(..., ddof=1)",
            _statistical(ddof=0),
        ),
        Mistake(
            "sum_not_mean",
            "compare each point's MEAN distance to its k neighbours with mu + std_ratio * sigma, not its sum",
            _statistical(total=True),
        ),
        Mistake(
            "two_sided",
            "the test is one-sided: keep every point with d_i <= mu + std_ratio * sigma, however small its d_i",
            _statistical(two_sided=True),
        ),
        Mistake(
            "strict_threshold",
            "keep where d_i <= mu + std_ratio * sigma (<=, not <): with sigma = 0 a strict test removes every point",
            _statistical(strict=True),
        ),
        Mistake(
            "rejects_the_largest_k",
            "k = N - 1 is allowed (every other point is a neighbour): reject only k < 1 and k > N - 1",
            _rejects_the_largest_k,
        ),
    ),
)


# -- bilateral_filter_image ---------------------------------------------------------------------


def bilateral_image(image, sigma_s, sigma_r, radius=None, padding=None, range_weight=True, in_place=False):
    source = np.array(image, dtype=float)
    if source.ndim != 2 or not np.isfinite(source).all() or not (sigma_s > 0 and sigma_r > 0):
        raise ValueError("not a valid image or sigma")
    reach = math.ceil(2 * sigma_s) if radius is None else int(radius)
    height, width = source.shape
    if in_place:
        if source.size > MAX_LOOPED_PIXELS:
            raise ValueError("too large to replay")
        return _in_place(source, sigma_s, sigma_r, reach)
    total = np.zeros_like(source)
    weights = np.zeros_like(source)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            shifted = np.full_like(source, np.nan if padding is None else padding)
            ys, yd = slice(max(0, dy), height + min(0, dy)), slice(max(0, -dy), height + min(0, -dy))
            xs, xd = slice(max(0, dx), width + min(0, dx)), slice(max(0, -dx), width + min(0, -dx))
            shifted[yd, xd] = source[ys, xs]
            inside = ~np.isnan(shifted)
            value = np.where(inside, shifted, 0.0)
            weight = math.exp(-(dy * dy + dx * dx) / (2 * sigma_s**2))
            if range_weight:
                weight = weight * np.exp(-((source - value) ** 2) / (2 * sigma_r**2))
            weight = np.where(inside, weight, 0.0)
            total += weight * value
            weights += weight
    return total / weights


def _in_place(image, sigma_s, sigma_r, reach):
    out = image.copy()
    height, width = out.shape
    for y in range(height):
        for x in range(width):
            top, bottom = max(0, y - reach), min(height, y + reach + 1)
            left, right = max(0, x - reach), min(width, x + reach + 1)
            window = out[top:bottom, left:right]
            ys, xs = np.mgrid[top:bottom, left:right]
            weight = np.exp(-((ys - y) ** 2 + (xs - x) ** 2) / (2 * sigma_s**2)) * np.exp(
                -((out[y, x] - window) ** 2) / (2 * sigma_r**2)
            )
            out[y, x] = (weight * window).sum() / weight.sum()
    return out


def _image(**changes):
    return lambda image, sigma_s, sigma_r, radius=None: bilateral_image(image, sigma_s, sigma_r, radius, **changes)


BILATERAL_FILTER_IMAGE = Model(
    truth=bilateral_image,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "in_place_updates",
            "compute every output pixel from the INPUT image: writing into the image as you go makes later "
            "pixels read already-filtered neighbours",
            _image(in_place=True),
        ),
        Mistake(
            "no_range_weight",
            "the range weight exp(-(I_p - I_q)^2 / (2 sigma_r^2)) is missing: without it the filter is a "
            "plain Gaussian blur that smooths edges away",
            _image(range_weight=False),
        ),
        Mistake(
            "zero_padding",
            "sum over the part of the window inside the image only: pixels outside it do not exist (no padding with 0)",
            _image(padding=0.0),
        ),
    ),
)


# -- bilateral_filter_points ---------------------------------------------------------------------


def bilateral_points(points, normals, radius, sigma_s, sigma_r, range_weight=True, centroid=False):
    xyz = _cloud(points)
    directions = np.array(normals, dtype=float)
    if directions.shape != xyz.shape or not np.isfinite(directions).all() or not radius > 0:
        raise ValueError("not valid normals or radius")
    if len(xyz) > MAX_LOOPED_POINTS:
        raise ValueError("too large to replay")
    neighbourhoods = cKDTree(xyz).query_ball_point(xyz, radius)
    out = np.empty_like(xyz)
    for i, members in enumerate(neighbourhoods):
        near = np.asarray(members, dtype=np.int64)
        offsets = xyz[near] - xyz[i]
        heights = offsets @ directions[i]
        weight = np.exp(-np.sum(offsets**2, axis=1) / (2 * sigma_s**2))
        if range_weight:
            weight = weight * np.exp(-(heights**2) / (2 * sigma_r**2))
        if centroid:
            out[i] = weight @ xyz[near] / weight.sum()
        else:
            out[i] = xyz[i] + directions[i] * (weight @ heights) / weight.sum()
    return out


BILATERAL_FILTER_POINTS = Model(
    truth=bilateral_points,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "no_range_weight",
            "the range weight exp(-h^2 / (2 sigma_r^2)) on the height h = n_p . (q - p) is missing: "
            "without it sharp features are smoothed away",
            lambda points, normals, radius, sigma_s, sigma_r: bilateral_points(
                points, normals, radius, sigma_s, sigma_r, range_weight=False
            ),
        ),
        Mistake(
            "weighted_centroid",
            "move each point ALONG ITS NORMAL, p' = p + n_p * sum(w h) / sum(w): moving it to its neighbours' "
            "weighted centroid also slides it within the surface",
            lambda points, normals, radius, sigma_s, sigma_r: bilateral_points(
                points, normals, radius, sigma_s, sigma_r, centroid=True
            ),
        ),
    ),
)


# -- joint_bilateral_upsample ----------------------------------------------------------------------


def joint_upsample(sparse_depth, guide, sigma_s, sigma_r, radius, channels="all", guide_weight=True, zeros=False):
    depth = np.array(sparse_depth, dtype=float)
    colours = np.array(guide, dtype=float)
    if depth.ndim != 2 or colours.shape[:2] != depth.shape or not np.isfinite(depth).all():
        raise ValueError("not a valid depth map or guide")
    colours = colours.reshape(depth.shape[0], depth.shape[1], -1)
    if channels == "first":
        colours = colours[:, :, :1]
    reach = int(radius)
    height, width = depth.shape
    total = np.zeros_like(depth)
    weights = np.zeros_like(depth)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            ys, yd = slice(max(0, dy), height + min(0, dy)), slice(max(0, -dy), height + min(0, -dy))
            xs, xd = slice(max(0, dx), width + min(0, dx)), slice(max(0, -dx), width + min(0, -dx))
            value = np.zeros_like(depth)
            inside = np.zeros(depth.shape, bool)
            value[yd, xd] = depth[ys, xs]
            inside[yd, xd] = True
            other = np.zeros_like(colours)
            other[yd, xd] = colours[ys, xs]
            weight = np.full(depth.shape, math.exp(-(dy * dy + dx * dx) / (2 * sigma_s**2)))
            if guide_weight:
                weight = weight * np.exp(-np.sum((colours - other) ** 2, axis=2) / (2 * sigma_r**2))
            used = inside & ((value > 0) | zeros)
            total += np.where(used, weight * value, 0.0)
            weights += np.where(used, weight, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(weights > 0, total / weights, 0.0)
    return np.where(total > 0, out, 0.0)


def _upsample(**changes):
    return lambda sparse_depth, guide, sigma_s, sigma_r, radius: joint_upsample(
        sparse_depth, guide, sigma_s, sigma_r, radius, **changes
    )


JOINT_BILATERAL_UPSAMPLE = Model(
    truth=joint_upsample,
    output_dtypes=("float64",),
    mistakes=(
        Mistake(
            "first_channel_only",
            "the range weight compares the guide's whole colour: ||g_p - g_q||^2 summed over ALL its channels",
            _upsample(channels="first"),
        ),
        Mistake(
            "no_guide_weight",
            "the guide's range weight exp(-||g_p - g_q||^2 / (2 sigma_r^2)) is missing: without it depth edges "
            "do not follow the image's edges",
            _upsample(guide_weight=False),
        ),
        Mistake(
            "zeros_averaged",
            "average over the VALID pixels only (d_q > 0): a missing pixel is not a depth of 0",
            _upsample(zeros=True),
        ),
    ),
)


MODELS = {
    "radius_outlier_removal": RADIUS_OUTLIER_REMOVAL,
    "statistical_outlier_removal": STATISTICAL_OUTLIER_REMOVAL,
    "bilateral_filter_image": BILATERAL_FILTER_IMAGE,
    "bilateral_filter_points": BILATERAL_FILTER_POINTS,
    "joint_bilateral_upsample": JOINT_BILATERAL_UPSAMPLE,
}
