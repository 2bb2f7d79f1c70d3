"""The generated data: shapes with exact normals, mini ModelNet, lidar scan, file formats."""

import re

import numpy as np
import pytest

from grading import REPO_ROOT
from pcl_course import datasets
from pcl_course.io import (
    read_kitti_bin,
    read_kitti_depth_png,
    read_modelnet_txt,
    write_kitti_bin,
    write_kitti_depth_png,
    write_modelnet_txt,
)


@pytest.mark.parametrize("name", sorted(set(datasets.SHAPE_NAMES + datasets.MODELNET40_NAMES)))
def test_shape_has_requested_size_and_unit_normals(name):
    points, normals = datasets.make_shape(name, 1500, rng=0)
    assert points.shape == normals.shape == (1500, 3)
    assert points.dtype == normals.dtype == np.float64
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    assert np.all(np.isfinite(points))


@pytest.mark.parametrize("name", datasets.SHAPE_NAMES)
def test_shape_is_deterministic_given_its_seed(name):
    a = datasets.make_shape(name, 500, noise=0.01, rng=3, variation=0.2)
    b = datasets.make_shape(name, 500, noise=0.01, rng=3, variation=0.2)
    c = datasets.make_shape(name, 500, noise=0.01, rng=4, variation=0.2)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert not np.array_equal(a[0], c[0])


def test_there_are_at_least_twelve_categories():
    assert len(set(datasets.SHAPE_NAMES)) >= 12


def test_the_modelnet40_categories_are_all_there_and_distinct():
    assert len(set(datasets.MODELNET40_NAMES)) == len(datasets.MODELNET40_NAMES) == 40
    assert datasets.MODELNET40_NAMES == tuple(sorted(datasets.MODELNET40_NAMES))  # the data set's order
    sizes = {name: np.ptp(datasets.make_shape(name, 800, rng=0)[0], axis=0) for name in datasets.MODELNET40_NAMES}
    shapes = {name: tuple(np.round(np.sort(size / size.max()), 2)) for name, size in sizes.items()}
    assert len(set(shapes.values())) >= 38, "the categories must be distinct objects, not copies of one shape"


def test_a_mini_modelnet40_has_the_real_files_and_names(tmp_path):
    root = datasets.make_mini_modelnet(tmp_path, n_per_class=2, n_test_per_class=1, n_points=64,
                                       classes=datasets.MODELNET40_NAMES)  # fmt: skip
    assert (root / "modelnet40_shape_names.txt").read_text().split() == list(datasets.MODELNET40_NAMES)
    train = datasets.load_modelnet(root, split="train")
    assert sorted({o["label"] for o in train}) == list(datasets.MODELNET40_NAMES)


def test_sphere_normals_are_exact_radial_directions():
    points, normals = datasets.make_shape("sphere", 2000, rng=1)
    assert np.allclose(points, normals)  # unit sphere: the point is its normal


def test_torus_normals_are_exact():
    points, normals = datasets.make_shape("torus", 2000, rng=2)
    major, minor = 0.8, 0.25
    ring = np.column_stack([points[:, :2], np.zeros(len(points))])
    centre = major * ring / np.linalg.norm(ring, axis=1, keepdims=True)
    assert np.allclose(np.linalg.norm(points - centre, axis=1), minor)
    assert np.allclose(normals, (points - centre) / minor)


def test_ellipsoid_points_on_surface_with_gradient_normals():
    points, normals = datasets.make_shape("ellipsoid", 2000, rng=3)
    axes = np.array([1.0, 0.6, 0.35])
    assert np.allclose(np.sum((points / axes) ** 2, axis=1), 1.0)
    gradient = points / axes**2
    assert np.allclose(normals, gradient / np.linalg.norm(gradient, axis=1, keepdims=True))


def test_cone_normals_are_perpendicular_to_the_slant():
    points, normals = datasets.make_shape("cone", 4000, rng=4)
    lateral = normals[:, 2] > -0.99  # not the base disk
    apex = np.array([0.0, 0.0, 0.6])
    # On a cone, the line from the apex to the point lies in the surface.
    along = points[lateral] - apex
    assert np.allclose(np.sum(along * normals[lateral], axis=1), 0.0, atol=1e-12)


