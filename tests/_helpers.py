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


def run_batch(classroom, csv_path, *args):
    """Run ``python -m grading batch CLASSROOM --csv CSV_PATH ARGS``; return the rows by submission."""
    import csv

    completed = subprocess.run(
        [sys.executable, "-m", "grading", "batch", str(classroom), "--csv", str(csv_path), *args],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    with open(csv_path, newline="") as handle:
        return {row["submission"]: row for row in csv.DictReader(handle)}
