"""Claims of the book's check-your-understanding answers, checked numerically:
the answers hold derivations by hand, so their conclusions are tested here."""

import numpy as np
from scipy.spatial import cKDTree


def test_row_zero_of_eigh_is_the_normal_on_every_plane_x_const():
    # book/normals.md, cyu-normal-column
    rng = np.random.default_rng(0)
    for _ in range(20):
        spread = rng.uniform(0.1, 3.0, size=2)
        points = np.column_stack([np.full(200, rng.normal()), rng.normal(size=(200, 2)) * spread])
        points[:, 1:] = points[:, 1:] @ np.linalg.qr(rng.normal(size=(2, 2)))[0]  # any in-plane directions
        vectors = np.linalg.eigh(np.cov(points.T))[1]
        assert np.allclose(np.abs(vectors[0]), np.abs(vectors[:, 0]), atol=1e-9)
    tilted = rng.normal(size=(200, 3)) * [3.0, 1.0, 0.01]
    vectors = np.linalg.eigh(np.cov(tilted.T))[1]
    assert not np.allclose(np.abs(vectors[0]), np.abs(vectors[:, 0]), atol=1e-3)


def test_the_surface_variation_of_a_cube_corner_is_about_an_eighth():
    # book/normals.md, cyu-curvature-bound: three quarter-discs of radius R
    rng = np.random.default_rng(1)
    faces = []
    for axis in range(3):
        face = rng.uniform(0, 1, size=(200_000, 3))
        face[:, axis] = 0
        faces.append(face)
    points = np.vstack(faces)
    stated = (1 / 6 + 1 / (3 * np.pi) - 64 / (27 * np.pi**2)) / (1 / 2 - 64 / (27 * np.pi**2))
    for radius in (0.3, 0.9):
        ball = points[np.linalg.norm(points, axis=1) < radius]
        eigenvalues = np.linalg.eigvalsh(np.cov(ball.T))
        assert abs(eigenvalues[0] / eigenvalues.sum() - stated) < 2e-3
    assert abs(stated - 1 / 8) < 1e-3


def normal_errors(points, centres, ks):
    tree = cKDTree(points)
    errors = []
    for k in ks:
        _, neighbours = tree.query(centres, k)
        groups = points[neighbours] - points[neighbours].mean(axis=1, keepdims=True)
        normals = np.linalg.eigh(np.einsum("nki,nkj->nij", groups, groups))[1][:, :, 0]
        errors.append(np.sqrt(np.mean(np.arccos(np.clip(np.abs(normals[:, 2]), 0, 1)) ** 2)))
    return np.array(errors)


def test_the_knn_normal_error_on_a_noisy_plane_falls_like_one_over_k():
    # book/normals.md, cyu-k-choice: at a fixed density the error falls like 1/k
    rng = np.random.default_rng(2)
    plane = np.column_stack([rng.uniform(-10, 10, size=(200_000, 2)), rng.normal(0, 0.01, 200_000)])
    centres = plane[np.linalg.norm(plane[:, :2], axis=1) < 5][:2000]
    ks = np.array([16, 32, 64, 128, 256])
    slope = np.polyfit(np.log(ks), np.log(normal_errors(plane, centres, ks)), 1)[0]
    assert -1.2 < slope < -0.85


def test_kernel_pca_gives_zero_alphas_for_zero_eigenvalues():
    # pcl_course/pca.py's kernel_pca docstring and book/kernel_pca.md: a zero eigenvalue of K~ has no
    # 1/eigenvalue scaling; its alphas column is zeros, as scikit-learn's transform uses it.
    from sklearn.decomposition import KernelPCA

    from solutions.pca import kernel_pca, kernel_pca_transform

    points = np.random.default_rng(3).normal(size=(12, 3))
    # Polynomial kernel of degree 1, (x.y + 1): a feature space of dimension 4, so K~ has rank 3.
    projections, eigenvalues, alphas = kernel_pca(points, 6, kernel="polynomial", degree=1)
    assert np.all(np.abs(eigenvalues[3:]) <= 1e-12 * eigenvalues[0])
    assert np.all(alphas[:, 3:] == 0) and np.all(projections[:, 3:] == 0)
    assert np.allclose(alphas[:, :3].T @ alphas[:, :3], np.diag(1 / eigenvalues[:3]))
    new = np.random.default_rng(4).normal(size=(5, 3))
    model = KernelPCA(6, kernel="poly", degree=1, gamma=1.0, coef0=1.0).fit(points)
    assert np.allclose(np.abs(kernel_pca_transform(new, points, alphas, kernel="polynomial", degree=1)),
                       np.abs(model.transform(new)), atol=1e-8)  # fmt: skip


def test_the_point_bilateral_worked_example_moves_p_by_the_stated_fraction():
    # book/filters.md: p is its own neighbour (weight 1, height 0), so p' - p = 2w h / (1 + 2w) < h
    from solutions.filters import bilateral_filter_points

    trio = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [-1.0, 0.0, 0.1]])
    up = np.tile([0.0, 0.0, 1.0], (3, 1))
    for sigma_s, sigma_r in [(1e6, 1e6), (1.0, 0.1), (1.0, 0.03)]:
        w = np.exp(-1.01 / (2 * sigma_s**2)) * np.exp(-0.01 / (2 * sigma_r**2))
        moved = bilateral_filter_points(trio, up, radius=1.5, sigma_s=sigma_s, sigma_r=sigma_r)[0]
        assert np.allclose(moved, [0.0, 0.0, 0.2 * w / (1 + 2 * w)], atol=1e-12)
        assert moved[2] < 0.1


def test_farthest_point_sampling_covers_within_twice_the_best_radius():
    # book/downsampling.md, thm-fps-two, against brute force over centres among the points
    from itertools import combinations

    from scipy.spatial.distance import cdist

    from solutions.downsampling import farthest_point_sampling

    rng = np.random.default_rng(6)
    for _ in range(5):
        points = np.column_stack([rng.uniform(size=(16, 2)), np.zeros(16)])
        distances = cdist(points, points)
        for m in (2, 3):
            start = int(rng.integers(16))
            fps = distances[:, farthest_point_sampling(points, m, start_index=start)].min(axis=1).max()
            best = min(distances[:, list(c)].min(axis=1).max() for c in combinations(range(16), m))
            assert fps <= 2 * best + 1e-12
