"""``python -m grading release OUT_DIR``: write the student repository.

What goes out: the stubs and helpers of ``pcl_course/``, the book sources
with every instructor-only ``{solution}`` block removed, the public graded
tests, the grader's runtime (so that students see the same marks table), the
student's set-up files and pins (``requirements/student.txt`` for the book,
``requirements/grading.txt`` for the workflow), a student README and a GitHub
Actions workflow (the advisory check). What stays: ``solutions/``, the
project's own tests, the wrong and alternative submissions, any hidden tests,
CI, and the instructors' tools (:data:`grading.instructors.shipping.WITHHELD`, this whole folder).
The release is then scanned for the reference's code (:mod:`grading.instructors.leakcheck`);
a match fails the release.
"""

import hashlib
import re
import shutil
from pathlib import Path

import yaml

from grading import ASSIGNMENTS, EXERCISE_MODULES, HIDDEN_TESTS, REPO_ROOT
from grading.config import FORBIDDEN_PACKAGES
from grading.errors import VISUALISATION_ONLY
from grading.hidden import POINTS_FILE, write_points_file
from grading.instructors.leakcheck import find_leaks
from grading.instructors.shipping import IGNORED, WITHHELD, cut_reference_link, substitute

COPIED = [
    "pcl_course",
    "grading",
    "tests/graded",
    "book",
    "scripts/setup.mk",
    "scripts/system-deps.sh",
    "scripts/check_python.py",
    "_toc.yml",
    "requirements/student.txt",
    "requirements/grading.txt",
    ".gitignore",
    "benchmarks/results",  # the appendix reads the results, not the harness
]

TEMPLATES = Path(__file__).with_name("templates")  # the student repository's own files
WORKFLOW = ".github/workflows/check.yml"  # the students' advisory check
CHECK_SCRIPT = ".github/check_grader.py"  # its test of the grader (templates/check_grader.py)
PRISTINE = ".github/pristine/pcl_course"  # the released stubs: the grader's pcl_course when no course is named
# Everything the workflow runs or reads as the grader: its code, public tests,
# package set-up and pins, the check itself, and the stubs whose signatures it reads.
GRADER_FILES = ("grading", "tests/graded", "pyproject.toml", "requirements/grading.txt", CHECK_SCRIPT, PRISTINE)
GRADER_MANIFEST = ".github/grader.sha256"
# What must be identical to the course repository's copy when one is named.
COMPARED = (*GRADER_FILES, GRADER_MANIFEST, WORKFLOW)


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
    text = substitute(text, "  allow_errors: false", "  allow_errors: true", "_config.yml")
    text = substitute(
        text, "    nb_execution_raise_on_error: true", "    nb_execution_raise_on_error: false", "_config.yml"
    )
    # ... and a sentence whose number such a cell would give says so (book/_ext/missing_results.py),
    # without a warning per sentence.
    return substitute(
        text,
        'suppress_warnings: ["mystnb.unknown_mime_type"]',
        'suppress_warnings: ["mystnb.unknown_mime_type", "mystnb.glue"]',
        "_config.yml",
    )


def _student_pyproject(text):
    # The student package and the grader only: no reference, no benchmark harness.
    text = substitute(
        text, r"^packages = \[[^\]]*\]", 'packages = ["pcl_course", "grading"]', "pyproject.toml", regex=True
    )
    text = substitute(text, r"^testpaths = \[[^\]]*\]", 'testpaths = ["tests/graded"]', "pyproject.toml", regex=True)
    text = substitute(text, "[tool.ruff.lint]\n", '[tool.ruff.lint]\nextend-select = ["TID251"]\n', "pyproject.toml")
    modules = ",".join(EXERCISE_MODULES)  # the banned-api rules hold in the exercise modules only
    text = substitute(
        text,
        "[tool.ruff.lint.per-file-ignores]\n",
        f'[tool.ruff.lint.per-file-ignores]\n"!pcl_course/{{{modules}}}.py" = ["TID251"]\n',
        "pyproject.toml",
    )
    return text + banned_api_config()


def banned_api_config():
    """The student ``pyproject.toml``'s ruff ``banned-api`` (TID251) rules, from :mod:`grading.config`'s lists.

    An import of a package forbidden in every exercise module is flagged in
    those modules, with the grader's own words; the rest of the repository
    (the helpers, the book) may use them. ruff keeps one list per
    configuration (astral-sh/ruff#7696), so ``nn.py``'s own rules
    (``scipy.spatial``, ...) are the grader's scan alone.
    """
    lines = [
        "",
        "# Generated by the release from grading/config.py: the grader's forbidden packages, flagged by ruff",
        "# (TID251) in the exercise modules as you type. nn.py's own rules are checked when grading only.",
        "[tool.ruff.lint.flake8-tidy-imports.banned-api]",
        *[
            f'"{package}".msg = "forbidden in the exercise modules: write your own code; {VISUALISATION_ONLY}"'
            for package in FORBIDDEN_PACKAGES
        ],
    ]
    return "\n".join(lines) + "\n"


