"""The student release (python -m grading release): what ships, what does
not, that its grader gives the stubs 0 points without an error, and that
the reference's code is caught if it slips in."""

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib

import pytest
import yaml
from _helpers import STEP_BACKSTOP, SUBPROCESS_BACKSTOP, load_results

from grading import EXERCISE_MODULES, REPO_ROOT
from grading.hidden import hidden_points
from grading.instructors.leakcheck import find_leaks
from grading.instructors.shipping import WITHHELD


@pytest.fixture(scope="module")
def release_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("release") / "student"
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "release", str(out)],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return out


def test_the_release_holds_what_students_need_and_nothing_else(release_dir):
    for needed in (
        "Makefile",
        "README.md",
        "requirements/student.txt",
        "requirements/grading.txt",
        "pyproject.toml",
        "_config.yml",
        "_toc.yml",
        ".github/workflows/check.yml",
        ".github/grader.sha256",
        "scripts/system-deps.sh",
        "scripts/check_python.py",
        "pcl_course/pca.py",
        "grading/cli.py",
        "tests/graded/test_pca.py",
        "book/pca.md",
    ):
        assert (release_dir / needed).exists(), needed
    for absent in (
        "solutions",
        "grading/instructors/mistakes",
        "tests/mutants",
        "tests/alternatives",
        "tests/project",
        "tests/hidden",
        ".git",
        ".ci",
        "requirements/course.txt",
        "requirements/course.in",
        WITHHELD,
    ):
        assert not (release_dir / absent).exists(), absent
    for module in EXERCISE_MODULES:
        assert (release_dir / "pcl_course" / f"{module}.py").read_bytes() == (
            REPO_ROOT / "pcl_course" / f"{module}.py"
        ).read_bytes()
    assert "REFERENCE_PACKAGE = None" in (release_dir / "pcl_course" / "book.py").read_text()
    top = [line for line in (release_dir / "requirements.txt").read_text().splitlines() if not line.startswith("#")]
    assert top == ["-r requirements/student.txt"]  # pip install -r requirements.txt: the student's set


def test_instructor_solutions_are_removed_and_self_check_answers_kept(release_dir):
    from grading.instructors.release import _strip_solutions

    page = (
        "Intro.\n\n:::{exercise}\n:label: a\nQuestion A.\n:::\n\n"
        ":::{solution} a\n:class: dropdown\nAnswer A.\n:::\n\n"
        ":::{solution} b\n:class: dropdown instructor-only\nAnswer B.\n:::\n\n"
        "````{solution} c\n:class: instructor-only\nAnswer C.\n````\nOutro.\n"
    )
    stripped = _strip_solutions(page)
    assert "Answer A." in stripped and "Question A." in stripped and "Outro." in stripped
    assert "Answer B." not in stripped and "Answer C." not in stripped
    for page in (release_dir / "book").glob("*.md"):
        assert "instructor-only" not in page.read_text(), page.name
    released = (release_dir / "book" / "downsampling.md").read_text()
    assert "{solution} cyu-voxel-indices" in released  # the self-checks keep their answers


def test_the_release_contains_no_reference_code(release_dir):
    assert find_leaks(release_dir) == []


