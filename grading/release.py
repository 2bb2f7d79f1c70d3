"""``python -m grading release OUT_DIR``: write the student repository.

What goes out: the stubs and helpers of ``pcl_course/``, the book sources
with every ``{solution}`` block removed, the public graded tests, the grader
(so that students see the same marks table), the set-up files, a student
README and a GitHub Classroom workflow. What stays: ``solutions/``, the
project's own tests, the wrong and alternative submissions, and any hidden
tests. The release is then scanned for the reference's code
(:mod:`grading.leakcheck`); a match fails the release.
"""

import re
import shutil
import textwrap
from pathlib import Path

from grading import GRADED_FUNCTIONS, REPO_ROOT
from grading.leakcheck import find_leaks

COPIED = ["pcl_course", "grading", "tests/graded", "book", "scripts", "_toc.yml", "requirements.txt",
          "requirements.in", ".gitignore", "benchmarks/results"]  # the appendix reads the results, not the harness
IGNORED = shutil.ignore_patterns("__pycache__", "*.pyc", ".ipynb_checkpoints")

STUDENT_MAKEFILE = """\
# 3D Point Cloud Processing, Lecture 1 (student repository)
#   make book    set up, then build the book with YOUR code into _build/html
#   make test    set up, then grade your pcl_course/ with the public tests
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.setup-done

.PHONY: setup book test

setup: $(STAMP)

$(STAMP): requirements.txt pyproject.toml scripts/system-deps.sh
\tbash scripts/system-deps.sh
\ttest -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
\t$(BIN)/python -m pip install --quiet --disable-pip-version-check -r requirements.txt
\t$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
\ttouch $@

# Cells that need an exercise you have not done yet show "not implemented".
book: setup
\trm -rf _build/.jupyter_cache _build/.doctrees
\t$(BIN)/jupyter-book build . -n --keep-going
\t@echo "The book is in _build/html: open $(CURDIR)/_build/html/index.html"

# The marks of the public tests; exits 0 whatever the score.
test: setup
\t$(BIN)/python -m grading grade . --results results/results.json
"""

STUDENT_README = """\
# 3D Point Cloud Processing, Lecture 1: exercises

```bash
make book    # set up, then build the book (it runs YOUR code) into _build/html
make test    # set up, then your marks on the public tests
```

`make setup` (run by both) installs `libusb-1.0-0`, `bubblewrap` and `chromium` with apt when
it can, a `.venv` with the pinned requirements, and this package.

## Workflow
1. Read a chapter in `_build/html` (or the book sources in `book/`).
2. Implement its exercises in `pcl_course/` (the stubs raise
   `NotImplementedError`; their docstrings are the contract).
3. Run the tests of one exercise, and see your marks:

   ```bash
   .venv/bin/python -m grading grade . -k test_pca_
   .venv/bin/pytest tests/graded -k test_pca_      # the same tests, with tracebacks
   ```

Write your own code: Open3D, PCL and scikit-learn are for visualisation
only, outside `pcl_course/`'s exercise modules. NumPy and SciPy (including
`scipy.spatial.cKDTree`) are allowed. The graded run checks this.

Your submission is graded with these public tests and with hidden tests of
the same contract.
"""


def _strip_solutions(markdown):
    """Remove ``{solution}`` directives (colon or backtick fences)."""
    markdown = re.sub(r"^(:{3,})\{solution\}.*?^\1[ \t]*$\n?", "", markdown, flags=re.S | re.M)
    return re.sub(r"^(`{3,})\{solution\}.*?^\1[ \t]*$\n?", "", markdown, flags=re.S | re.M)


def _student_config(text):
    text = text.replace("  allow_errors: false", "  allow_errors: true")
    text = text.replace("    nb_execution_raise_on_error: true", "    nb_execution_raise_on_error: false")
    return text


def _student_pyproject(text):
    # The student package and the grader only: no reference, no benchmark harness.
    text = re.sub(r'packages = \[[^\]]*\]', 'packages = ["pcl_course", "grading"]', text)
    return re.sub(r'testpaths = \[[^\]]*\]', 'testpaths = ["tests/graded"]', text)


