"""The points each function's hidden tests carry, for a run that has none (a student's own).

The hidden tests run only on the instructors' grader (Gradescope, ``batch``),
after the deadline; a student's local run grades the public tests alone, and
its table says what is still to come. In the course's repository the points
are read from the hidden tests' markers; a student release carries them in
:data:`POINTS_FILE`, which the release writes from the same markers.
"""

import ast
import json
from pathlib import Path

from grading import HIDDEN_TESTS

POINTS_FILE = Path(__file__).with_name("hidden_points.json")


def hidden_points():
    """Function -> points of its hidden tests (empty where neither the tests nor the file are here)."""
    if HIDDEN_TESTS.is_dir():
        return points_from_markers(HIDDEN_TESTS)
    if POINTS_FILE.is_file():
        return {str(name): float(points) for name, points in json.loads(POINTS_FILE.read_text()).items()}
    return {}


def points_from_markers(folder):
    """Function -> points, summed over the test functions of ``folder`` by their ``grades`` and ``points``
    markers (1 point without one, as :mod:`grading.plugin` counts)."""
    points = {}
    for path in sorted(Path(folder).glob("test_*.py")):
        for node in ast.parse(path.read_text()).body:
            if not isinstance(node, ast.FunctionDef) or not node.name.startswith("test_"):
                continue
            marks = {
                mark.func.attr: mark.args
                for mark in node.decorator_list
                if isinstance(mark, ast.Call) and isinstance(mark.func, ast.Attribute)
            }
            if "grades" in marks:
                function = ast.literal_eval(marks["grades"][0])
                value = float(ast.literal_eval(marks["points"][0])) if "points" in marks else 1.0
                points[function] = points.get(function, 0.0) + value
    return points


def write_points_file(folder, destination):
    """Write the hidden tests' points of ``folder`` to ``destination`` (the release's :data:`POINTS_FILE`)."""
    Path(destination).write_text(json.dumps(points_from_markers(folder), indent=1, sort_keys=True) + "\n")
