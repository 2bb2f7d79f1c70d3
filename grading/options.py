"""The options of a grading run, declared once.

``python -m grading grade`` (:mod:`grading.cli`) offers the :data:`SHARED`
ones and passes them through; :func:`grading.runner.run_graded_tests` turns
their values into the grading process's command line
(:func:`pytest_arguments`); the plugin (:mod:`grading.plugin`) declares
them, and the :data:`PLUGIN_ONLY` ones the runner sets, to pytest. The
markers of a graded test (:data:`MARKERS`) are registered by the plugin
only.
"""

import argparse
from dataclasses import dataclass, field

from grading import config


@dataclass(frozen=True)
class Option:
    """One option: its flag and what ``argparse`` / pytest's ``addoption`` take."""

    flag: str
    help: str
    kwargs: dict = field(default_factory=dict)
    hidden: bool = False  # not in `grade --help` (the project's own checks)

    @property
    def dest(self):
        return self.flag.lstrip("-").replace("-", "_")

    def add_to(self, parser, public=True):
        """Declare the option on an ``argparse`` parser or a pytest option group."""
        shown = argparse.SUPPRESS if self.hidden and public else self.help
        add = parser.addoption if hasattr(parser, "addoption") else parser.add_argument
        add(self.flag, help=shown, **self.kwargs)


# Offered by `grade` and passed through to the grading process.
SHARED = (
    Option(
        "--budget",
        f"wall-clock budget of the whole grading (default {config.SUBMISSION_BUDGET:g}); tests not started by then "
        "score 0",
        {"type": float, "default": config.SUBMISSION_BUDGET, "metavar": "SECONDS"},
    ),
    Option(
        "--function",
        "grade only this function's tests (by their grades marker); repeatable",
        {"action": "append", "default": [], "metavar": "NAME"},
    ),
    Option(
        "--call-timeout",
        f"CPU seconds one call of a submission may take (default {config.CALL_TIMEOUT:g}; "
        f"{config.CALL_WALL_FACTOR:g} times as many seconds of wall clock stop a call that waits)",
        {"type": float, "default": config.CALL_TIMEOUT, "metavar": "SECONDS"},
    ),
    Option(
        "--require-isolation",
        "refuse to grade unless the submission runs isolated (bubblewrap, or root with a dedicated uid); "
        "for official marks",
        {"action": "store_true"},
    ),
    Option(
        "--impl-module",
        "replace one exercise module of the graded folder by FILE (the project's mutation checks)",
        {"action": "append", "default": [], "metavar": "MODULE=FILE"},
        hidden=True,
    ),
    Option(
        "--diagnose-always",
        "run the diagnosis on full-marks functions too (the project's check for false diagnoses)",
        {"action": "store_true"},
        hidden=True,
    ),
    Option(
        "--no-diagnosis",
        "skip the diagnosis (the project's checks of marks alone: degenerate answers)",
        {"action": "store_true"},
        hidden=True,
    ),
)

# Set by the runner only.
PLUGIN_ONLY = (
    Option(
        "--impl", "folder of exercise modules to grade (default: ./pcl_course)", {"default": None, "metavar": "DIR"}
    ),
    Option("--results", "write the results (Gradescope JSON) to FILE", {"default": None, "metavar": "FILE"}),
    Option(
        "--sandbox", "run the implementation in a limited worker process (grading/sandbox/)", {"action": "store_true"}
    ),
    Option(
        "--sandbox-uid",
        "the dedicated uid that runs the submission when the grader is root",
        {"type": int, "default": None, "metavar": "UID"},
    ),
    Option(
        "--submission-note",
        "a first line of the results' output (e.g. which files of an upload were graded)",
        {"default": None, "metavar": "TEXT"},
    ),
    Option(
        "--progress-fd",
        "a pipe to write one line to as each graded test finishes (`done/total seconds test score/max`)",
        {"type": int, "default": None, "metavar": "FD"},
    ),
    Option(
        "--grading-options",
        "a JSON file of options (impl, results, submission_note) that name a submission's paths: kept off the "
        "command line, which any process can read in /proc",
        {"default": None, "metavar": "FILE"},
    ),
)

# The options that name a submission's paths: written to the --grading-options file, never on a command line.
PRIVATE = ("impl", "results", "submission_note")

_BY_DEST = {option.dest: option for option in (*SHARED, *PLUGIN_ONLY)}

MARKERS = {
    "grades": "grades(function): the graded function a test grades",
    "hidden": "hidden: a graded test run by the instructors' grader only",
    "points": "points(n): marks that a graded test is worth",
    "in_place": "in_place: a graded test of in-place changes, run after the other tests of its function "
    "(it reads every call of the grading)",
    "interface": "interface: a graded test of shapes, dtypes, errors or in-place changes only "
    "(a degenerate answer may pass it)",
}


def pytest_arguments(values):
    """The grading process's command-line arguments for ``values`` (option dest -> value).

    Options left at None, False or empty are omitted; an ``append`` option
    is repeated; :data:`PRIVATE` ones are refused:
    they go through the options file.
    """
    arguments = []
    for dest, value in values.items():
        if dest in PRIVATE:
            raise ValueError(f"{dest} names a submission's path: pass it in the options file")
        option = _BY_DEST[dest]
        action = option.kwargs.get("action")
        if value is None or value is False or (action == "append" and not value):
            continue
        if action == "store_true":
            arguments.append(option.flag)
        elif action == "append":
            for item in value:
                arguments += [option.flag, str(item)]
        else:
            arguments += [option.flag, str(value)]
    return arguments
