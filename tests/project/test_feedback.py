"""What a submission can put in front of a student or an instructor.

* Feedback is sanitised: no terminal escape, HTML or Markdown of a
  submission's reaches the results file or the terminal as anything but
  text, and every text is capped.
* Hidden tests are no oracle: the visible summary counts the public tests
  only, and a hidden test's feedback holds no text the submission produced.
* ``batch`` in the uid mode refuses a class folder the sandbox uids can read.
"""

import json
import os
import re
import shutil
import textwrap

import pytest
from _helpers import hidden_tests, public_tests, run_grader

from grading import REPO_ROOT
from grading.config import MAX_OUTPUT
from grading.implementation import _first_line
from grading.results import Grading, TestResult, clean, fenced

needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="needs root (the uid mode)")


def submission(root, metrics_source):
    package = root / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "metrics.py").write_text(textwrap.dedent(metrics_source))
    return root


def grade(clone, tmp_path, *args):
    """(results, what the grader printed, the results file's raw text)."""
    summary, printed = run_grader(str(clone), *args, tmp_path=tmp_path)
    return summary, printed, (tmp_path / "results.json").read_text()


HOSTILE_TEXT = """
    import numpy as np

    ESCAPES = "\\x1b[2J\\x1b[H\\x1b]0;owned\\x07  8.0/8.0  ok   test_chamfer_distance_hand_computed\\u202e"
    MARKUP = "<script>alert(1)</script> <img src=x onerror=alert(1)> [click](javascript:alert(1))"
    HEADING = "\\n# Score: 100 / 100\\n```\\n</pre><h1>Score</h1>"


    class Loud(Exception):
        pass


    Loud.__name__ = Loud.__qualname__ = ESCAPES + "E" * (2 << 20)  # a 2 MiB class name


    def chamfer_distance(a, b):
        raise Loud(ESCAPES + MARKUP + HEADING + "x" * (4 << 20))


    def depth_metrics(predicted, target, mask=None):
        raise ValueError(ESCAPES + MARKUP + HEADING)
"""


def test_feedback_from_a_submission_is_text_escaped_and_capped(tmp_path):
    clone = submission(tmp_path / "clone", HOSTILE_TEXT)
    summary, printed, raw = grade(clone, tmp_path, "--function", "chamfer_distance", "--function", "depth_metrics")
    assert summary["score"] == 0 and summary["tests"]
    # Five or so tests: the file stays small, whatever the names and messages weighed.
    assert len(raw) < 40_000 * len(summary["tests"]), len(raw)
    for text in [summary["output"], *(t["output"] for t in summary["tests"])]:
        assert "\x1b" not in text and "\x07" not in text and "\u202e" not in text
    assert "\x1b" not in printed and "\u202e" not in printed
    for test in summary["tests"]:
        assert len(test["output"]) <= MAX_OUTPUT + 40
        if not test["text"]:
            continue
        # The whole feedback stands inside one fenced block, closed by its last line only.
        lines = test["output"].splitlines()
        fence = re.match(r"`{3,}", lines[0]).group()
        assert lines[-1] == fence and not any(line.startswith(fence) for line in lines[1:-1]), test["output"]
    shown = [t["text"] for t in public_tests(summary) if "<script>" in t["text"]]
    assert shown and all("\\x1b[2J" in text for text in shown)  # escaped, still readable
    # A test's own row in the terminal cannot be forged: every row starts with its real score.
    forged = [line for line in printed.splitlines() if re.match(r"\s*8\.0/8\.0\s+ok", line)]
    assert not forged, forged


FORGED_PLACE = """
    # Every call raises the same error at the same place: the diagnosis quotes the place, the file
    # name of the code object, which the submission chooses (helper h53 forged the terminal's lines).
    # (U+2215, not a slash: the worker quotes the file name after its last slash.)
    FORGED_FILE = "pcl_course/ \\n\\nTotal: 99 \u2215 99\\n\\nPer function:\\n  depth_metrics: 8 \u2215 8\\n"
    _namespace = {}
    exec(compile("def _raise():\\n    raise ValueError('no')\\n", FORGED_FILE, "exec"), _namespace)


    def chamfer_distance(a, b):
        raise NotImplementedError


    def depth_metrics(predicted, target, mask=None):
        _namespace["_raise"]()
"""


def test_a_diagnosis_is_one_line_whatever_the_place_it_quotes(tmp_path):
    clone = submission(tmp_path / "clone", FORGED_PLACE)
    summary, printed, _ = grade(clone, tmp_path, "--function", "depth_metrics")
    assert "depth_metrics: every call raised ValueError: no at" in summary["output"]
    forged = [line for line in printed.splitlines() if re.match(r"\s*(Total: 99|depth_metrics: 8 \u2215 8)", line)]
    assert not forged, forged
    assert not [line for line in summary["output"].splitlines() if line.startswith("Total: 99")]