WORKFLOW_HEADER = """\
# The advisory check: on a push that changes pcl_course/, on a tag, or by hand,
# the public tests grade this repository's pcl_course/ with a pristine grader,
# in its bubblewrap sandbox; the marks go to the run's summary and results.json
# is kept as an artifact. The grader is either the course
# repository's (COURSE_REPOSITORY below, or the repository variable
# PCL_COURSE_REPOSITORY; a private one needs a read token in the secret
# PCL_COURSE_TOKEN), checked out at the release's tag (COURSE_REF), to which
# this repository's grader must be identical; or, when none is named, this
# repository's own copy, used only if it matches the release's manifest
# (.github/grader.sha256, whose digest is GRADER_DIGEST below). A link
# anywhere in the grader refuses the check. You control this repository and
# this workflow, so this mark is advisory: the official mark is the
# instructor's (Gradescope, or their re-grade of your submission).
"""


class _WorkflowDumper(yaml.SafeDumper):
    """``yaml.safe_dump`` with multi-line strings as literal blocks (``run: |``)."""


_WorkflowDumper.add_representer(
    str,
    lambda dumper, text: dumper.represent_scalar("tag:yaml.org,2002:str", text, style="|" if "\n" in text else None),
)

ACTIONS = {
    "checkout": "actions/checkout@v6",
    "setup-python": "actions/setup-python@v6",
    "upload-artifact": "actions/upload-artifact@v7",
}
CHECKED = "grader-check.txt"  # the check's lines, for the summary (in the runner's workspace)

CHOOSE_GRADER = """\
if [ -n "$COURSE_REPOSITORY" ]; then
  echo "source=course" >> "$GITHUB_OUTPUT"
  echo "Grading with the course repository $COURSE_REPOSITORY's grader at $COURSE_REF"
else
  echo "source=hashes" >> "$GITHUB_OUTPUT"
  echo "No course repository named: grading with this repository's grader, if it matches the release's manifest"
fi"""

COMPARE = f"""\
# The course's own check script, on this repository's grader against the course's (list, kinds, bytes).
set -o pipefail
python3 -I course/{CHECK_SCRIPT} submission {" ".join(COMPARED)} --course course | tee {CHECKED}"""

CHECK_HASHES = f"""\
# This repository's grader against the release's manifest, whose digest the workflow records.
set -o pipefail
python3 -I submission/{CHECK_SCRIPT} submission {" ".join(GRADER_FILES)} \\
  --manifest {GRADER_MANIFEST} --digest "$GRADER_DIGEST" | tee {CHECKED}
# The grader as checked, and the released stubs as its pcl_course (never the submission's).
mkdir course
(cd submission && cp -a --parents {" ".join(name for name in GRADER_FILES if name != PRISTINE)} ../course/)
cp -a submission/{PRISTINE} course/pcl_course"""

SET_UP = """\
sudo apt-get update -qq
sudo apt-get install -y -qq --no-install-recommends bubblewrap
# Ubuntu 24.04 lets AppArmor forbid unprivileged user namespaces; bubblewrap needs them.
sudo sysctl -w kernel.apparmor_restrict_unprivileged_userns=0 || true
python -m pip install --quiet -r course/requirements/grading.txt
python -m pip install --quiet --no-deps -e course
mkdir -p results"""

GRADE = """\
set -o pipefail
python -m grading grade ../submission --require-isolation ${ASSIGNMENT:+--assignment "$ASSIGNMENT"} \\
  --results ../results/results.json | tee ../results/marks.txt"""