def test_the_leak_check_sees_through_renaming(release_dir, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(release_dir, copy)
    # The reference chamfer_distance with every name changed, and a docstring.
    renamed = (
        "import numpy as np\n"
        "from scipy.spatial import cKDTree\n"
        "from pcl_course.validation import as_points\n\n\n"
        "def chamfer_distance(p, q):\n"
        '    """My own work."""\n'
        "    p = as_points(p, 'a', allow_empty=False)[:, :3]\n"
        "    q = as_points(q, 'b', allow_empty=False)[:, :3]\n"
        "    there = cKDTree(q).query(p)[0]\n"
        "    back = cKDTree(p).query(q)[0]\n"
        "    return float(np.mean(there**2) + np.mean(back**2))\n"
    )
    (copy / "pcl_course" / "metrics.py").write_text(renamed)
    leaks = find_leaks(copy)
    assert any("chamfer_distance" in leak and "metrics.py" in leak for leak in leaks), leaks


def workflow_steps(text):
    return {step.get("id", step.get("name")): step for step in yaml.safe_load(text)["jobs"]["check"]["steps"]}


def test_the_workflow_grades_with_a_pristine_grader_in_the_sandbox(release_dir):
    from grading.instructors.release import GRADER_MANIFEST, grader_digest

    text = (release_dir / ".github" / "workflows" / "check.yml").read_text()
    assert "classroom" not in text.lower() and "advisory" in text.lower()
    workflow = yaml.safe_load(text)
    env = workflow["jobs"]["check"]["env"]
    assert env["COURSE_REPOSITORY"] == "${{ vars.PCL_COURSE_REPOSITORY }}"
    # The release records its manifest's digest, and the course's tag named after it.
    digest = grader_digest(release_dir)
    assert digest == hashlib.sha256((release_dir / GRADER_MANIFEST).read_bytes()).hexdigest()
    assert env["GRADER_DIGEST"] == digest
    assert env["COURSE_REF"] == f"${{{{ vars.PCL_COURSE_REF || 'grader-{digest[:12]}' }}}}"
    steps = workflow_steps(text)
    uses = {step["uses"].split("@")[0]: step["uses"].split("@")[1] for step in steps.values() if "uses" in step}
    assert uses == {"actions/checkout": "v6", "actions/setup-python": "v6", "actions/upload-artifact": "v7"}
    # A private course repository is read with the instructors' token, at the release's tag.
    assert steps["course"]["with"]["token"] == "${{ secrets.PCL_COURSE_TOKEN || github.token }}"
    assert steps["course"]["with"]["ref"] == "${{ env.COURSE_REF }}"
    assert steps["course"]["if"] == steps["compare"]["if"] == "steps.grader.outputs.source == 'course'"
    assert steps["hashes"]["if"] == "steps.grader.outputs.source == 'hashes'"
    # The course's check script judges this repository's grader, not this repository's own script.
    assert "python3 -I course/.github/check_grader.py submission" in steps["compare"]["run"]
    python = next(step for step in steps.values() if step.get("uses", "").startswith("actions/setup-python"))
    assert python["with"]["cache"] == "pip"
    assert steps["grade"]["working-directory"] == "course"
    assert "../submission" in steps["grade"]["run"] and "--require-isolation" in steps["grade"]["run"]
    assert "bubblewrap" in steps["setup"]["run"] and "course/requirements/grading.txt" in steps["setup"]["run"]
    summary = next(step for step in steps.values() if "GITHUB_STEP_SUMMARY" in step.get("run", ""))
    assert summary["if"] == "always()" and "working-directory" not in summary


def test_the_workflow_names_the_course_repository_when_given(tmp_path):
    from grading.instructors.release import _student_workflow

    workflow = yaml.safe_load(_student_workflow("cs-dept/pcl-course-2027", "ab" * 32, "v2027.1"))
    assert workflow["jobs"]["check"]["env"]["COURSE_REPOSITORY"] == "cs-dept/pcl-course-2027"
    assert workflow["jobs"]["check"]["env"]["COURSE_REF"] == "${{ vars.PCL_COURSE_REF || 'v2027.1' }}"


def run_step(step, cwd, env=None, timeout=STEP_BACKSTOP):
    return subprocess.run(
        ["bash", "-e", "-c", step["run"]],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, **(env or {})},
    )


PRISTINE_COPY = shutil.ignore_patterns("_build", "r.json", "results", "__pycache__", ".git")


@pytest.fixture(scope="module")
def course_clone(release_dir, tmp_path_factory):
    """The course repository as the workflow checks it out: a git clone of the release as committed."""
    source = tmp_path_factory.mktemp("course") / "source"
    shutil.copytree(release_dir, source, ignore=PRISTINE_COPY)
    git = ["git", "-c", "user.name=course", "-c", "user.email=course@example.org", "-c", "init.defaultBranch=main"]
    for command in (["init", "-q"], ["add", "-A"], ["commit", "-q", "-m", "release"]):
        subprocess.run([*git, *command], cwd=source, check=True, capture_output=True, timeout=STEP_BACKSTOP)
    clone = source.parent / "clone"
    subprocess.run(
        [*git, "clone", "-q", str(source), str(clone)], check=True, capture_output=True, timeout=STEP_BACKSTOP
    )
    return clone


def _regenerate_manifest(submission):
    from grading.instructors.release import GRADER_MANIFEST, _grader_manifest

    (submission / GRADER_MANIFEST).write_text(_grader_manifest(submission))


