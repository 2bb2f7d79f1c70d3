"""The course autograder, in three rooms.

**The engine** (ships to students; ``python -m grading grade``):

* :mod:`grading.cli` -- the command line; the instructors' commands come from
  :mod:`grading.instructors.commands` where that folder exists.
* :mod:`grading.options` -- the options of a grading run and the graded
  tests' markers, declared once.
* :mod:`grading.runner` -- the pytest process that runs the graded tests.
* :mod:`grading.plugin` -- pytest plugin: the ``impl`` fixture that hands the
  implementation under test to graded tests, points per test, per-test
  timeouts, the diagnosis and the results file.
* :mod:`grading.feedback` -- what a failed test says: its kind, its rule and
  the student-visible line, classified once.
* :mod:`grading.diagnosis` -- names a mistake from a function's calls and verdicts.
* :mod:`grading.results` -- the results as data (:class:`~grading.results.Grading`),
  written to Gradescope's JSON and the terminal table, every submission text sanitised.
* :mod:`grading.implementation` -- the implementation under test: the
  reference or a project mutant in-process (trusted code), a student's
  submission staged and run in the sandbox.
* :mod:`grading.staging` -- copies a submission's ``pcl_course/`` without
  following links: regular files only, with caps.
* :mod:`grading.forbidden` -- the static scan for forbidden APIs.
* :mod:`grading.checks` -- assertions with student-readable messages; one
  module per exercise module that needs its own (``checks/nn.py``: trees).
* :mod:`grading.config` -- what is graded, every limit and constant.
* :mod:`grading.errors` -- the grader's own exceptions.

**The sandbox** (ships too): :mod:`grading.sandbox`, the isolated worker
process, one job per module.

**The instructors' tools** (never in a student's copy):
:mod:`grading.instructors` -- release, Gradescope, the class ``batch`` and
its gradebook, the similarity report, the leak check, the catalogue of known
mistakes and each lecture's own checkers (``trees.py``). A copy of the
grader without that folder is a student's (:func:`instructors_grader`).
"""

import os
import stat
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
GRADED_TESTS = REPO_ROOT / "tests" / "graded"  # public: shipped to students
HIDDEN_TESTS = REPO_ROOT / "tests" / "hidden"  # run only by the instructors' grader
INSTRUCTORS = Path(__file__).resolve().parent / "instructors"  # the one folder a release withholds


def instructors_grader():
    """Whether this is the instructors' grader (the course repository, the Gradescope archive).

    The one test of a student's copy: the release withholds
    ``grading/instructors/`` whole, and nothing else of the grader's.
    """
    return INSTRUCTORS.is_dir() and not INSTRUCTORS.is_symlink()


def grader_links():
    """The entries of this grader that are not regular files or folders, as printable lines.

    ``grading/`` and the graded tests are read without following a link:
    a symbolic link (or a FIFO, a device) there could make the grader run
    other code, a submission's included, so the grader refuses to run while
    one is there (the students' advisory check refuses it too).
    """
    found = []
    for top in (REPO_ROOT / "grading", GRADED_TESTS, HIDDEN_TESTS):
        entries = [str(top)] if os.path.lexists(top) else []
        while entries:
            path = entries.pop()
            mode = os.lstat(path).st_mode
            if stat.S_ISDIR(mode):
                try:
                    entries += [os.path.join(path, name) for name in os.listdir(path)]
                except PermissionError:  # a folder this user cannot list, nor pytest collect
                    continue
            elif not stat.S_ISREG(mode):
                found.append(f"{ascii(os.path.relpath(path, REPO_ROOT))[1:-1]} is not a regular file or folder")
    return sorted(found)


from grading.config import (  # noqa: E402,F401
    ASSIGNMENT_MODULES,
    ASSIGNMENTS,
    EXERCISE_MODULES,
    GRADED_FUNCTIONS,
    HELPER_MODULES,
)