def test_sampling_is_uniform_in_area():
    # Sphere: z is uniform on [-1, 1] (Archimedes). Torus: the density of the
    # tube angle is proportional to the ring radius.
    points, _ = datasets.make_shape("sphere", 40000, rng=5)
    counts, _ = np.histogram(points[:, 2], bins=10, range=(-1, 1))
    assert np.all(np.abs(counts / 4000 - 1) < 0.06)
    points, _ = datasets.make_shape("torus", 40000, rng=6)
    outer = np.mean(np.linalg.norm(points[:, :2], axis=1) > 0.8)
    expected = 0.5 + 0.25 / (np.pi * 0.8)  # share of the area outside the ring of radius R
    assert abs(outer - expected) < 0.01


def test_box_faces_get_points_in_proportion_to_their_area():
    points, normals = datasets.make_shape("box", 30000, rng=7)
    sizes = np.array([1.0, 0.7, 0.5])
    areas = np.array([sizes[1] * sizes[2], sizes[0] * sizes[2], sizes[0] * sizes[1]])
    share = np.array([np.mean(np.abs(normals[:, i]) > 0.5) for i in range(3)])
    assert np.allclose(share, areas / areas.sum(), atol=0.01)
    # every point lies on the face its normal says
    face = np.argmax(np.abs(normals), axis=1)
    assert np.allclose(np.abs(points[np.arange(len(points)), face]), sizes[face] / 2)


def test_noise_moves_points_by_its_standard_deviation():
    clean, _ = datasets.make_shape("plane", 20000, rng=8)
    noisy, _ = datasets.make_shape("plane", 20000, noise=0.01, rng=8)
    assert abs(np.std(noisy[:, 2]) - 0.01) < 5e-4
    assert np.allclose(clean[:, 2], 0.0)


def test_make_shape_rejects_bad_arguments():
    with pytest.raises(ValueError, match="name"):
        datasets.make_shape("teapot")
    with pytest.raises(ValueError, match="n_points"):
        datasets.make_shape("sphere", -1)
    with pytest.raises(ValueError, match="noise"):
        datasets.make_shape("sphere", 10, noise=-1.0)


def test_modelnet_text_round_trip(tmp_path):
    points, normals = datasets.make_shape("chair", 300, rng=0)
    write_modelnet_txt(tmp_path / "chair_0001.txt", points, normals)
    first = (tmp_path / "chair_0001.txt").read_text().splitlines()[0]
    assert len(first.split(",")) == 6
    p, n = read_modelnet_txt(tmp_path / "chair_0001.txt")
    assert np.allclose(p, points, atol=1e-6) and np.allclose(n, normals, atol=1e-6)


def test_mini_modelnet_layout_and_loader(tmp_path):
    root = datasets.make_mini_modelnet(
        tmp_path / "mini", n_per_class=3, n_test_per_class=1, n_points=256, classes=("chair", "mug")
    )
    assert (root / "modelnet40_shape_names.txt").read_text().split() == ["chair", "mug"]
    assert (root / "chair" / "chair_0003.txt").is_file()
    train = datasets.load_modelnet(root, "train")
    test = datasets.load_modelnet(root, "test")
    assert [o["id"] for o in train] == ["chair_0001", "chair_0002", "mug_0001", "mug_0002"]
    assert [o["label"] for o in test] == ["chair", "mug"]
    for obj in train + test:
        norms = np.linalg.norm(obj["points"] - obj["points"].mean(axis=0), axis=1)
        assert abs(norms.max() - 1.0) < 1e-5  # unit-sphere scale
        assert obj["points"].shape == (256, 3)
    assert not np.allclose(train[0]["points"], train[1]["points"])  # distinct instances


def test_kitti_bin_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    points, intensity = rng.normal(size=(100, 3)) * 20, rng.uniform(size=100)
    write_kitti_bin(tmp_path / "000000.bin", points, intensity)
    assert (tmp_path / "000000.bin").stat().st_size == 100 * 4 * 4
    scan = read_kitti_bin(tmp_path / "000000.bin")
    assert scan.dtype == np.float32 and scan.shape == (100, 4)
    assert np.allclose(scan[:, :3], points, rtol=1e-6) and np.allclose(scan[:, 3], intensity, rtol=1e-6)


