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
    ".ci/run",
    "benchmarks/results",
]  # the appendix reads the results, not the harness
IGNORED = shutil.ignore_patterns("__pycache__", "*.pyc", ".ipynb_checkpoints")
# The catalogue of known mistakes computes right answers: it stays with the instructors.
WITHHELD = ("grading/mistakes",)

TEMPLATES = Path(__file__).with_name("templates")  # the student repository's own files


def _substitute(text, old, new, where, regex=False):
    """Replace ``old`` by ``new`` in ``text``, which must hold it exactly once.

    A release never silently ships an unchanged file because its source
    text moved on: a pattern found zero or several times stops the release.
    """
    if regex:
        text, count = re.subn(old, new, text, flags=re.M)
    else:
        count = text.count(old)
        text = text.replace(old, new)
    if count != 1:
        raise SystemExit(f"error: the release expects {old!r} exactly once in {where}, found it {count} times")
    return text


INSTRUCTOR_ONLY = "instructor-only"  # the class that keeps a {solution} out of the student release


def _strip_solutions(markdown):
    """Remove the ``{solution}`` directives of class ``instructor-only`` (colon or backtick fences).

    The other solutions are the answers of the book's self-checks, hidden
    behind a dropdown: students keep them.
    """
    for fence in (":", "`"):
        # The fence, the directive, its option lines up to a :class: naming INSTRUCTOR_ONLY,
        # then anything up to the same closing fence.
        pattern = (
            rf"^({re.escape(fence)}{{3,}})\{{solution\}}[^\n]*\n(?:(?!\1[ \t]*$)[^\n]*\n)*?"
            rf":class:[^\n]*\b{INSTRUCTOR_ONLY}\b[\s\S]*?^\1[ \t]*$\n?"
        )
        markdown = re.sub(pattern, "", markdown, flags=re.M)
    return markdown


def _student_config(text):
    # Cells of exercises a student has not done yet show "not implemented" instead of failing the build.
    text = _substitute(text, "  allow_errors: false", "  allow_errors: true", "_config.yml")
    return _substitute(
        text, "    nb_execution_raise_on_error: true", "    nb_execution_raise_on_error: false", "_config.yml"
    )


def _student_pyproject(text):
    # The student package and the grader only: no reference, no benchmark harness.
    text = _substitute(
        text, r"^packages = \[[^\]]*\]", 'packages = ["pcl_course", "grading"]', "pyproject.toml", regex=True
    )
    return _substitute(text, r"^testpaths = \[[^\]]*\]", 'testpaths = ["tests/graded"]', "pyproject.toml", regex=True)


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
            for withheld in WITHHELD:
                if withheld.startswith(f"{name}/"):
                    shutil.rmtree(out / withheld, ignore_errors=True)
        elif source.exists():
            (out / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, out / name)
    for page in (out / "book").glob("*.md"):
        page.write_text(_strip_solutions(page.read_text()))
    book_helper = out / "pcl_course" / "book.py"
    book_helper.write_text(
        _substitute(
            book_helper.read_text(), 'REFERENCE_PACKAGE = "solutions"', "REFERENCE_PACKAGE = None", "pcl_course/book.py"
        )
    )
    (out / "_config.yml").write_text(_student_config((REPO_ROOT / "_config.yml").read_text()))
    (out / "pyproject.toml").write_text(_student_pyproject((REPO_ROOT / "pyproject.toml").read_text()))
    for name in ("Makefile", "README.md"):
        shutil.copy2(TEMPLATES / name, out / name)
    workflow = out / ".github" / "workflows" / "check.yml"
    workflow.parent.mkdir(parents=True)
    workflow.write_text(_student_workflow(course_repository))
    return find_leaks(out)
