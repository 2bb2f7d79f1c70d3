"""Fixtures of the project's tests."""

import fcntl
import shutil
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pytest
from _helpers import TEST_BACKSTOP, load_results, run_grader

PROJECT_TESTS = Path(__file__).parent


def pytest_collection_modifyitems(items):
    """Every project test without its own ``timeout`` marker gets the wall-clock backstop
    (``tests/_helpers.py``); graded tests keep the grader's (grading.config.TEST_TIMEOUT).

    Tests marked ``long`` come first, in their order (a stable sort, the same in every xdist
    worker): xdist deals the first tests out in turn, so the long ones start at once on
    every worker instead of ending the run on one while the others are idle."""
    for item in items:
        if item.path.is_relative_to(PROJECT_TESTS) and item.get_closest_marker("timeout") is None:
            item.add_marker(pytest.mark.timeout(TEST_BACKSTOP))
    items.sort(key=lambda item: item.get_closest_marker("long") is None)


@pytest.fixture(autouse=True)
def own_temporary_folder(monkeypatch, tmp_path_factory):
    """Every temporary folder a test makes in this process (a staged submission, a grading's
    options) goes into a folder of its own, removed after the test: a test that stages a
    submission for a worker of its own never leaves it in /tmp. Mode 0711, as /tmp's
    sticky folder is traversable: a worker of another uid reaches the staged root below it."""
    tmp_path_factory.getbasetemp()  # pytest's own folder first, where it always is (it is made lazily)
    folder = tempfile.mkdtemp(prefix="pcl-test-")
    Path(folder).chmod(0o711)
    monkeypatch.setattr(tempfile, "tempdir", folder)
    yield
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture
def rng(request):
    """A random generator seeded from the test's own id: the same numbers
    whatever the order or the xdist worker that runs the test."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


@pytest.fixture(scope="session")
def reference_grading(tmp_path_factory, request):
    """The grader's verdict on the reference solutions, run once per test run.

    Under xdist the first worker that needs it grades; the others wait on a lock and read its
    results file (the workers share their basetemp's parent, which is this run's own)."""
    if not hasattr(request.config, "workerinput"):  # not an xdist worker: this run alone
        return run_grader("--reference", tmp_path=tmp_path_factory.mktemp("reference"))
    shared = tmp_path_factory.getbasetemp().parent / "reference-grading"
    shared.mkdir(exist_ok=True)
    with open(shared / "lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / "stdout.txt").exists():
            _, stdout = run_grader("--reference", tmp_path=shared)
            (shared / "stdout.txt").write_text(stdout)
    return load_results(shared / "results.json"), (shared / "stdout.txt").read_text()
