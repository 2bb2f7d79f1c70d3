"""Helpers shared by the project's tests (``tests/project``); ``pythonpath``
in ``pyproject.toml`` puts this folder on the import path."""

import json
import subprocess
import sys

from grading import REPO_ROOT

# -- wall-clock backstops -------------------------------------------------------------------
# Where cost is the point, the tests limit CPU time (the grader's calls: grading.config.CALL_TIMEOUT);
# the wall clock only stops what hangs, and must not stop what is merely slow on a busy machine
# (a shared lab machine, a CI runner). Every wall-clock limit of the project's tests is therefore
# BUSY_FACTOR times an idle budget, itself above what the step took on an idle 2-core machine during
# `make test` (both xdist workers busy; measured with `pytest --durations=0`, README "Tests").
BUSY_FACTOR = 4


def backstop(idle_budget):
    """Wall-clock seconds allowed to a step whose idle budget is ``idle_budget`` seconds."""
    return BUSY_FACTOR * idle_budget


# A whole test: the slowest takes about 60 s idle (the release's book build; the bounds-checked
# kernel run has its own, test_kernels.py). Applied in tests/project/conftest.py.
TEST_BACKSTOP = backstop(150)
# One subprocess a test runs (a grading, a release, a book build, a batch): the slowest about 60 s
# idle. Below TEST_BACKSTOP, so that the subprocess's own message, not a stack dump, reports it.
SUBPROCESS_BACKSTOP = backstop(120)
# One quick command (a workflow step, a probe): a few seconds idle.
STEP_BACKSTOP = backstop(30)


def run_grader(*args, tmp_path):
    """Run ``python -m grading grade ARGS``; return (results summary, stdout)."""
    results = tmp_path / "results.json"
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", *args, "--results", str(results)],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return load_results(results), completed.stdout


def load_results(path):
    """A results file, checked against Gradescope's format, for the tests: its total as
    ``max_score``, each test's plain feedback as ``text``, and the whole grading as data
    (``grading``, a :class:`grading.results.Grading`) under ``extra_data``'s fields."""
    from grading.results import Grading, fenced

    results = json.loads(path.read_text())
    check_gradescope_results(results)
    results["max_score"] = sum(test["max_score"] for test in results["tests"])
    grading = Grading.from_gradescope(results)
    for test, result in zip(results["tests"], grading.tests):
        test["text"] = result.output_text()
        # The Markdown shows exactly the plain text, inside a fence that nothing in it can close.
        assert test["output"] == (fenced(test["text"]) if test["text"] else ""), test
    results["grading"] = grading
    return results


def run_batch(classroom, csv_path, *args):
    """Run ``python -m grading batch CLASSROOM --csv CSV_PATH ARGS``; return the rows by submission."""
    import csv

    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "grading",
            "batch",
            str(classroom),
            "--assignment",
            "lecture1",
            "--csv",
            str(csv_path),
            *args,
        ],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    with open(csv_path, newline="") as handle:
        return {row["submission"]: row for row in csv.DictReader(handle)}


def reference_source(module):
    """A reference module as a student's file: its private helpers imported from pcl_course.

    The sandbox hides solutions/, so a clone carries copies of the compiled
    kernels the references import (:data:`REFERENCE_KERNELS`).
    """
    return (REPO_ROOT / "solutions" / f"{module}.py").read_text().replace("from solutions.", "from pcl_course.")


# The references' private modules: the compiled kernels, as paths under solutions/ without ".py".
REFERENCE_KERNELS = tuple(sorted(f"_fast/{path.stem}" for path in (REPO_ROOT / "solutions" / "_fast").glob("*.py")))


def write_reference_modules(package, modules):
    """Write the reference modules ``modules`` (and the kernels they import) into the student package ``package``."""
    for module in (*modules, *REFERENCE_KERNELS):
        path = package / f"{module}.py"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(reference_source(module))


def reference_package(target):
    """Write the course's ``pcl_course/`` with every exercise solved by the reference into ``target``."""
    import shutil

    from grading import EXERCISE_MODULES

    shutil.copytree(REPO_ROOT / "pcl_course", target, ignore=shutil.ignore_patterns("__pycache__"))
    write_reference_modules(target, EXERCISE_MODULES)
    return target


# Gradescope's documented fields (gradescope-autograders.readthedocs.io, "Autograder Specifications").
GRADESCOPE_TOP = {
    "score",
    "execution_time",
    "output",
    "output_format",
    "visibility",
    "stdout_visibility",
    "extra_data",
    "tests",
    "leaderboard",
    "test_output_format",
    "test_name_format",
}
GRADESCOPE_TEST = {
    "score",
    "max_score",
    "status",
    "name",
    "name_format",
    "number",
    "output",
    "output_format",
    "tags",
    "visibility",
    "extra_data",
}
GRADESCOPE_VISIBILITY = {"hidden", "after_due_date", "after_published", "visible"}
GRADESCOPE_FORMATS = {"text", "html", "simple_format", "md", "ansi"}


def check_gradescope_results(results):
    """Assert that ``results`` (a loaded results.json) uses Gradescope's fields only, with valid values."""
    assert set(results) <= GRADESCOPE_TOP, set(results) - GRADESCOPE_TOP
    assert isinstance(results.get("score", 0), (int, float))
    assert isinstance(results["execution_time"], int) and results["execution_time"] >= 0
    assert isinstance(results["output"], str)
    assert results["stdout_visibility"] in GRADESCOPE_VISIBILITY
    for test in results["tests"]:
        assert set(test) <= GRADESCOPE_TEST, set(test) - GRADESCOPE_TEST
        assert isinstance(test["name"], str) and test["name"]
        assert isinstance(test["score"], (int, float)) and isinstance(test["max_score"], (int, float))
        assert 0 <= test["score"] <= test["max_score"]
        assert test["status"] in {"passed", "failed"}
        assert test["output_format"] in GRADESCOPE_FORMATS
        assert test["visibility"] in GRADESCOPE_VISIBILITY
        assert isinstance(test["tags"], list) and all(isinstance(t, str) for t in test["tags"])
        assert isinstance(test["number"], str)
    numbers = [t["number"] for t in results["tests"]]
    assert len(numbers) == len(set(numbers)), "test numbers must be unique"


HIDDEN_REFUSAL = "the submission was refused (the public tests say why) (hidden test: details withheld)"


def public_tests(summary):
    """The tests a student sees at once (visibility ``visible``)."""
    return [t for t in summary["tests"] if t["visibility"] == "visible"]


def hidden_tests(summary):
    """The tests shown after publication only; their feedback is in the grader's words."""
    return [t for t in summary["tests"] if t["visibility"] != "visible"]


def staged_root(package):
    """The root of ``package`` staged as the grader stages a submission, removed when this test
    process exits: a ``Worker`` stops its processes but leaves the staging to its owner (the
    grader's ``Implementation`` removes its own), so tests that make workers would otherwise
    leave copies in the temporary folder."""
    import atexit

    from grading import scratch
    from grading.staging import stage

    root = stage(package).root
    atexit.register(scratch.remove, root)
    return root