def _points_per_function():
    """Points of each graded function, from a grading run of the reference."""
    import json
    import tempfile

    from grading import GRADED_TESTS
    from grading.cli import points_per_function, run_graded_tests

    results = Path(tempfile.mkdtemp()) / "results.json"
    run_graded_tests(REPO_ROOT / "solutions", results, tests=GRADED_TESTS)  # the public tests only
    return {f: maximum for f, (_, maximum) in points_per_function(json.loads(results.read_text())).items()}


def _classroom_workflow(points):
    """A GitHub Classroom workflow: one step per graded function, passing
    when that function gets full marks, worth that function's points."""
    ids = [f.replace("_", "-") for f in GRADED_FUNCTIONS]
    lines = [
        "# GitHub Classroom: runs the public tests, one step per graded function",
        "# (a step passes when its function gets full marks), and reports the points.",
        "name: Autograding Tests",
        "on: [push, workflow_dispatch, repository_dispatch]",
        "permissions:",
        "  checks: write",
        "  actions: read",
        "  contents: read",
        "jobs:",
        "  run-autograding-tests:",
        "    runs-on: ubuntu-latest",
        "    if: github.actor != 'github-classroom[bot]'",
        "    steps:",
        "      - uses: actions/checkout@v4",
        "      - uses: actions/setup-python@v5",
        "        with:",
        '          python-version: "3.11"',
        "      - name: Set up",
        "        run: |",
        "          sudo apt-get update && sudo apt-get install -y libusb-1.0-0",
        "          python -m pip install -r requirements.txt && python -m pip install --no-deps -e .",
    ]
    for function, step_id in zip(GRADED_FUNCTIONS, ids):
        # -k test_kernel_pca_ would also select test_kernel_pca_transform_...
        longer = [g for g in GRADED_FUNCTIONS if g != function and g.startswith(function + "_")]
        keyword = " and ".join([f"test_{function}_"] + [f"not test_{g}_" for g in longer])
        lines += [
            f"      - name: {function}",
            f"        id: {step_id}",
            "        uses: classroom-resources/autograding-command-grader@v1",
            "        with:",
            f"          test-name: {function}",
            f"          command: python -m grading grade . -k '{keyword}' --require-full",
            "          timeout: 10",
            f"          max-score: {points.get(function, 0):g}",
        ]
    lines += [
        "      - name: Autograding Reporter",
        "        uses: classroom-resources/autograding-grading-reporter@v1",
        "        env:",
        *[f"          {i.upper().replace('-', '_')}_RESULTS: \"${{{{steps.{i}.outputs.result}}}}\"" for i in ids],
        "        with:",
        f"          runners: {','.join(ids)}",
    ]
    return "\n".join(lines) + "\n"


def release(out_dir):
    """Write the student repository to ``out_dir``; return the list of leaks (empty when clean)."""
    out = Path(out_dir).resolve()
    if out.exists() and any(out.iterdir()):
        raise SystemExit(f"error: {out} exists and is not empty")
    out.mkdir(parents=True, exist_ok=True)
    for name in COPIED:
        source = REPO_ROOT / name
        if source.is_dir():
            shutil.copytree(source, out / name, ignore=IGNORED)
        elif source.exists():
            (out / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, out / name)
    for page in (out / "book").glob("*.md"):
        page.write_text(_strip_solutions(page.read_text()))
    book_helper = out / "pcl_course" / "book.py"
    book_helper.write_text(book_helper.read_text().replace(
        'REFERENCE_PACKAGE = "solutions"', "REFERENCE_PACKAGE = None"))
    (out / "_config.yml").write_text(_student_config((REPO_ROOT / "_config.yml").read_text()))
    (out / "pyproject.toml").write_text(_student_pyproject((REPO_ROOT / "pyproject.toml").read_text()))
    (out / "Makefile").write_text(STUDENT_MAKEFILE)
    (out / "README.md").write_text(STUDENT_README)
    (out / ".ci").mkdir(exist_ok=True)
    (out / ".ci" / "run").write_text("#!/usr/bin/env bash\nset -euo pipefail\ncd \"$(dirname \"$0\")/..\"\nmake test\n")
    workflow = out / ".github" / "workflows" / "classroom.yml"
    workflow.parent.mkdir(parents=True)
    workflow.write_text(_classroom_workflow(_points_per_function()))
    return find_leaks(out)