@pytest.fixture(scope="module")
def scan():
    return datasets.simulate_lidar_scan(seed=0)


def test_lidar_scan_has_a_realistic_size_and_range(scan):
    n = len(scan.points)
    assert 80_000 <= n <= 130_000
    ranges = np.linalg.norm(scan.points, axis=1)
    assert ranges.max() <= 100.5 and ranges.max() > 60.0
    for field in ("intensity", "labels", "ring", "is_outlier"):
        assert getattr(scan, field).shape == (n,)
    assert scan.normals.shape == (n, 3)
    assert np.all((scan.intensity >= 0) & (scan.intensity <= 1))


def test_lidar_scan_sees_every_class_and_labels_its_outliers(scan):
    labels = set(np.unique(scan.labels[~scan.is_outlier]))
    assert labels == set(range(len(datasets.LIDAR_CLASSES)))
    assert np.all(scan.labels[scan.is_outlier] == -1)
    assert 0.001 < scan.is_outlier.mean() < 0.02


def test_lidar_scan_numbers_its_objects(scan):
    # book/dbscan.md clusters the objects and scores the clusters against them.
    assert scan.objects.shape == scan.labels.shape and scan.objects.dtype == np.int64
    assert np.array_equal(scan.objects == -1, scan.is_outlier)
    assert np.all(scan.objects[scan.labels == datasets.LIDAR_CLASSES.index("ground")] == 0)
    inliers = ~scan.is_outlier
    pairs = np.unique(np.column_stack([scan.objects[inliers], scan.labels[inliers]]), axis=0)
    assert len(pairs) == len(np.unique(pairs[:, 0]))  # one class per object
    trees = pairs[pairs[:, 1] == datasets.LIDAR_CLASSES.index("vegetation"), 0]
    tops = [scan.points[scan.objects == tree, 2].max() for tree in trees]
    assert max(tops) > 2.5 - datasets.SENSOR_HEIGHT + 0.5  # a tree's object holds its crown, above its trunk


def test_lidar_ground_points_lie_on_the_ground_plane(scan):
    ground = scan.labels == datasets.LIDAR_CLASSES.index("ground")
    assert np.abs(scan.points[ground, 2] + datasets.SENSOR_HEIGHT).max() < 0.2
    assert np.allclose(scan.normals[ground], [0, 0, 1], atol=1e-6)


def test_lidar_ground_density_falls_as_the_cube_of_the_range(scan):
    # book/point_clouds.md, prop-lidar-density: each beam at depression theta meets the ground at
    # r = h / tan(theta), so the circles spread as r^2 and the density falls as r^-3, not r^-2.
    ground = (scan.labels == datasets.LIDAR_CLASSES.index("ground")) & ~scan.is_outlier
    elevations = np.deg2rad(np.linspace(2.0, -24.8, 64))
    ranges = np.linalg.norm(scan.points[ground, :2], axis=1)
    predicted = datasets.SENSOR_HEIGHT / np.tan(-elevations[scan.ring[ground]])
    assert np.median(np.abs(ranges / predicted - 1)) < 0.01
    # One annulus per beam's circle, from the circle halfway in to halfway out.
    circles = np.sort(datasets.SENSOR_HEIGHT / np.tan(-elevations[elevations < 0]))
    middle = circles[1:-1]
    areas = np.pi * (((circles[2:] + middle) / 2) ** 2 - ((circles[:-2] + middle) / 2) ** 2)
    returns = np.histogram(ranges, bins=(circles[1:] + circles[:-1]) / 2)[0]
    chosen = (middle >= 10) & (middle <= 60) & (returns > 0)
    model_exponent = np.polyfit(np.log(middle[chosen]), np.log(1 / areas[chosen]), 1)[0]
    scan_exponent = np.polyfit(np.log(middle[chosen]), np.log(returns[chosen] / areas[chosen]), 1)[0]
    assert -3.2 < model_exponent < -2.8
    assert scan_exponent < model_exponent  # occlusion: far circles reach the ground at fewer azimuths