SUMMARY = f"""\
{{
  echo '## Advisory marks (public tests)'
  echo
  if [ -s results/marks.txt ] && [ "$GRADE" = success ]; then
    if [ "$SOURCE" = course ]; then
      echo "Grader: the course repository $COURSE_REPOSITORY at $COURSE_REF, whose copy ran here. This" \\
           "repository's grader, public tests and workflow were compared with it entry by entry:" \\
           "identical, with no link."
    else
      echo "Grader: this repository's own copy, identical to its manifest {GRADER_MANIFEST} (SHA-256" \\
           "$GRADER_DIGEST, recorded in this workflow), with no link. No course repository is named, so it" \\
           "was compared with nothing the student cannot rewrite: compare that digest with the course's."
    fi
    echo
    # The results' own Markdown (the marks per function and what each mistake is), as Gradescope shows it.
    python3 -c 'import json; print(json.load(open("results/results.json"))["output"])' 2> /dev/null \
      || {{ echo '```'; cat results/marks.txt; echo '```'; }}
  elif [ "$COURSE" = failure ]; then
    echo "Grading did not run: the course repository $COURSE_REPOSITORY could not be checked out at" \\
         "$COURSE_REF. If it is private, the instructor adds a read-only token as the secret" \\
         "PCL_COURSE_TOKEN; the release's commit must carry the tag $COURSE_REF."
  elif [ "$COMPARE" = failure ] || [ "$HASHES" = failure ]; then
    echo "Grading did not run: this repository's grader ({", ".join(GRADER_FILES)}) is not the" \\
         "release's, or holds a link. Restore those files as released (the course repository's):"
    echo
    echo '```'
    head -n 25 {CHECKED} 2> /dev/null || true
    echo '```'
  elif [ "$SETUP" != success ]; then
    echo "Grading did not run: the set-up step failed ($SETUP); see its log."
  else
    echo "Grading failed ($GRADE); see the grading step's log."
  fi
  echo
  echo "What this does not prove: this workflow runs from this repository, and whoever can push to it" \\
       "can change the workflow itself, so this mark is advisory. The official mark is Gradescope's or" \\
       "the instructor's re-grade, which read only the submission's pcl_course/ and never run its grader."
}} >> "$GITHUB_STEP_SUMMARY"
"""


def course_tag(digest):
    """The tag of the course repository's release commit, from its grader's manifest digest."""
    return f"grader-{digest[:12]}"


def _student_workflow(course_repository, digest, course_ref=None):
    """A plain GitHub Actions workflow (no GitHub Classroom): the advisory check.

    Parameters
    ----------
    course_repository : str or None
        ``OWNER/NAME`` of the instructor's student repository, checked out
        at ``course_ref``: this repository's :data:`COMPARED` files must be
        identical to its, and its copy grades. ``None`` reads it from the
        repository variable ``PCL_COURSE_REPOSITORY``; when that is empty
        too, the workflow grades with this repository's own grader only if
        it matches :data:`GRADER_MANIFEST`, whose SHA-256 is ``digest``.
    digest : str
        The SHA-256 of the release's :data:`GRADER_MANIFEST`.
    course_ref : str, optional
        The course repository's tag or commit of this release (default
        :func:`course_tag`); the repository variable ``PCL_COURSE_REF`` overrides it.
    """
    repository = course_repository or "${{ vars.PCL_COURSE_REPOSITORY }}"
    source = "steps.grader.outputs.source"
    workflow = {
        "name": "Advisory check",
        # A push that changes pcl_course/ (not every push: large classes), any tag, or by hand.
        "on": {
            "push": {"branches": ["**"], "tags": ["**"], "paths": ["pcl_course/**"]},
            "workflow_dispatch": {
                "inputs": {
                    "assignment": {
                        "description": f"the lecture to grade ({', '.join(sorted(ASSIGNMENTS))}; empty: every one)",
                        "required": False,
                        "default": "",
                        "type": "string",
                    }
                }
            },
        },
        "permissions": {"contents": "read"},
        "jobs": {
            "check": {
                "runs-on": "ubuntu-24.04",
                "timeout-minutes": 30,
                "env": {
                    "COURSE_REPOSITORY": repository,
                    "COURSE_REF": f"${{{{ vars.PCL_COURSE_REF || '{course_ref or course_tag(digest)}' }}}}",
                    "GRADER_DIGEST": digest,
                    # The lecture graded: the run's input, else the repository variable, else every one.
                    "ASSIGNMENT": "${{ inputs.assignment || vars.PCL_ASSIGNMENT }}",
                },
                "steps": [
                    {
                        "name": "Check out this repository (the submission)",
                        "uses": ACTIONS["checkout"],
                        "with": {"path": "submission", "persist-credentials": False},
                    },
                    {"name": "Choose the grader", "id": "grader", "run": CHOOSE_GRADER},
                    {
                        "name": "Check out the pristine course at the release's tag (its grader and public tests)",
                        "id": "course",
                        "if": f"{source} == 'course'",
                        "uses": ACTIONS["checkout"],
                        "with": {
                            "repository": "${{ env.COURSE_REPOSITORY }}",
                            "ref": "${{ env.COURSE_REF }}",
                            "token": "${{ secrets.PCL_COURSE_TOKEN || github.token }}",
                            "path": "course",
                            "persist-credentials": False,
                        },
                    },
                    {
                        "name": "Compare this repository's grader with the course's",
                        "id": "compare",
                        "if": f"{source} == 'course'",
                        "run": COMPARE,
                    },
                    {
                        "name": "Or check this repository's grader against the release's manifest",
                        "id": "hashes",
                        "if": f"{source} == 'hashes'",
                        "run": CHECK_HASHES,
                    },
                    {
                        "uses": ACTIONS["setup-python"],
                        "with": {
                            "python-version": "3.11",
                            "cache": "pip",
                            "cache-dependency-path": "course/requirements/grading.txt",
                        },
                    },
                    {"name": "Set up (bubblewrap, the lean grading environment)", "id": "setup", "run": SET_UP},
                    {
                        "name": "Grade with the pristine grader (advisory)",
                        "id": "grade",
                        "working-directory": "course",
                        "run": GRADE,
                    },
                    {
                        "name": "Write the marks, or why there are none, to the summary",
                        "if": "always()",
                        "env": {
                            "SOURCE": f"${{{{ {source} }}}}",
                            "COURSE": "${{ steps.course.outcome }}",
                            "COMPARE": "${{ steps.compare.outcome }}",
                            "HASHES": "${{ steps.hashes.outcome }}",
                            "SETUP": "${{ steps.setup.outcome }}",
                            "GRADE": "${{ steps.grade.outcome }}",
                        },
                        "run": SUMMARY,
                    },
                    {
                        "name": "Keep results.json as an artifact of the run",
                        "if": "always()",
                        "uses": ACTIONS["upload-artifact"],
                        "with": {"name": "results", "path": "results/", "if-no-files-found": "ignore"},
                    },
                ],
            }
        },
    }
    return WORKFLOW_HEADER + yaml.dump(workflow, Dumper=_WorkflowDumper, sort_keys=False, width=120)


