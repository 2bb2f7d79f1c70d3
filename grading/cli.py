"""Command line of the autograder: ``python -m grading grade ...``.

Examples
--------
Grade a student's clone (its ``pcl_course/``)::

    python -m grading grade path/to/clone --results results.json

Grade the reference solutions, or only the ``pca`` tests::

    python -m grading grade --reference
    python -m grading grade . --function pca

An official mark (refuse to run where the submission cannot be isolated)::

    python -m grading grade path/to/clone --require-isolation

Grade a whole class, one submission per subdirectory, in parallel::

    python -m grading batch submissions/ --csv marks.csv

Pairwise similarity of a class's exercise modules (``grading/instructors/similarity.py``)::

    python -m grading similarity submissions/ --report similarity.html

Write the Gradescope autograder archive (``grading/instructors/gradescope.py``)::

    python -m grading gradescope _build/gradescope/autograder.zip

Exit status: 0 whenever grading ran, whatever the score (``--require-full``:
1 unless every selected test passed); 2 for a usage error (a folder that does
not exist, no ``pcl_course/`` found, no test selected, a bad option); 1 if
grading could not run (pytest itself broke, no isolation where it is required).
"""

import argparse
import json
import os
import platform
import shutil
import sys
from importlib import metadata
from pathlib import Path

from grading import ASSIGNMENTS, REPO_ROOT, instructors_grader, scratch
from grading.errors import UsageError, existing_folder
from grading.options import SHARED
from grading.results import Grading
from grading.runner import PYTEST_EXIT_NO_TESTS, PYTEST_EXIT_USAGE, run_graded_tests


def find_package(submission):
    """The exercise folder of a submission: ``DIR/pcl_course`` or ``DIR`` itself.

    Symbolic links are not followed here: staging (grading/staging.py)
    refuses a linked ``pcl_course`` with one clear line.
    """
    submission = existing_folder(os.path.abspath(submission))
    for candidate in (submission / "pcl_course", submission):
        if candidate.name == "pcl_course" and os.path.lexists(candidate):
            return candidate
    raise UsageError(f"no pcl_course/ package found in {submission}")


def grade(args):
    if args.results:
        return _grade(args, Path(args.results))
    folder = scratch.folder("grading-results-")  # the table is the output
    try:
        return _grade(args, Path(folder) / "results.json")
    finally:
        scratch.remove(folder)


def _grade(args, results):
    if args.reference:
        impl_dir = REPO_ROOT / "solutions"
    elif args.submission:
        impl_dir = find_package(args.submission)
    else:
        raise UsageError("give a SUBMISSION folder or --reference")
    # The reference and the project's own wrong submissions are trusted code;
    # a student's submission runs in the sandbox.
    sandbox = not args.reference and not args.impl_module
    if sandbox and args.require_isolation:
        from grading.sandbox import isolation

        level = isolation()
        if not level.isolated:
            print(f"error: refusing to grade: the submission could not be isolated ({level.reason})", file=sys.stderr)
            return 1
    passed = {option.dest: getattr(args, option.dest) for option in SHARED}
    passed["function"] = [*args.function, *ASSIGNMENTS.get(args.assignment, ())]
    progress = None if args.quiet or not sys.stderr.isatty() else ProgressLine(sys.stderr)
    code, output = run_graded_tests(
        impl_dir, results, keyword=args.k, junit=args.junit, sandbox=sandbox, progress=progress, **passed
    )
    if progress is not None:
        progress.close()
    if code == PYTEST_EXIT_NO_TESTS:
        print(f"error: no graded test matches -k {args.k!r}", file=sys.stderr)
        return 2
    if code == PYTEST_EXIT_USAGE:
        print(output.strip().splitlines()[-1] if output.strip() else "error: bad arguments", file=sys.stderr)
        return 2
    if code not in (0, 1) or not results.exists():
        print(output, file=sys.stderr)
        print(f"error: the grading run broke (pytest exit code {code})", file=sys.stderr)
        return 1
    graded = Grading.from_gradescope(json.loads(results.read_text()))
    title = f"Grading {impl_dir}" + "".join(f" (with {o})" for o in args.impl_module)
    print(graded.to_table(title))
    if args.results:
        print(f"Results written to {results}")
    if args.require_full and graded.score < graded.max_score:
        return 1
    return 0


class ProgressLine:
    """One terminal line rewritten as each graded test finishes: ``[37/120] 42 s  test_name``."""

    def __init__(self, stream):
        self.stream = stream

    def __call__(self, done, total, seconds, test, score):
        line = f"[{done}/{total}] {seconds:.0f} s  {test}"
        width = shutil.get_terminal_size().columns - 1
        self.stream.write("\r\x1b[K" + line[:width])
        self.stream.flush()

    def close(self):
        self.stream.write("\r\x1b[K")  # the table follows on a clean line
        self.stream.flush()


def _grade_arguments(parser):
    parser.add_argument("submission", nargs="?", help="a student's clone (holding pcl_course/)")
    parser.add_argument("--reference", action="store_true", help="grade solutions/ instead")
    parser.add_argument("--results", help="write the Gradescope results JSON here")
    parser.add_argument("--junit", help="also write JUnit XML here")
    parser.add_argument("-k", help="select tests as pytest -k does (e.g. -k pca)")
    parser.add_argument(
        "--assignment",
        choices=sorted(ASSIGNMENTS),
        help="grade only this assignment's functions (one per lecture; default: every graded function)",
    )
    parser.add_argument("--require-full", action="store_true", help="exit 1 unless every selected test passed")
    parser.add_argument(
        "--quiet", action="store_true", help="no progress line while grading (there is none off a terminal)"
    )
    for option in SHARED:  # passed through to the grading process (grading/options.py)
        option.add_to(parser)


def _commands():
    """Command name -> (help, arguments, run): ``grade``, and the instructors' where they ship."""
    commands = {"grade": ("grade a submission or the reference", _grade_arguments, grade)}
    if instructors_grader():
        from grading.instructors.commands import COMMANDS

        commands.update({name: (c.help, c.arguments, c.run) for name, c in COMMANDS.items()})
    return commands


VERSIONED = ("numpy", "scipy", "numba", "pytest")  # what a grading's outcome depends on, besides the grader


def version():
    """One line: the grader's version (the course package's) and the versions its marks depend on."""

    def of(name):
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "not installed"

    grader = of("pcl-course")
    if grader == "not installed" and (REPO_ROOT / "pyproject.toml").is_file():  # a student's clone, not installed
        import tomllib

        grader = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]["version"]
    packages = ", ".join(f"{name} {of(name)}" for name in VERSIONED)
    return f"grading {grader} (Python {platform.python_version()}; {packages})"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    commands = _commands()
    if argv and not argv[0].startswith("-") and argv[0] not in commands and not instructors_grader():
        print(
            f"error: `{argv[0]}` is not a command of the student's grader (only `grade`); "
            "the instructors' commands are in the course repository",
            file=sys.stderr,
        )
        return 2
    examples = __doc__[__doc__.index("Examples") :].replace("::\n", ":\n")
    if not instructors_grader():  # a student's copy: its examples and statuses of `grade` only
        examples = examples[: examples.index("Grade a whole class")] + examples[examples.index("Exit status") :]
    parser = argparse.ArgumentParser(
        prog="python -m grading",
        description=__doc__.split("\n")[0],
        epilog=examples,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=version())
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name, (help_text, arguments, _) in commands.items():
        arguments(subparsers.add_parser(name, help=help_text))
    args = parser.parse_args(argv)
    try:
        return commands[args.command][2](args)
    except UsageError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
