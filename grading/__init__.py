"""The course autograder.

* :mod:`grading.cli` -- ``python -m grading grade | batch | release | gradescope | autograde | similarity``.
* :mod:`grading.runner` -- the pytest process that runs the graded tests.
* :mod:`grading.results` -- the results as data (:class:`~grading.results.Grading`),
  written to Gradescope's JSON and the terminal table, every submission text sanitised.
* :mod:`grading.plugin` -- pytest plugin: the ``impl`` fixture that hands the
  implementation under test to graded tests, points per test, per-test
  timeouts, short feedback and the results file.
* :mod:`grading.implementation` -- the implementation under test: the
  reference or a project mutant in-process (trusted code), a student's
  submission staged and run in the sandbox.
* :mod:`grading.staging` -- copies a submission's ``pcl_course/`` without
  following links: regular files only, with caps.
* :mod:`grading.sandbox` -- the isolated worker
  process (bubblewrap, or a dedicated uid) and its plain-data protocol.
* :mod:`grading.forbidden` -- the static scan for forbidden APIs.
* :mod:`grading.checks` -- assertions with student-readable messages.
* :mod:`grading.config` -- every limit and constant of the grader.
* :mod:`grading.errors` -- the grader's own exceptions.
* :mod:`grading.release` and :mod:`grading.leakcheck` -- the student repository.
* :mod:`grading.gradescope` -- the Gradescope archive, and `autograde` inside it.
* :mod:`grading.similarity` -- the similarity report of a class (copydetect).
"""

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
GRADED_TESTS = REPO_ROOT / "tests" / "graded"  # public: shipped to students
HIDDEN_TESTS = REPO_ROOT / "tests" / "hidden"  # run only by the instructors' grader

from grading.config import (  # noqa: E402,F401
    ASSIGNMENT_MODULES,
    ASSIGNMENTS,
    EXERCISE_MODULES,
    GRADED_FUNCTIONS,
    HELPER_MODULES,
)
