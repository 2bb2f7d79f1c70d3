"""Helpers shared by the project's tests (``tests/project``); ``pythonpath``
in ``pyproject.toml`` puts this folder on the import path."""

import json
import subprocess
import sys

from grading import REPO_ROOT


def run_grader(*args, tmp_path):
    """Run ``python -m grading grade ARGS``; return (results summary, stdout)."""
    results = tmp_path / "results.json"
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", *args, "--results", str(results)],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return json.loads(results.read_text()), completed.stdout
