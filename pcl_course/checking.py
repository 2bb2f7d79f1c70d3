"""Check an exercise from a notebook cell: ``check("pca")``.

:func:`check` grades this repository's ``pcl_course/`` with the course's
grader, in its own process and sandbox, exactly as ``python -m grading grade``
does on a terminal, and returns a :class:`CheckReport`: in Jupyter it shows
the marks and what each failed test says as Markdown, in a terminal as the
grader's table. Only the public tests run; the hidden ones run after the
deadline.
"""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["check", "CheckReport"]

REPOSITORY = Path(__file__).resolve().parent.parent  # the clone whose pcl_course/ is graded


class CheckReport:
    """The outcome of :func:`check`: marks, and the feedback of the failed tests.

    Attributes
    ----------
    score, max_score : float
        The public tests' points.
    results : dict
        The grader's results file (Gradescope's format).
    table : str
        What ``python -m grading grade`` prints: the marks as plain text.
    """

    def __init__(self, results, table):
        self.results, self.table = results, table
        self.score = float(results.get("score", 0.0))
        self.max_score = float(sum(test["max_score"] for test in results.get("tests", ())))

    def failed(self):
        """The failed tests' results (name, points, feedback), in the grader's order."""
        return [test for test in self.results.get("tests", ()) if test.get("status") != "passed"]

    def _repr_markdown_(self):
        parts = [self.results.get("output", "")]
        for test in self.failed():
            parts.append(f"**{test['name']}** ({test['score']:g} / {test['max_score']:g})\n\n{test.get('output', '')}")
        return "\n\n".join(part for part in parts if part)

    def __repr__(self):
        return self.table


def _selection(name, assignment):
    """The grader's options that select ``name``: a graded function, an exercise module or a lecture."""
    from grading.config import ASSIGNMENTS, GRADED_FUNCTIONS  # the grader ships beside this package

    if assignment is not None and assignment not in ASSIGNMENTS:
        raise ValueError(f"assignment must be one of {', '.join(sorted(ASSIGNMENTS))}, got {assignment!r}")
    if name in ASSIGNMENTS:
        functions = list(ASSIGNMENTS[name])
    elif name in GRADED_FUNCTIONS:
        functions = [name]
    else:
        functions = [f for f, module in GRADED_FUNCTIONS.items() if module == name]
    if not functions:
        modules = ", ".join(dict.fromkeys(GRADED_FUNCTIONS.values()))
        raise ValueError(
            f"name must be a graded function (e.g. 'pca'), an exercise module ({modules}) or a lecture "
            f"({', '.join(sorted(ASSIGNMENTS))}), got {name!r}"
        )
    if assignment is not None and not set(functions) <= set(ASSIGNMENTS[assignment]):
        raise ValueError(f"name {name!r} is not graded in assignment {assignment!r}")
    return [option for function in functions for option in ("--function", function)]


def check(name, assignment=None):
    """Grade one exercise of this repository's ``pcl_course/`` with the public tests.

    Parameters
    ----------
    name : str
        A graded function (``"pca"``), an exercise module (``"nn"``: all its
        functions) or a lecture (``"lecture2"``).
    assignment : str, optional
        The lecture ``name`` belongs to, checked (``check("nn", assignment="lecture2")``).

    Returns
    -------
    CheckReport
        Shown as Markdown in a notebook (the last line of a cell), as the
        grader's table in a terminal.

    Raises
    ------
    ValueError
        ``name`` or ``assignment`` is not the course's.
    RuntimeError
        The grader could not run (its one line).
    """
    selection = _selection(name, assignment)
    with tempfile.TemporaryDirectory(prefix="pcl-check-") as folder:
        results = Path(folder) / "results.json"
        command = [sys.executable, "-m", "grading", "grade", str(REPOSITORY), "--quiet", "--results", str(results)]
        completed = subprocess.run([*command, *selection], cwd=REPOSITORY, capture_output=True, text=True, check=False)
        if completed.returncode != 0 or not results.exists():
            lines = (completed.stderr or completed.stdout).strip().splitlines()
            raise RuntimeError(lines[-1] if lines else f"the grader exited with status {completed.returncode}")
        report = json.loads(results.read_text())
    # The grader's last line names the results file; a test's feedback above it may quote the
    # submission, "Results written to" included, so the table ends at the last such line.
    table = completed.stdout.rsplit("\nResults written to", 1)[0].rstrip()
    return CheckReport(report, table)