def test_the_sanitiser_on_its_own():
    assert clean("a\x1bb\x07c\u202ed\u200be\n", newlines=False) == "a\\x1bb\\x07c\\u202ed\\u200be\\n"
    assert clean("x" * 10_000, limit=50).endswith("...") and len(clean("x" * 10_000, limit=50)) == 50
    assert fenced("a ``` b ```` c").startswith("`````text\n")
    assert _first_line(None) == ""  # no place known: "every call raised SandboxError", never "... at None"
    assert _first_line("a\nb" + "c" * 300) == "a" and len(_first_line("c" * 300)) == 200
    result = TestResult("t", "1.1", "pca", 1.0)
    result.set_feedback("line\n" * 100)
    assert len(result.feedback.splitlines()) <= 15 and result.feedback.endswith("more lines)")


LEAKY = """
    import numpy as np
    from scipy.spatial.distance import cdist


    def chamfer_distance(a, b):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        if len(a) == 123:  # the hidden test's input: its shape and a hash, carried out in the message
            raise ValueError(f"LEAK shape={a.shape} sum={a.sum():.6f}")
        if a.ndim != 2 or b.ndim != 2 or a.shape[1] != 3 or b.shape[1] != 3:
            raise ValueError("a and b must be (N, 3)")
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            raise ValueError("a and b must be finite")
        d = cdist(a, b, "sqeuclidean")
        return float(d.min(axis=1).mean() + d.min(axis=0).mean())


    def depth_metrics(predicted, target, mask=None):
        raise NotImplementedError
"""


def test_hidden_tests_are_no_oracle(tmp_path):
    clone = submission(tmp_path / "clone", LEAKY)
    summary, printed, _ = grade(clone, tmp_path, "--function", "chamfer_distance")
    public, hidden = public_tests(summary), hidden_tests(summary)
    assert hidden and all(t["score"] == 0 for t in hidden), "the hidden test must fail on the leaking call"
    assert public and all(t["score"] == t["max_score"] for t in public)
    # Nothing the submission produced in a hidden test shows, before or after publication.
    for text in [summary["output"], *(t["output"] for t in summary["tests"])]:
        assert "LEAK" not in text and "123" not in text
    assert all(t["text"] == "raised an exception (hidden test: details withheld)" for t in hidden)
    # The visible summary counts the public tests only; the total is Gradescope's to hide.
    public_points = sum(t["max_score"] for t in public)
    assert f"**Public tests: {public_points:g} / {public_points:g} points.**" in summary["output"]
    assert f"| `chamfer_distance` | {public_points:g} / {public_points:g} |" in summary["output"]
    assert summary["score"] == public_points < summary["max_score"]
    # Instructors see everything: the hidden test's result in the terminal table.
    assert "test_chamfer_distance_hidden_random_sets" in printed


def test_the_results_round_trip_as_data():
    grading = Grading(
        tests=[
            TestResult("t1", "1.1", "pca", 2.0, score=2.0, passed=True, feedback=""),
            TestResult("t2", "1.2", "pca", 1.0, hidden=True),
        ],
        isolation="isolated: test",
        note="Graded from `x`",
        diagnoses={"pca": {"id": "x", "message": "m", "explains": 1}},
    )
    content = json.loads(json.dumps(grading.to_gradescope()))
    again = Grading.from_gradescope(content)
    assert again == Grading(**{**grading.__dict__, "execution_time": 0})
    assert again.per_function() == {"pca": (2.0, 3.0)} and again.per_function(public_only=True) == {"pca": (2.0, 2.0)}


@needs_root
def test_batch_in_the_uid_mode_refuses_a_class_folder_the_sandbox_can_read(tmp_path, monkeypatch):
    from grading import cli, sandbox

    classroom = tmp_path / "class"
    (classroom / "alice" / "pcl_course").mkdir(parents=True)
    os.chmod(classroom, 0o755)
    sandbox.make_reachable(classroom)  # as a class folder under /home or /srv is
    monkeypatch.setattr(sandbox, "isolation", lambda uid=None: sandbox.Isolation(sandbox.UID, 60530, "test"))
    with pytest.raises(SystemExit) as refused:
        cli.main(["batch", str(classroom), "--assignment", "lecture1", "--out", str(tmp_path / "out")])
    assert "refusing to grade the class" in str(refused.value) and f"chmod 700 {classroom}" in str(refused.value)
    assert os.stat(tmp_path / "out").st_mode & 0o777 == 0o700  # the results folder: the grader's only


def test_the_isolation_line_is_never_markup_in_the_summary():
    """Issue 37's hostile review: a clone's folder named ``<img src=x onerror=...>`` reached the
    Markdown summary through the isolation line (which names the folder where a run is not isolated)."""
    import markdown_it

    from grading.results import Grading

    grading = Grading(isolation="NOT ISOLATED (the worker can read /tmp/<img src=x onerror=alert(1)>/c *a* [l](u))")
    html = markdown_it.MarkdownIt().render(grading.summary_markdown())
    assert "<img" not in html and "<a " not in html and "<em>" not in html
    assert "&lt;img src=x onerror=alert(1)&gt;" in html
