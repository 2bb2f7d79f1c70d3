"""Command line of the autograder: ``python -m grading grade ...``.

Examples
--------
Grade a student's clone (its ``pcl_course/``)::

    python -m grading grade path/to/clone --results results.json

Grade the reference solutions, or only the ``pca`` tests::

    python -m grading grade --reference
    python -m grading grade . -k pca

The exit status is 0 whenever grading ran, whatever the score; 2 for a usage
error (no ``pcl_course/`` found, no test selected); 1 if pytest itself broke.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from grading import GRADED_TESTS, REPO_ROOT

PYTEST_EXIT_NO_TESTS = 5


def find_package(submission):
    """The exercise folder of a submission: ``DIR/pcl_course`` or ``DIR`` itself."""
    submission = Path(submission).resolve()
    for candidate in (submission / "pcl_course", submission):
        if candidate.name == "pcl_course" and (candidate / "__init__.py").is_file():
            return candidate
    raise SystemExit(f"error: no pcl_course/ package found in {submission}")


def run_graded_tests(impl_dir, results, keyword=None, junit=None, overrides=(), tests=None):
    """Run the graded tests on ``impl_dir``; return pytest's exit code."""
    command = [
        sys.executable, "-m", "pytest", str(tests or GRADED_TESTS),
        # The grader's own configuration only: nothing from the submission.
        "-c", str(REPO_ROOT / "grading" / "pytest.ini"),
        "--rootdir", str(REPO_ROOT),
        "-p", "grading.plugin", "-p", "no:cacheprovider", "-p", "no:dash",
        "--impl", str(impl_dir), "--results", str(results),
        "-q", "--tb=no", "--no-header", "-rN",
    ]
    for override in overrides:
        command += ["--impl-module", override]
    if keyword:
        command += ["-k", keyword]
    if junit:
        command += ["--junitxml", str(junit)]
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    completed = subprocess.run(command, cwd=REPO_ROOT, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return completed.returncode, completed.stdout


def format_report(summary, title):
    lines = [title, ""]
    width = max((len(t["name"]) for t in summary["tests"]), default=10)
    for test in summary["tests"]:
        status = "ok  " if test["status"] == "passed" else "FAIL"
        output = test["output"].splitlines()
        first = f"  {output[0]}" if output else ""
        lines.append(
            f"{test['score']:5.1f}/{test['max_score']:<4.1f} {status} "
            f"{test['name']:<{width}}{first}".rstrip()
        )
        lines.extend(" " * (width + 17) + "  " + line for line in output[1:])
    lines += ["", f"Total: {summary['score']:g} / {summary['max_score']:g}"]
    return "\n".join(lines)


def grade(args):
    if args.reference:
        impl_dir = REPO_ROOT / "solutions"
    elif args.submission:
        impl_dir = find_package(args.submission)
    else:
        raise SystemExit("error: give a SUBMISSION directory or --reference")
    results = Path(args.results) if args.results else Path(tempfile.mkdtemp()) / "results.json"
    code, output = run_graded_tests(impl_dir, results, args.k, args.junit, args.impl_module)
    if code == PYTEST_EXIT_NO_TESTS:
        print(f"error: no graded test matches -k {args.k!r}", file=sys.stderr)
        return 2
    if code not in (0, 1) or not results.exists():
        print(output, file=sys.stderr)
        print(f"error: the grading run broke (pytest exit code {code})", file=sys.stderr)
        return 1
    summary = json.loads(results.read_text())
    title = f"Grading {impl_dir}" + "".join(f" (with {o})" for o in args.impl_module)
    print(format_report(summary, title))
    if args.results:
        print(f"Results written to {results}")
    return 0



def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m grading", description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    g = commands.add_parser("grade", help="grade a submission or the reference")
    g.add_argument("submission", nargs="?", help="a student's clone (holding pcl_course/)")
    g.add_argument("--reference", action="store_true", help="grade solutions/ instead")
    g.add_argument("--results", help="write the Gradescope results JSON here")
    g.add_argument("--junit", help="also write JUnit XML here")
    g.add_argument("-k", help="select tests as pytest -k does (e.g. -k pca)")
    g.add_argument("--impl-module", action="append", default=[], metavar="MODULE=FILE",
                   help=argparse.SUPPRESS)  # mutation checks: replace one module
    args = parser.parse_args(argv)
    if args.command == "grade":
        return grade(args)
    return 2
