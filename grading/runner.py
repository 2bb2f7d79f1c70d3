"""Run the graded tests in their own pytest process (``python -m pytest`` with the grader's plugin).

Used by ``python -m grading grade`` (:mod:`grading.cli`), ``batch``
(:mod:`grading.instructors.batch`) and Gradescope's ``autograde``
(:mod:`grading.instructors.gradescope`).
"""

import json
import os
import subprocess
import sys
import threading

from grading import GRADED_TESTS, HIDDEN_TESTS, REPO_ROOT, scratch
from grading.config import GRADER_ENVIRONMENT
from grading.options import pytest_arguments
from grading.results import clean

PYTEST_EXIT_NO_TESTS = 5
PYTEST_EXIT_USAGE = 4


def run_graded_tests(impl_dir, results, *, keyword=None, junit=None, tests=None, note=None, progress=None, **options):
    """Run the graded tests on ``impl_dir`` in a pytest process; return its exit code and its output.

    ``options`` are the grading process's own (:mod:`grading.options`, by
    their dest: ``budget``, ``function``, ``sandbox``, ``sandbox_uid``, ...).
    ``progress``, if given, is called with ``(done, total, seconds, test,
    score)`` as each graded test finishes (read from a pipe the grading
    process writes one line to per test, ``--progress-fd``).
    The paths that name a submission (its folder, its results file) and the
    note on it go to pytest in a file only the grader's user can read, not
    on its command line: any process, a submission graded beside this one
    included, can read a command line in ``/proc``.
    """
    if tests is None:  # the public tests, and the hidden ones where they exist (not in a release)
        tests = [d for d in (GRADED_TESTS, HIDDEN_TESTS) if d.is_dir()]
    command = [
        sys.executable,
        "-m",
        "pytest",
        *[str(t) for t in (tests if isinstance(tests, list) else [tests])],
        # The grader's own configuration only: nothing from the submission.
        "-c",
        str(REPO_ROOT / "grading" / "pytest.ini"),
        "--rootdir",
        str(REPO_ROOT),
        "-p",
        "pytest_timeout",
        "-p",
        "grading.plugin",
        "-p",
        "no:cacheprovider",
        "-q",
        "--tb=no",
        "--no-header",
        "-rN",
        *pytest_arguments(options),
    ]
    if keyword:
        command += ["-k", keyword]
    if junit:
        command += ["--junitxml", str(junit)]
    # Only the plugins named above: the environment's others (nbval, dash,
    # pytest-benchmark, xdist) have no say in a grade, and importing them costs 0.2 s a grade.
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", PYTEST_DISABLE_PLUGIN_AUTOLOAD="1", **GRADER_ENVIRONMENT)
    scratch.sweep()  # what killed gradings left on this machine (grading/scratch.py)
    folder = scratch.folder("grading-options-")  # mode 0700: the grader's user only
    options_file = os.path.join(folder, "options.json")
    reader = writer = None
    if progress is not None:
        reader, writer = os.pipe()
        command += ["--progress-fd", str(writer)]
    try:
        with open(os.open(options_file, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600), "w") as handle:
            json.dump({"impl": str(impl_dir), "results": str(results), "submission_note": note}, handle)
        process = subprocess.Popen(
            [*command, "--grading-options", options_file],
            cwd=REPO_ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            pass_fds=(writer,) if writer is not None else (),
        )
        listener = None
        if writer is not None:
            os.close(writer)  # the grading process holds it now: the pipe ends when that process does
            listener = threading.Thread(target=_relay_progress, args=(reader, progress), daemon=True)
            listener.start()
        output, _ = process.communicate()
        if listener is not None:
            # A process the grading left behind may hold the pipe open (an ungraded, not isolated
            # run gives the submission the grader's own user): progress is a courtesy, never a wait.
            listener.join(timeout=PROGRESS_DRAIN)
    finally:
        scratch.remove(folder)
    return process.returncode, output


PROGRESS_DRAIN = 2.0  # seconds to wait, once grading has ended, for the progress pipe's last lines


def _relay_progress(reader, progress):
    """Call ``progress`` for each line of the grading process's progress pipe, until it closes.

    The lines come from the grading process (``counts seconds test score``); a line that is not
    of that form is skipped, and the test's name is cleaned of control characters: where the
    run is not isolated, the submission runs as the grader's user and could write to the pipe."""
    with os.fdopen(reader, errors="replace") as lines:
        for line in lines:
            try:
                counts, seconds, test, score = line.split()
                done, total = (int(n) for n in counts.split("/"))
                progress(done, total, float(seconds), clean(test, limit=200, newlines=False), clean(score, limit=20))
            except ValueError:
                continue