# How a student's copy of the grader may differ from the release, and a word of the line that says so.
TAMPERING = {
    "linked module": (lambda s: (s / "grading" / "mistakes.py").symlink_to("../pcl_course/pca.py"), "symbolic link"),
    "linked folder": (lambda s: (s / "grading" / "instructors").symlink_to("../pcl_course"), "symbolic link"),
    "linked file replaced": (
        lambda s: ((s / "grading" / "plugin.py").unlink(), (s / "grading" / "plugin.py").symlink_to("cli.py")),
        "symbolic link",
    ),
    "linked parent": (
        lambda s: (shutil.move(s / "tests", s / "elsewhere"), (s / "tests").symlink_to("elsewhere")),
        "symbolic link",
    ),
    "fifo": (lambda s: os.mkfifo(s / "grading" / "checks" / "extra.py"), "FIFO"),
    "hard link": (lambda s: os.link(s / "grading" / "config.py", s / "pcl_course" / "config.py"), "hard link"),
    "hidden name": (lambda s: (s / "grading" / "\x1b[2Kx.py").write_text(""), "unprintable"),
    "edited": (
        lambda s: (s / "tests" / "graded" / "test_pca.py").write_text("def test_free(impl):\n    pass\n"),
        "differs",
    ),
    "edited, manifest regenerated": (
        lambda s: ((s / "grading" / "plugin.py").write_text("raise SystemExit(0)\n"), _regenerate_manifest(s)),
        "not the release's|differs",
    ),
    "pins edited, manifest regenerated": (
        lambda s: ((s / "requirements" / "grading.txt").write_text("numpy-hacked\n"), _regenerate_manifest(s)),
        "not the release's|differs",
    ),
    "stubs edited, manifest regenerated": (
        lambda s: ((s / ".github" / "pristine" / "pcl_course" / "pca.py").write_text(""), _regenerate_manifest(s)),
        "not the release's|differs",
    ),
    "added": (lambda s: (s / "tests" / "graded" / "conftest.py").write_text(""), "added"),
    "compiled": (
        lambda s: (
            (s / "grading" / "__pycache__").mkdir(),
            (s / "grading" / "__pycache__" / "plugin.pyc").write_bytes(b""),
        ),
        "added",
    ),
    "empty folder": (lambda s: (s / "grading" / "instructors").mkdir(), "added"),
    "removed": (lambda s: (s / "grading" / "forbidden.py").unlink(), "missing"),
}


def _workspace(release_dir, tmp_path, change):
    """The runner's workspace: this repository, as released or changed, checked out in ``submission/``."""
    submission = tmp_path / "submission"
    shutil.copytree(release_dir, submission, ignore=PRISTINE_COPY)
    if change is not None:
        TAMPERING[change][0](submission)
    return submission


def _check(release_dir, course_clone, tmp_path, mode, change):
    steps = workflow_steps((release_dir / ".github" / "workflows" / "check.yml").read_text())
    env = {
        "GRADER_DIGEST": yaml.safe_load((release_dir / ".github" / "workflows" / "check.yml").read_text())["jobs"][
            "check"
        ]["env"]["GRADER_DIGEST"]
    }
    _workspace(release_dir, tmp_path, change)
    if mode == "course":
        shutil.copytree(course_clone, tmp_path / "course", symlinks=True)
        return run_step(steps["compare"], tmp_path, env)
    return run_step(steps["hashes"], tmp_path, env)


@pytest.mark.parametrize("mode", ["course", "hashes"])
def test_the_workflow_grades_a_pristine_release_with_the_released_grader(release_dir, course_clone, tmp_path, mode):
    completed = _check(release_dir, course_clone, tmp_path, mode, None)
    assert completed.returncode == 0, completed.stdout + completed.stderr
    assert "identical to" in (tmp_path / "grader-check.txt").read_text()
    course = tmp_path / "course"
    assert (course / "tests" / "graded" / "test_pca.py").is_file() and (course / "grading" / "plugin.py").is_file()
    # The grader's own pcl_course is the released stubs, never the submission's.
    assert (course / "pcl_course" / "pca.py").read_bytes() == (release_dir / "pcl_course" / "pca.py").read_bytes()


