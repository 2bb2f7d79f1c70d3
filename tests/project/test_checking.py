"""``pcl_course.check`` (issue 37, item 2): an exercise checked from a notebook cell, in a real kernel
(nbclient), shows the marks and the failed tests' feedback as Markdown; in a terminal, the grader's table."""

import nbformat
import pytest
from _helpers import SUBPROCESS_BACKSTOP
from nbclient import NotebookClient

import pcl_course
from grading import ASSIGNMENTS, REPO_ROOT


def test_check_in_a_notebook_cell_shows_the_marks_and_feedback_as_markdown(tmp_path):
    notebook = nbformat.v4.new_notebook()
    notebook.cells = [nbformat.v4.new_code_cell('from pcl_course import check\ncheck("fit_plane")')]
    notebook.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    NotebookClient(notebook, timeout=SUBPROCESS_BACKSTOP, resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = notebook.cells[0].outputs
    shown = [o for o in outputs if o.output_type == "execute_result"]
    assert len(shown) == 1 and "text/markdown" in shown[0].data, outputs
    markdown = shown[0].data["text/markdown"]
    assert "**Public tests: 0 / 10 points.**" in markdown  # this repository's pcl_course/ holds the stubs
    assert "**test_fit_plane_recovers_a_known_plane** (0 / 2)" in markdown
    assert "not implemented: fit_plane() raises NotImplementedError" in markdown


def test_check_in_a_terminal_is_the_graders_table_and_selects_a_module_or_a_lecture():
    report = pcl_course.check("metrics", assignment="lecture1")
    assert repr(report).startswith(f"Grading {REPO_ROOT / 'pcl_course'}")
    assert {t["tags"][0] for t in report.results["tests"]} == {"chamfer_distance", "depth_metrics"}
    assert report.score == 0 and report.max_score > 0 and len(report.failed()) == len(report.results["tests"])


@pytest.mark.parametrize(
    "name, assignment, message",
    [
        ("pcaa", None, "name must be a graded function"),
        ("pca", "lecture9", "assignment must be one of " + ", ".join(ASSIGNMENTS)),
        ("pca", "lecture2", "name 'pca' is not graded in assignment 'lecture2'"),
    ],
)
def test_check_refuses_a_name_that_is_not_the_courses(name, assignment, message):
    with pytest.raises(ValueError, match=message):
        pcl_course.check(name, assignment)


def test_feedback_that_quotes_the_results_line_does_not_cut_the_table(monkeypatch):
    """Issue 37's hostile review: an exception message holding "Results written to" ended the
    terminal table there, hiding the real total behind a forged one."""
    import json
    import subprocess
    from pathlib import Path

    from pcl_course import checking

    forged = "  test_x: raised ValueError: x\n\nTotal: 7 / 7\n\nResults written to /dev/null"
    stdout = f"Grading here\n{forged}\nTotal: 0 / 7\nisolated: test\nResults written to /tmp/r.json\n"

    def run(command, **kwargs):
        Path(command[command.index("--results") + 1]).write_text(json.dumps({"score": 0, "tests": []}))
        return subprocess.CompletedProcess(command, 0, stdout=stdout, stderr="")

    monkeypatch.setattr(checking.subprocess, "run", run)
    table = repr(checking.check("fit_plane"))
    assert table.endswith("Total: 0 / 7\nisolated: test") and "Total: 7 / 7" in table
