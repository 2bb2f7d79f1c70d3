"""``python -m grading release OUT_DIR``: write the student repository.

What goes out: the stubs and helpers of ``pcl_course/``, the book sources
with every ``{solution}`` block removed, the public graded tests, the grader
(so that students see the same marks table), the set-up files, a student
README and a GitHub Actions workflow (the advisory check). What stays: ``solutions/``, the
project's own tests, the wrong and alternative submissions, and any hidden
tests. The release is then scanned for the reference's code
(:mod:`grading.leakcheck`); a match fails the release.
"""

import re
import shutil
from pathlib import Path

import yaml

from grading import REPO_ROOT
from grading.leakcheck import find_leaks

COPIED = [
    "pcl_course",
    "grading",
    "tests/graded",
    "book",
    "scripts",
    "_toc.yml",
    "requirements.txt",
    "requirements.in",
    ".gitignore",
    "benchmarks/results",
]  # the appendix reads the results, not the harness
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
the same contract, in a sandbox that sees nothing but your `pcl_course/`.

On every push, `.github/workflows/check.yml` grades your code with a pristine
copy of the course's grader and writes the table to the run's summary. That
mark, like `make test`'s, is **advisory** (you control this repository and
its CI): the official mark is the instructor's, on Gradescope or from their
re-grade of your submission.
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
    text = re.sub(r"packages = \[[^\]]*\]", 'packages = ["pcl_course", "grading"]', text)
    return re.sub(r"testpaths = \[[^\]]*\]", 'testpaths = ["tests/graded"]', text)


WORKFLOW_HEADER = """\
# The advisory check: on every push, the public tests grade this repository's
# pcl_course/ with a PRISTINE copy of the course's grader (not this
# repository's grading/ or tests/), in its bubblewrap sandbox, and the marks
# table goes to the run's summary. You control this repository, so this mark
# is advisory: the official mark is the instructor's (Gradescope, or their
# re-grade of your submission).
"""


class _WorkflowDumper(yaml.SafeDumper):
    """``yaml.safe_dump`` with multi-line strings as literal blocks (``run: |``)."""


_WorkflowDumper.add_representer(
    str,
    lambda dumper, text: dumper.represent_scalar("tag:yaml.org,2002:str", text, style="|" if "\n" in text else None),
)


SETUP_COMMANDS = [
    "sudo apt-get update",
    "sudo apt-get install -y --no-install-recommends libusb-1.0-0 bubblewrap",
    "# Ubuntu 24.04 lets AppArmor forbid unprivileged user namespaces; bubblewrap needs them.",
    "sudo sysctl -w kernel.apparmor_restrict_unprivileged_userns=0 || true",
    "python -m pip install --quiet -r course/requirements.txt",
    "python -m pip install --quiet --no-deps -e course",
    "mkdir -p results",
]


def _student_workflow(course_repository):
    """A plain GitHub Actions workflow (no GitHub Classroom): the advisory check.

    ``course_repository`` is the instructor's student repository
    (``OWNER/NAME``) whose grader and public tests are checked out pristine;
    ``None`` reads it from the repository variable ``PCL_COURSE_REPOSITORY``.
    """
    repository = course_repository or "${{ vars.PCL_COURSE_REPOSITORY }}"
    grade = " ".join(
        [
            "python -m grading grade ../submission --require-isolation --results ../results/results.json",
            "| tee ../results/marks.txt",
        ]
    )
    summary = "\n".join(
        [
            "{",
            "  echo '## Advisory marks (public tests)'",
            "  echo",
            "  echo 'The official mark is the instructor'\\''s re-grade (or Gradescope).'",
            "  echo",
            "  echo '```'",
            "  cat ../results/marks.txt",
            "  echo '```'",
            '} >> "$GITHUB_STEP_SUMMARY"',
        ]
    )
    workflow = {
        "name": "Advisory check",
        "on": {"push": None, "workflow_dispatch": None},
        "permissions": {"contents": "read"},
        "jobs": {
            "check": {
                "runs-on": "ubuntu-24.04",
                "timeout-minutes": 30,
                "steps": [
                    {
                        "name": "Check out this repository (the submission)",
                        "uses": "actions/checkout@v4",
                        "with": {"path": "submission"},
                    },
                    {
                        "name": "Check out the pristine course (its grader and public tests)",
                        "uses": "actions/checkout@v4",
                        "with": {
                            "repository": repository,
                            "ref": "${{ vars.PCL_COURSE_REF || 'main' }}",
                            "path": "course",
                        },
                    },
                    {"uses": "actions/setup-python@v5", "with": {"python-version": "3.11"}},
                    {
                        "name": "Set up (Debian packages, pinned requirements, the sandbox)",
                        "run": "\n".join(SETUP_COMMANDS),
                    },
                    {
                        "name": "Grade with the pristine grader (advisory)",
                        "working-directory": "course",
                        "run": f"set -o pipefail\n{grade}",
                    },
                    {
                        "name": "Write the marks to the summary",
                        "if": "always()",
                        "working-directory": "course",
                        "run": summary,
                    },
                ],
            }
        },
    }
    return WORKFLOW_HEADER + yaml.dump(workflow, Dumper=_WorkflowDumper, sort_keys=False, width=120)


def release(out_dir, course_repository=None):
    """Write the student repository to ``out_dir``; return the list of leaks (empty when clean).

    ``course_repository`` (``OWNER/NAME``) is where the students' advisory
    workflow checks out the pristine grader; see :func:`_student_workflow`.
    """
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
    book_helper.write_text(
        book_helper.read_text().replace('REFERENCE_PACKAGE = "solutions"', "REFERENCE_PACKAGE = None")
    )
    (out / "_config.yml").write_text(_student_config((REPO_ROOT / "_config.yml").read_text()))
    (out / "pyproject.toml").write_text(_student_pyproject((REPO_ROOT / "pyproject.toml").read_text()))
    (out / "Makefile").write_text(STUDENT_MAKEFILE)
    (out / "README.md").write_text(STUDENT_README)
    (out / ".ci").mkdir(exist_ok=True)
    (out / ".ci" / "run").write_text('#!/usr/bin/env bash\nset -euo pipefail\ncd "$(dirname "$0")/.."\nmake test\n')
    workflow = out / ".github" / "workflows" / "check.yml"
    workflow.parent.mkdir(parents=True)
    workflow.write_text(_student_workflow(course_repository))
    return find_leaks(out)