@pytest.mark.parametrize("mode", ["course", "hashes"])
@pytest.mark.parametrize("change", sorted(TAMPERING))
def test_the_workflow_refuses_a_grader_that_is_not_the_release(release_dir, course_clone, tmp_path, mode, change):
    completed = _check(release_dir, course_clone, tmp_path, mode, change)
    assert completed.returncode == 1, completed.stdout + completed.stderr
    lines = completed.stdout.splitlines()
    assert lines[0].startswith("::error::this repository's grader differs from"), completed.stdout
    assert re.search(TAMPERING[change][1], completed.stdout), completed.stdout
    assert completed.stdout == (tmp_path / "grader-check.txt").read_text()  # for the summary
    if mode == "hashes":
        assert not (tmp_path / "course").exists()  # nothing to grade with


def test_the_students_submission_never_becomes_the_graders_stubs(release_dir, course_clone, tmp_path):
    # A submission's pcl_course/ is graded in the sandbox; the grader imports its own stubs' signatures.
    submission = _workspace(release_dir, tmp_path, None)
    (submission / "pcl_course" / "pca.py").write_text("import os\nos._exit(0)\n")
    for mode in ("course", "hashes"):
        shutil.rmtree(tmp_path / "course", ignore_errors=True)
        steps = workflow_steps((release_dir / ".github" / "workflows" / "check.yml").read_text())
        if mode == "course":
            shutil.copytree(course_clone, tmp_path / "course", symlinks=True)
        digest = yaml.safe_load((release_dir / ".github" / "workflows" / "check.yml").read_text())["jobs"]["check"][
            "env"
        ]["GRADER_DIGEST"]
        completed = run_step(steps[mode if mode == "hashes" else "compare"], tmp_path, {"GRADER_DIGEST": digest})
        assert completed.returncode == 0, completed.stdout + completed.stderr
        stubs = (tmp_path / "course" / "pcl_course" / "pca.py").read_bytes()
        assert stubs == (release_dir / "pcl_course" / "pca.py").read_bytes(), mode


@pytest.mark.parametrize(
    "outcomes, expected",
    [
        ({"SOURCE": "course", "COURSE": "failure", "SETUP": "skipped", "GRADE": "skipped"}, "PCL_COURSE_TOKEN"),
        ({"SOURCE": "course", "COURSE": "failure", "SETUP": "skipped", "GRADE": "skipped"}, "the tag grader-x"),
        ({"SOURCE": "hashes", "HASHES": "failure", "SETUP": "skipped", "GRADE": "skipped"}, "is a symbolic link"),
        ({"SOURCE": "course", "COMPARE": "failure", "SETUP": "skipped", "GRADE": "skipped"}, "is a symbolic link"),
        ({"SOURCE": "hashes", "HASHES": "success", "SETUP": "failure", "GRADE": "skipped"}, "the set-up step failed"),
        ({"SOURCE": "hashes", "HASHES": "success", "SETUP": "success", "GRADE": "success"}, "Total: 1 / 2"),
        # What the check compared, and what it does not prove.
        ({"SOURCE": "course", "SETUP": "success", "GRADE": "success"}, "a/b at grader-x, whose copy ran here"),
        ({"SOURCE": "hashes", "SETUP": "success", "GRADE": "success"}, "compared with nothing the student cannot"),
        ({"SOURCE": "hashes", "SETUP": "success", "GRADE": "success"}, "SHA-256 0123abc"),
        ({"SOURCE": "course", "SETUP": "success", "GRADE": "success"}, "can change the workflow itself"),
        ({"SOURCE": "hashes", "HASHES": "failure", "SETUP": "skipped", "GRADE": "skipped"}, "advisory"),
    ],
)
def test_the_workflow_summary_says_why_grading_did_not_run(release_dir, tmp_path, outcomes, expected):
    steps = workflow_steps((release_dir / ".github" / "workflows" / "check.yml").read_text())
    summary = next(step for step in steps.values() if "GITHUB_STEP_SUMMARY" in step.get("run", ""))
    if outcomes["GRADE"] == "success":  # the results' Markdown is the summary (issue 37, item 3)
        (tmp_path / "results").mkdir()
        (tmp_path / "results" / "marks.txt").write_text("a fenced table\n")
        (tmp_path / "results" / "results.json").write_text(json.dumps({"output": "**Total: 1 / 2**"}))
    if "failure" in (outcomes.get("HASHES"), outcomes.get("COMPARE")):
        (tmp_path / "grader-check.txt").write_text("::error::...\ngrading/mistakes.py is a symbolic link\n")
    env = {"COURSE": "", "COMPARE": "", "HASHES": "", "COURSE_REPOSITORY": "a/b", "COURSE_REF": "grader-x"}
    env = {**env, "GRADER_DIGEST": "0123abc", **outcomes}
    completed = run_step(summary, tmp_path, {**env, "GITHUB_STEP_SUMMARY": str(tmp_path / "summary.md")})
    assert completed.returncode == 0, completed.stderr
    assert expected in (tmp_path / "summary.md").read_text()


