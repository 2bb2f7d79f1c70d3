"""Fixtures of the project's tests."""

import fcntl
import shutil
import tempfile
import threading
import zlib
from pathlib import Path

import numpy as np
import pytest
from _helpers import TEST_BACKSTOP, load_results, run_grader

PROJECT_TESTS = Path(__file__).parent


def _order(item):
    """Tests marked ``long`` first, the tests that read the reference's grading last."""
    if item.get_closest_marker("long") is not None:
        return 0
    return 2 if "reference_grading" in getattr(item, "fixturenames", ()) else 1


def pytest_collection_modifyitems(items):
    """Every project test without its own ``timeout`` marker gets the wall-clock backstop
    (``tests/_helpers.py``); graded tests keep the grader's (grading.config.TEST_TIMEOUT).

    The order (a stable sort, the same in every xdist worker): tests marked ``long`` first, so
    that, with xdist handing out one test at a time (``--maxschedchunk=1``, the Makefile), they
    start at once on every worker instead of ending the run on one while the others are idle;
    the tests that read the reference's grading last, by when :func:`pytest_collection_finish`'s
    grading is ready."""
    for item in items:
        if item.path.is_relative_to(PROJECT_TESTS) and item.get_closest_marker("timeout") is None:
            item.add_marker(pytest.mark.timeout(TEST_BACKSTOP))
    items.sort(key=_order)


def _shared_reference_folder(config):
    # pytest's own tmp_path factory (the session's basetemp); an xdist worker's is a folder of
    # the run's, which all the workers share.
    return config._tmp_path_factory.getbasetemp().parent / "reference-grading"


def _grade_the_reference_once(shared):
    """Grade the reference into ``shared`` unless another worker of this run has (under a lock)."""
    shared.mkdir(exist_ok=True)
    with open(shared / "lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / "stdout.txt").exists():
            _, stdout = run_grader("--reference", tmp_path=shared)
            (shared / "stdout.txt").write_text(stdout)


def pytest_collection_finish(session):
    """Under xdist, start the reference's grading in the background as soon as a worker has
    collected a test that reads it: it takes one to two minutes of a busy machine, and a worker
    that waited for it at its first such test would idle all that time."""
    config = session.config
    if hasattr(config, "workerinput") and any("reference_grading" in item.fixturenames for item in session.items):
        folder = _shared_reference_folder(config)
        # A daemon thread: a failed grading is left to the fixture, which grades again and fails the test.
        threading.Thread(target=_grade_the_reference_once, args=(folder,), daemon=True).start()


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

    Under xdist a background thread of the first worker to collect a test that reads it grades
    (:func:`pytest_collection_finish`); a test waits on the lock for it, then reads its
    results file (the workers share their basetemp's parent, which is this run's own)."""
    if not hasattr(request.config, "workerinput"):  # not an xdist worker: this run alone
        return run_grader("--reference", tmp_path=tmp_path_factory.mktemp("reference"))
    shared = _shared_reference_folder(request.config)
    _grade_the_reference_once(shared)
    return load_results(shared / "results.json"), (shared / "stdout.txt").read_text()