def _grader_manifest(out):
    """``sha256sum`` lines of every file of :data:`GRADER_FILES` in the release."""
    files = []
    for name in GRADER_FILES:  # no link in the release: copytree copies a link's target
        path = out / name
        files += sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    return "".join(f"{hashlib.sha256(p.read_bytes()).hexdigest()}  {p.relative_to(out).as_posix()}\n" for p in files)


def grader_digest(out):
    """The SHA-256 of the release's :data:`GRADER_MANIFEST` (the digest the course publishes)."""
    return hashlib.sha256((Path(out) / GRADER_MANIFEST).read_bytes()).hexdigest()


def release(out_dir, course_repository=None, course_ref=None):
    """Write the student repository to ``out_dir``; return the list of leaks (empty when clean).

    ``course_repository`` (``OWNER/NAME``) is where the students' advisory
    workflow checks out the pristine grader, at ``course_ref`` (default: the
    tag :func:`course_tag` names); see :func:`_student_workflow`.
    """
    out = Path(out_dir).resolve()
    if out.exists() and any(out.iterdir()):
        raise SystemExit(f"error: {out} exists and is not empty")
    out.mkdir(parents=True, exist_ok=True)
    for name in COPIED:
        source = REPO_ROOT / name
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        if source.is_dir():
            shutil.copytree(source, out / name, ignore=IGNORED)
        else:
            shutil.copy2(source, out / name)
    shutil.rmtree(out / WITHHELD)  # the instructors' tools: all of them, and only them
    write_points_file(HIDDEN_TESTS, out / POINTS_FILE.relative_to(REPO_ROOT))  # what the local table announces
    for page in (out / "book").glob("*.md"):
        page.write_text(_strip_solutions(page.read_text()))
    cut_reference_link(out / "pcl_course")
    (out / "_config.yml").write_text(_student_config((REPO_ROOT / "_config.yml").read_text()))
    (out / "pyproject.toml").write_text(_student_pyproject((REPO_ROOT / "pyproject.toml").read_text()))
    for name in ("Makefile", "README.md", "requirements.txt"):
        shutil.copy2(TEMPLATES / name, out / name)
    (out / CHECK_SCRIPT).parent.mkdir(parents=True)
    shutil.copy2(TEMPLATES / Path(CHECK_SCRIPT).name, out / CHECK_SCRIPT)
    shutil.copytree(out / "pcl_course", out / PRISTINE)
    (out / GRADER_MANIFEST).write_text(_grader_manifest(out))
    (out / WORKFLOW).parent.mkdir(parents=True)
    (out / WORKFLOW).write_text(_student_workflow(course_repository, grader_digest(out), course_ref))
    return find_leaks(out)