def test_the_students_grader_refuses_to_run_with_a_link_in_it(release_dir, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(release_dir, copy, ignore=PRISTINE_COPY)
    (copy / "grading" / "instructors").symlink_to("../pcl_course")  # would pass for the instructors' grader
    env = {**os.environ, "PYTHONPATH": str(copy)}
    for command in (["-m", "grading", "grade", "."], ["-m", "pytest", "tests/graded", "-p", "no:cacheprovider"]):
        completed = subprocess.run(
            [sys.executable, *command], cwd=copy, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP, env=env
        )
        assert completed.returncode != 0, command
        assert "refusing to" in completed.stdout + completed.stderr, completed.stdout + completed.stderr
        assert "grading/instructors is not a regular file or folder" in completed.stdout + completed.stderr


def test_the_release_grades_its_stubs_at_zero_without_an_error(release_dir):
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", ".", "--results", "r.json"],
        cwd=release_dir,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    summary = load_results(release_dir / "r.json")
    assert summary["score"] == 0 and summary["max_score"] > 0
    odd = [t for t in summary["tests"] if not t["text"].startswith("not implemented")]
    assert not odd, [(t["name"], t["text"]) for t in odd[:3]]
    # No hidden test ships, but the table says what they carry, from the points the release wrote down.
    hidden = hidden_points()
    assert json.loads((release_dir / "grading" / "hidden_points.json").read_text()) == hidden
    public = sum(t["max_score"] for t in summary["tests"] if t["tags"] == ["kdtree_knn"])
    assert f"kdtree_knn: 0 / {public:g} (+ {hidden['kdtree_knn']:g} in hidden tests)" in completed.stdout
    assert f"Hidden tests carry {sum(hidden.values()):g} more points of these functions" in completed.stdout


@pytest.mark.long
def test_the_release_book_builds_with_the_stubs(release_dir):
    # The release's own pcl_course first on the path: the kernel must run the
    # stubs, as in a student's fresh environment (where no solutions exist).
    env = dict(__import__("os").environ, PYTHONPATH=str(release_dir))
    completed = subprocess.run(
        [str(REPO_ROOT / ".venv" / "bin" / "jupyter-book"), "build", ".", "-n", "--keep-going"],
        cwd=release_dir,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
        env=env,
    )
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    # Issue 38: a student saw 21 warnings for exercises not done yet, and the stub's message twice.
    log = completed.stdout + completed.stderr
    assert "glue data" not in log, [line for line in log.splitlines() if "glue data" in line][:3]
    page = (release_dir / "_build" / "html" / "book" / "pca.html").read_text()
    assert "Not implemented yet: pca." in page
    assert not re.search(r"not implemented yet[^\n<]*not implemented yet", page, re.I)
    # A sentence whose number the stub could not compute says so, instead of losing the number.
    kernel_page = (release_dir / "_build" / "html" / "book" / "kernel_pca.html").read_text()
    assert "[not computed: a cell above failed]" in kernel_page
    # The cells that use a stub's results show one line each, not a traceback.
    assert "Not run: this cell needs results" in kernel_page
    for built in (release_dir / "_build" / "html" / "book").glob("*.html"):
        assert "Traceback" not in built.read_text(), built.name
    assert "lambda_k = s_k^2 / N: True" not in page  # no reference results
    assert find_leaks(release_dir / "_build" / "html") == []


def test_the_workflow_grade_step_runs_the_pristine_grader_on_the_submission(release_dir, tmp_path):
    # The runner's workspace: the submission and the pristine course side by side.
    workspace = tmp_path / "workspace"
    shutil.copytree(release_dir, workspace / "course", ignore=shutil.ignore_patterns("_build", "r.json"))
    submission = workspace / "submission"
    shutil.copytree(release_dir / "pcl_course", submission / "pcl_course")
    shutil.copy(REPO_ROOT / "solutions" / "metrics.py", submission / "pcl_course" / "metrics.py")
    # A submission that tampers with its own copy of the grader changes nothing.
    (submission / "grading").mkdir()
    (submission / "grading" / "plugin.py").write_text("raise SystemExit('tampered')\n")
    (workspace / "results").mkdir()
    workflow = yaml.safe_load((release_dir / ".github" / "workflows" / "check.yml").read_text())
    step = next(s for s in workflow["jobs"]["check"]["steps"] if "python -m grading grade" in s.get("run", ""))
    env = dict(__import__("os").environ, PATH=f"{REPO_ROOT / '.venv' / 'bin'}:{__import__('os').environ['PATH']}")
    completed = subprocess.run(
        ["bash", "-e", "-c", step["run"]],
        cwd=workspace / step["working-directory"],
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
        env=env,
    )
    assert completed.returncode == 0, completed.stdout[-2000:] + completed.stderr[-2000:]
    summary = load_results(workspace / "results" / "results.json")
    metrics = [t for t in summary["tests"] if t["name"].startswith(("test_chamfer_distance_", "test_depth_metrics_"))]
    assert metrics and all(t["status"] == "passed" for t in metrics)
    assert summary["output"].startswith("isolated: bubblewrap")
    assert "Total: " in (workspace / "results" / "marks.txt").read_text()


def test_every_substitution_must_match_exactly_once():
    from grading.instructors.shipping import substitute

    assert substitute("a = 1\nb = 2\n", "a = 1", "a = 3", "x") == "a = 3\nb = 2\n"
    for text in ("b = 2\n", "a = 1\na = 1\n"):
        with pytest.raises(SystemExit, match="exactly once in x"):
            substitute(text, "a = 1", "a = 3", "x")


def test_the_student_makefile_shares_the_set_up_rules(release_dir):
    assert "include scripts/setup.mk" in (release_dir / "Makefile").read_text()
    assert "include scripts/setup.mk" in (REPO_ROOT / "Makefile").read_text()
    assert (release_dir / "scripts" / "setup.mk").read_bytes() == (REPO_ROOT / "scripts" / "setup.mk").read_bytes()
    for target in ("setup", "book", "test"):
        completed = subprocess.run(["make", "-n", target], cwd=release_dir, capture_output=True, text=True)
        assert completed.returncode == 0, completed.stderr


def test_the_students_book_runs_every_page_again_only_after_a_change_to_their_code(release_dir):
    """Issue 38: a student's make book started from scratch on every run."""
    stamp = release_dir / "_build" / ".code-stamp"
    stamp.parent.mkdir(exist_ok=True)
    stamp.touch()
    newest = max(path.stat().st_mtime for path in (release_dir / "pcl_course").glob("*.py"))
    os.utime(stamp, (newest + 10, newest + 10))

    def dry_run():
        completed = subprocess.run(["make", "-n", "book"], cwd=release_dir, capture_output=True, text=True)
        assert completed.returncode == 0, completed.stderr
        return completed.stdout

    assert "jupyter_cache" not in dry_run() and "jupyter-book build" in dry_run()
    os.utime(release_dir / "pcl_course" / "nn.py", (newest + 20, newest + 20))
    assert "rm -rf _build/.jupyter_cache" in dry_run()


def test_the_workflow_runs_on_changes_to_the_exercises_tags_or_by_hand_and_keeps_its_results(release_dir):
    """Issue 37, item 3: not every push (large classes), any tag, or by hand with a lecture to grade; the
    lecture also from the repository variable PCL_ASSIGNMENT; results.json kept as an artifact."""
    workflow = yaml.safe_load((release_dir / ".github" / "workflows" / "check.yml").read_text())
    triggers = workflow.get("on", workflow.get(True))  # YAML 1.1 reads a bare `on` as True
    assert triggers["push"] == {"branches": ["**"], "tags": ["**"], "paths": ["pcl_course/**"]}
    assert triggers["workflow_dispatch"]["inputs"]["assignment"]["default"] == ""
    assert workflow["jobs"]["check"]["env"]["ASSIGNMENT"] == "${{ inputs.assignment || vars.PCL_ASSIGNMENT }}"
    upload = [s for s in workflow["jobs"]["check"]["steps"] if s.get("uses", "").startswith("actions/upload-artifact")]
    assert upload and upload[0]["if"] == "always()" and upload[0]["with"]["path"] == "results/"


@pytest.mark.parametrize("assignment, expected", [("lecture2", "--assignment lecture2"), ("", "")])
def test_the_workflow_grades_the_lecture_it_is_given(release_dir, tmp_path, assignment, expected):
    steps = workflow_steps((release_dir / ".github" / "workflows" / "check.yml").read_text())
    fake = tmp_path / "bin" / "python"  # records what the grade step asks of the grader
    fake.parent.mkdir()
    fake.write_text('#!/bin/sh\necho "$@"\n')
    fake.chmod(0o755)
    (tmp_path / "course").mkdir()
    (tmp_path / "results").mkdir()
    env = {"ASSIGNMENT": assignment, "PATH": f"{fake.parent}:{os.environ['PATH']}"}
    completed = run_step(steps["grade"], tmp_path / "course", env)
    assert completed.returncode == 0, completed.stderr
    arguments = (tmp_path / "results" / "marks.txt").read_text()
    assert arguments.startswith("-m grading grade ../submission --require-isolation ")
    assert (expected in arguments) if expected else "--assignment" not in arguments


def test_the_summary_falls_back_to_the_table_without_a_results_file(release_dir, tmp_path):
    steps = workflow_steps((release_dir / ".github" / "workflows" / "check.yml").read_text())
    summary = next(step for step in steps.values() if "GITHUB_STEP_SUMMARY" in step.get("run", ""))
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "marks.txt").write_text("Total: 1 / 2\n")
    env = {"SOURCE": "hashes", "HASHES": "success", "SETUP": "success", "GRADE": "success", "GRADER_DIGEST": "0"}
    env = {**env, "COURSE": "", "COMPARE": "", "GITHUB_STEP_SUMMARY": str(tmp_path / "summary.md")}
    assert run_step(summary, tmp_path, env).returncode == 0
    assert "```\nTotal: 1 / 2\n```" in (tmp_path / "summary.md").read_text()


