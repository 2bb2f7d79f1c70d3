"""The grader's static check for forbidden APIs (grading/forbidden.py)."""

import shutil

import pytest
from _helpers import run_grader

from grading import REPO_ROOT
from grading.forbidden import scan_package, scan_source


@pytest.mark.parametrize(
    "source",
    [
        "import open3d",
        "import open3d as o3d",
        "import sklearn.decomposition",
        "from sklearn.decomposition import PCA",
        "from sklearn import decomposition as d",
        "x = __import__('open3d')",
        "import importlib\nm = importlib.import_module('sklearn.decomposition')",
        "import importlib as il\nm = il.import_module('open' + '3d')",
        "from importlib import import_module as im\nm = im(f'open3d')",
        "def f():\n    import open3d\n    return open3d",
        "import importlib\nname = 'open3d'\nm = importlib.import_module(name)",
    ],
)
def test_forbidden_imports_are_found(source):
    assert scan_source(source), source


@pytest.mark.parametrize(
    "source",
    [
        "import numpy as np\nfrom scipy.spatial import cKDTree",
        "from scipy.linalg import eigh",
        "from . import validation\nfrom pcl_course.neighbors import knn",
        "import math, numbers",
        "s = 'import open3d'  # a string is not an import",
    ],
)
def test_allowed_code_is_not_flagged(source):
    assert scan_source(source) == [], source


def test_the_reference_and_the_stubs_are_clean():
    for directory in (REPO_ROOT / "solutions", REPO_ROOT / "pcl_course"):
        violations = scan_package(directory, REPO_ROOT / "pcl_course")
        assert not any(violations.values()), violations


def test_a_modified_helper_is_scanned_and_taints_its_importers(tmp_path):
    package = tmp_path / "clone" / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "neighbors.py").write_text((package / "neighbors.py").read_text() + "\nimport open3d as _o3d\n")
    (package / "normals.py").write_text("from .neighbors import knn\n" + (package / "normals.py").read_text())
    violations = scan_package(package, REPO_ROOT / "pcl_course")
    assert violations["neighbors"] and violations["normals"], violations
    assert not violations["pca"] and not violations["datasets"]


def test_a_forbidden_import_costs_the_whole_module_with_a_clear_message(tmp_path):
    package = tmp_path / "clone" / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "metrics.py").write_text(
        "from sklearn.metrics import mean_squared_error\n" + (REPO_ROOT / "solutions" / "metrics.py").read_text()
    )
    summary, stdout = run_grader(
        str(tmp_path / "clone"), "-k", "test_chamfer_distance_ or test_pca_", tmp_path=tmp_path
    )
    chamfer = [t for t in summary["tests"] if "chamfer" in t["name"] and t["visibility"] == "visible"]
    assert chamfer and all(t["score"] == 0 and "forbidden API in metrics.py" in t["text"] for t in chamfer)
    hidden = [t for t in summary["tests"] if "chamfer" in t["name"] and t["visibility"] != "visible"]
    assert hidden and all(t["score"] == 0 and "sklearn" not in t["text"] for t in hidden)
    assert "metrics.py:1: from sklearn.metrics import ..." in chamfer[0]["text"]
    assert "Traceback" not in stdout


@pytest.mark.parametrize("codec", ["utf-7", "utf-16"])
def test_a_coding_line_cannot_hide_an_import_from_the_scan(tmp_path, codec):
    """Python decodes a source by its PEP 263 coding line; so does the scan. In UTF-7, the
    encoded newline ``+AAo-`` ends a comment for Python, not for a scan that reads UTF-8."""
    package = tmp_path / "pcl_course"
    package.mkdir()
    (package / "__init__.py").write_text("")
    if codec == "utf-7":
        data = b"# -*- coding: utf-7 -*-\n# a comment +AAo-from scipy.spatial import cKDTree\n"
        assert "\nfrom scipy.spatial" in data.decode("utf-7")  # what Python runs
    else:
        # UTF-16 has no coding line Python accepts: the import fails, and the scan must say so.
        hidden = "# a comment\nfrom scipy.spatial import cKDTree\n"
        data = b"\xff\xfe" + hidden.encode("utf-16-le")
    (package / "nn.py").write_bytes(data)
    violations = scan_package(package, REPO_ROOT / "pcl_course")["nn"]
    assert violations, f"{codec}: the scan saw nothing"
    if codec == "utf-7":
        assert any("scipy.spatial" in v.what for v in violations), violations


def test_each_module_with_rules_of_its_own_says_why_in_its_own_words():
    """A forbidden import in cluster.py was told 'this lecture is about writing the search' (lecture
    2's sentence, for every module with rules of its own: a hostile review, h48h)."""
    from grading.config import FORBIDDEN_IN_MODULE, MODULE_RULES_WHY
    from grading.errors import VISUALISATION_ONLY, ForbiddenAPI

    assert set(MODULE_RULES_WHY) == set(FORBIDDEN_IN_MODULE)
    assert len(set(MODULE_RULES_WHY.values())) == len(MODULE_RULES_WHY)
    for module, why in MODULE_RULES_WHY.items():
        assert str(ForbiddenAPI(module, ["import x"])).endswith(why)
    assert "clustering" in str(ForbiddenAPI("cluster", ["from scipy.cluster.vq import kmeans2"]))
    assert str(ForbiddenAPI("pca", ["import sklearn"])).endswith(VISUALISATION_ONLY)
