"""The environments (README "Environments"): one lock, two subsets that agree
with it, a lean grading set, a Python floor stated once and checked, and
pins that resolve for the oldest supported Python (uv, against PyPI)."""

import re
import subprocess
import sys
import tomllib

import pytest
from _helpers import SUBPROCESS_BACKSTOP

from grading import REPO_ROOT

REQUIREMENTS = REPO_ROOT / "requirements"
BOOK_ONLY = {"open3d", "jupyter-book", "sphinx", "matplotlib", "plotly", "playwright", "ipykernel", "dash"}


def pins(name):
    """Package -> versions pinned in ``requirements/NAME.txt`` (a package may be pinned per Python)."""
    found = {}
    for line in (REQUIREMENTS / f"{name}.txt").read_text().splitlines():
        match = re.match(r"([A-Za-z0-9._-]+)==([^\s;]+)", line)
        if match:
            found.setdefault(match[1].lower().replace("_", "-"), set()).add(match[2])
    return found


@pytest.mark.parametrize("subset", ["grading", "student"])
def test_every_subset_pins_the_locks_versions(subset):
    lock = pins("course")
    differing = {name: versions for name, versions in pins(subset).items() if not versions <= lock.get(name, set())}
    assert not differing, f"requirements/{subset}.txt differs from the lock: {differing}"


def test_the_grading_set_is_lean_and_the_student_set_has_no_instructors_tools():
    assert not BOOK_ONLY & set(pins("grading"))
    assert {"numpy", "scipy", "scikit-learn", "numba", "pytest", "pytest-timeout", "pyseccomp"} <= set(pins("grading"))
    assert not {"playwright", "pytest-benchmark", "fpsample", "copydetect", "nbval"} & set(pins("student"))
    assert {"open3d", "jupyter-book", "ruff"} <= set(pins("student"))  # ruff: the banned-api check in the editor


def test_the_python_floor_is_stated_once_and_checked():
    floor = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]["requires-python"]
    sys.path.insert(0, str(REPO_ROOT / "scripts"))
    try:
        import check_python
    finally:
        sys.path.pop(0)
    assert floor == ">={}.{}".format(*check_python.FLOOR)
    assert re.search(
        r"^PYTHON_FLOOR := {}\.{}\.0$".format(*check_python.FLOOR), (REPO_ROOT / "Makefile").read_text(), re.M
    )
    assert check_python.problem() is None  # this interpreter passes


def test_a_python_below_the_floor_is_refused_in_one_line(tmp_path):
    # The check, run as if by Python 3.10: one line, naming the Python found and the one needed.
    script = (REPO_ROOT / "scripts" / "check_python.py").read_text()
    script = script.replace("if sys.version_info < FLOOR:", "if (3, 10, 12) < FLOOR:")
    script = script.replace("sys.version.split()[0]", '"3.10.12"')
    (tmp_path / "check_python.py").write_text(script)
    completed = subprocess.run([sys.executable, str(tmp_path / "check_python.py")], capture_output=True, text=True)
    assert completed.returncode == 1
    lines = completed.stderr.strip().splitlines()
    assert len(lines) == 1 and "Python 3.10.12" in lines[0] and "needs Python 3.11 or newer" in lines[0]


@pytest.mark.parametrize(
    "name, platform, binary_only",
    [
        ("grading", "x86_64-manylinux_2_35", True),  # Gradescope's Ubuntu 22.04: wheels only, nothing compiled
        ("course", "x86_64-manylinux_2_35", False),
    ],
)
def test_the_pins_resolve_for_the_oldest_supported_python(name, platform, binary_only):
    uv = REPO_ROOT / ".venv" / "bin" / "uv"
    command = [str(uv), "pip", "compile", "--quiet", "--no-header", "--python-version", "3.11.0"]
    command += ["--python-platform", platform, str(REQUIREMENTS / f"{name}.txt"), "-o", "/dev/null"]
    command += ["--only-binary", ":all:"] if binary_only else []
    completed = subprocess.run(command, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP)
    assert completed.returncode == 0, completed.stderr[-2000:]


def _requirement_lines(path):
    return [line.strip() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]


def test_the_top_level_requirements_file_installs_the_whole_course_from_the_lock():
    """``pip install -r requirements.txt`` is what users type (issue 37, item 6): it names the lock, and only it,
    so re-pinning never leaves it behind; the student repository's names its subset (test_release)."""
    assert _requirement_lines(REPO_ROOT / "requirements.txt") == ["-r requirements/course.txt"]
    template = REPO_ROOT / "grading" / "instructors" / "templates" / "requirements.txt"
    assert _requirement_lines(template) == ["-r requirements/student.txt"]