def test_the_student_makefile_grades_one_lecture_when_asked(release_dir):
    completed = subprocess.run(
        ["make", "-n", "test", "ASSIGNMENT=lecture2"], cwd=release_dir, capture_output=True, text=True
    )
    assert "grade . --assignment lecture2 --results" in completed.stdout, completed.stdout
    completed = subprocess.run(["make", "-n", "test"], cwd=release_dir, capture_output=True, text=True)
    assert "grade .  --results" in completed.stdout or "grade . --results" in completed.stdout, completed.stdout


def test_ruff_flags_a_forbidden_import_in_an_exercise_module_as_the_grader_words_it(release_dir, tmp_path):
    """Issue 37, item 4: the student pyproject.toml's banned-api rules come from grading/config.py, in the
    exercise modules only (the helpers may use Open3D), with the grader's own message."""
    from grading.config import FORBIDDEN_PACKAGES
    from grading.errors import VISUALISATION_ONLY

    copy = tmp_path / "repo"
    shutil.copytree(release_dir, copy, ignore=PRISTINE_COPY)
    pca = copy / "pcl_course" / "pca.py"
    pca.write_text("import open3d\nfrom sklearn.decomposition import PCA\n" + pca.read_text())
    (copy / "pcl_course" / "plotting.py").write_text(
        "import open3d\n" + (copy / "pcl_course" / "plotting.py").read_text()
    )
    ruff = [str(REPO_ROOT / ".venv" / "bin" / "ruff"), "check", "--no-cache", "--output-format", "concise", "."]
    completed = subprocess.run(ruff, cwd=copy, capture_output=True, text=True, timeout=STEP_BACKSTOP)
    flagged = [line for line in completed.stdout.splitlines() if "TID251" in line]
    assert [line.split(":")[0] for line in flagged] == ["pcl_course/pca.py"] * 2, completed.stdout
    assert all(VISUALISATION_ONLY in line for line in flagged)
    banned = tomllib.loads((copy / "pyproject.toml").read_text())["tool"]["ruff"]["lint"]["flake8-tidy-imports"]
    assert set(banned["banned-api"]) == set(FORBIDDEN_PACKAGES)
    pca.write_text(pca.read_text().split("\n", 2)[2])  # the released modules themselves pass
    completed = subprocess.run(ruff, cwd=copy, capture_output=True, text=True, timeout=STEP_BACKSTOP)
    assert "TID251" not in completed.stdout, completed.stdout