def test_lidar_normals_face_the_sensor(scan):
    inliers = ~scan.is_outlier
    facing = np.sum(scan.normals[inliers] * (scan.origin - scan.points[inliers]), axis=1)
    assert np.all(facing > 0)


def test_lidar_outliers_are_in_front_of_real_surfaces(scan):
    # A spurious return lies on a beam, closer than where that beam hits.
    assert np.all(np.linalg.norm(scan.points[scan.is_outlier], axis=1) < 95.0)


def test_lidar_scan_is_deterministic():
    a = datasets.simulate_lidar_scan(seed=1, n_azimuth=360)
    b = datasets.simulate_lidar_scan(seed=1, n_azimuth=360)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.labels, b.labels)


def test_kitti_depth_png_round_trip(tmp_path):
    from PIL import Image

    rng = np.random.default_rng(1)
    depth = np.where(rng.uniform(size=(20, 30)) < 0.3, rng.uniform(1, 80, size=(20, 30)), 0.0)
    write_kitti_depth_png(tmp_path / "0000000005.png", depth)
    with Image.open(tmp_path / "0000000005.png") as image:
        assert np.array(image).dtype == np.uint16  # the devkit's format
    back = read_kitti_depth_png(tmp_path / "0000000005.png")
    assert back.shape == depth.shape and np.all((back > 0) == (depth > 0))
    assert np.abs(back - depth).max() <= 0.5 / 256 + 1e-12


SHARED_DATA = REPO_ROOT.parent / "shared" / "data"


def test_published_table_reads_the_lecture_table_with_its_source():
    table, source = datasets.published_table("snet_modelnet40_classification")
    assert list(table) == ["sampled_points", "random", "fps", "s_net"]
    assert table["sampled_points"].tolist() == [1024, 512, 256, 128, 64, 32, 16, 8, 4, 2]
    assert all(np.all((column > 0) & (column <= 100)) for name, column in table.items() if name != "sampled_points")
    assert "Dovrat" in source and "Learning to Sample" in source


@pytest.mark.skipif(not SHARED_DATA.is_dir(), reason="../shared/data is not beside this clone")
def test_published_tables_are_the_shared_files_unchanged():
    published = sorted((REPO_ROOT / "pcl_course" / "data" / "published").glob("*.csv"))
    assert published
    for path in published:
        shared = SHARED_DATA / path.name
        assert shared.is_file(), f"{path.name} is in data/published/ but not in ../shared/data"
        assert path.read_bytes() == shared.read_bytes(), f"{path.name} differs from ../shared/data"


def test_every_table_is_in_one_of_the_two_kinds_and_names_are_unique():
    data = REPO_ROOT / "pcl_course" / "data"
    assert not list(data.glob("*.csv")), "a table goes into data/published/ or data/compiled/"
    stems = [path.stem for path in data.glob("*/*.csv")]
    assert {path.parent.name for path in data.glob("*/*.csv")} <= {"published", "compiled"}
    assert len(stems) == len(set(stems))


def test_a_compiled_table_cites_its_public_source_at_a_commit():
    compiled = sorted((REPO_ROOT / "pcl_course" / "data" / "compiled").glob("*.csv"))
    assert compiled
    for path in compiled:
        table, source = datasets.published_table(path.stem)
        assert re.search(r"\b[\w.-]+/[\w.-]+\b", source), f"{path.name} names no repository"
        assert re.search(r"commit [0-9a-f]{7,40}\b", source), f"{path.name} names no commit"
        assert all(np.all(np.isfinite(column)) for column in table.values())


def test_the_students_reports_read_with_their_columns():
    table, source = datasets.published_table("kitti_nn_student_reports")
    assert table["report"].tolist() == [1, 2]
    assert {"kdtree_build", "kdtree_knn", "octree_knn", "brute"} <= set(table)
    assert np.all(table["brute"] > table["kdtree_knn"])


def test_published_table_rejects_an_unknown_name():
    with pytest.raises(ValueError, match="name must be one of"):
        datasets.published_table("no_such_table")
