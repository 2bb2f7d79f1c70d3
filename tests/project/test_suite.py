"""The project's own tests hold on a busy machine: every wall-clock limit in them is a backstop
derived from one busy factor (``tests/_helpers.py``), never a bare number tuned on an idle one."""

import ast
import tomllib

from _helpers import BUSY_FACTOR, SUBPROCESS_BACKSTOP, TEST_BACKSTOP

from grading import REPO_ROOT

SOURCES = sorted((REPO_ROOT / "tests" / "project").glob("*.py")) + [REPO_ROOT / "tests" / "_helpers.py"]
# Calls whose ``timeout`` is CPU seconds (grading.sandbox.Worker's, the limit of a submission's
# call), which load does not consume: a number is right there.
CPU_TIME_LIMITS = {"Worker", "hostile_worker", "make_worker", "worker_of"}


def _bare_timeouts(path):
    """``(line, text)`` of every ``timeout=<number>`` keyword and ``mark.timeout(<number>)`` in ``path``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.Call) or getattr(node.func, "id", None) in CPU_TIME_LIMITS:
            continue
        values = [keyword.value for keyword in node.keywords if keyword.arg == "timeout"]
        if isinstance(node.func, ast.Attribute) and node.func.attr == "timeout":
            values += node.args
        found += [(value.lineno, ast.unparse(node)[:80]) for value in values if isinstance(value, ast.Constant)]
    return found


def test_no_wall_clock_limit_in_the_tests_is_a_bare_number():
    bare = {path.name: lines for path in SOURCES if (lines := _bare_timeouts(path))}
    assert not bare, f"use tests/_helpers.py's backstop(...) for: {bare}"


def test_the_ini_backstop_is_the_tests_own():
    # pytest-timeout's default (notebook cells under nbval, anything outside tests/project).
    ini = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert float(ini["timeout"]) == TEST_BACKSTOP


def test_the_backstops_allow_a_machine_four_times_busier():
    assert BUSY_FACTOR >= 4
    # A subprocess stops, with its own message, before the test around it does.
    assert SUBPROCESS_BACKSTOP < TEST_BACKSTOP
