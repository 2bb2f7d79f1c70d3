"""The course autograder.

* :mod:`grading.cli` -- ``python -m grading grade | batch | release``.
* :mod:`grading.plugin` -- pytest plugin: the ``impl`` fixture that hands the
  implementation under test to graded tests, points per test, per-test
  timeouts, short feedback and the results file.
* :mod:`grading.implementation` -- the implementation under test: the
  reference or a project mutant in-process (trusted code), a student's
  submission staged and run in the sandbox.
* :mod:`grading.staging` -- copies a submission's ``pcl_course/`` without
  following links: regular files only, with caps.
* :mod:`grading.sandbox` and :mod:`grading.worker` -- the isolated worker
  process (bubblewrap, or a dedicated uid) and its plain-data protocol.
* :mod:`grading.forbidden` -- the static scan for forbidden APIs.
* :mod:`grading.checks` -- assertions with student-readable messages.
* :mod:`grading.config` -- every limit and constant of the grader.
* :mod:`grading.errors` -- the grader's own exceptions.
* :mod:`grading.release` and :mod:`grading.leakcheck` -- the student repository.
"""

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
GRADED_TESTS = REPO_ROOT / "tests" / "graded"   # public: shipped to students
HIDDEN_TESTS = REPO_ROOT / "tests" / "hidden"   # run only by the instructors' grader

# Graded function -> exercise module; every name in ../shared/course-api.md.
GRADED_FUNCTIONS = {
    "pca": "pca",
    "kernel_matrix": "pca",
    "kernel_pca": "pca",
    "kernel_pca_transform": "pca",
    "fit_plane": "normals",
    "estimate_normals": "normals",
    "voxel_grid_downsample": "downsampling",
    "approximate_voxel_downsample": "downsampling",
    "farthest_point_sampling": "downsampling",
    "normal_space_sampling": "downsampling",
    "radius_outlier_removal": "filters",
    "statistical_outlier_removal": "filters",
    "bilateral_filter_image": "filters",
    "bilateral_filter_points": "filters",
    "joint_bilateral_upsample": "filters",
    "chamfer_distance": "metrics",
    "depth_metrics": "metrics",
}
