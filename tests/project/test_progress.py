"""Progress while grading (issue 37, item 1): on a terminal, ``grade`` rewrites one line as each test
finishes and ``batch`` prints a line as each submission finishes; off a terminal, or with ``--quiet``,
neither. Run on a real pseudo-terminal."""

import os
import re
import select
import subprocess
import sys
import time

import pytest
from _helpers import SUBPROCESS_BACKSTOP

from grading import REPO_ROOT


def run(argv, terminal):
    """``python -m grading ARGV``'s output (stdout and stderr), on a pseudo-terminal or on a pipe."""
    command = [sys.executable, "-m", "grading", *argv]
    if not terminal:
        completed = subprocess.run(command, cwd=REPO_ROOT, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP)
        return completed.stdout + completed.stderr
    primary, secondary = os.openpty()
    process = subprocess.Popen(command, cwd=REPO_ROOT, stdin=secondary, stdout=secondary, stderr=secondary)
    os.close(secondary)
    chunks, deadline = [], time.monotonic() + SUBPROCESS_BACKSTOP
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([primary], [], [], 1.0)
            if not ready:
                if process.poll() is not None:
                    break
                continue
            try:
                data = os.read(primary, 65536)
            except OSError:  # the terminal's other side is closed: the process is done
                break
            if not data:
                break
            chunks.append(data)
    finally:
        os.close(primary)
        process.wait(timeout=SUBPROCESS_BACKSTOP)
    return b"".join(chunks).decode("utf-8", errors="replace")


GRADE = ["grade", "--reference", "--function", "fit_plane"]


def test_grade_rewrites_one_progress_line_per_test_on_a_terminal():
    output = run(GRADE, terminal=True)
    steps = re.findall(r"\r\x1b\[K\[(\d+)/(\d+)\] \d+ s  (test_\w+)", output)
    total = int(steps[0][1])
    assert [int(done) for done, _, _ in steps] == list(range(1, total + 1)), output
    assert all(test.startswith("test_fit_plane") for _, _, test in steps)
    assert "fit_plane" in output.split("\r\x1b[K")[-1]  # the table follows the cleared line


@pytest.mark.parametrize("argv, terminal", [(GRADE, False), ([*GRADE, "--quiet"], True)])
def test_grade_shows_no_progress_off_a_terminal_or_when_quiet(argv, terminal):
    output = run(argv, terminal)
    assert "\x1b[K" not in output and not re.search(r"\[\d+/\d+\]", output)
    assert "fit_plane" in output


def test_batch_prints_a_line_as_each_submission_finishes_on_a_terminal(tmp_path):
    for name in ("ann", "ben"):
        (tmp_path / "class" / name).mkdir(parents=True)
        (tmp_path / "class" / name / "pca.py").write_text((REPO_ROOT / "pcl_course" / "pca.py").read_text())
    argv = ["batch", str(tmp_path / "class"), "--assignment", "lecture1", "-k", "test_fit_plane_", "--allow-unisolated"]
    output = run(argv, terminal=True)
    lines = re.findall(r"\[(\d)/2\] (ann|ben): (\d+) / (\d+) \((\d+) s\)", output)
    assert sorted(done for done, *_ in lines) == ["1", "2"] and {name for _, name, *_ in lines} == {"ann", "ben"}
    quiet = run([*argv, "--quiet", "--out", str(tmp_path / "quiet")], terminal=True)
    assert not re.search(r"\[\d/2\]", quiet) and re.search(r"^ann: \d+ / \d+\r?$", quiet, re.M), quiet


def test_the_relay_skips_lines_not_of_its_form_and_cleans_test_names():
    """Issue 37's hostile review: where a run is not isolated, a submission could write to the progress
    pipe; a malformed line killed the relay and a name with escapes reached the terminal."""
    import os

    from grading.runner import _relay_progress

    reader, writer = os.pipe()
    os.write(writer, b"garbage\n1/2 3 test_a\x1b]0;TITLE\x07 2/2\n2/2 4 test_b 1/1\n\xff\xfe\n")
    os.close(writer)
    seen = []
    _relay_progress(reader, lambda *line: seen.append(line))
    assert [line[0] for line in seen] == [1, 2]
    assert "\x1b" not in seen[0][3] and "\x07" not in seen[0][3]
