"""The instructors' commands of ``python -m grading``: batch, release, gradescope, autograde, similarity.

:data:`COMMANDS` is their registry, read by :mod:`grading.cli`: each
command's help, its arguments and what runs it. A student's copy of the
grader has no ``grading/instructors/``, so none of these commands.
"""

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

from grading import ASSIGNMENTS
from grading.errors import existing_folder


def _batch_arguments(parser):
    parser.add_argument(
        "directory",
        help="a folder with one submission per subdirectory (a clone, its pcl_course/, or loose modules), "
        "or Gradescope's exported submissions with their submission_metadata.yml",
    )
    parser.add_argument(
        "--assignment",
        required=True,
        choices=sorted(ASSIGNMENTS),
        help="the assignment to grade (one per lecture): its functions make the total",
    )
    parser.add_argument("--csv", help="where to write the marks (default: OUT/marks.csv)")
    parser.add_argument("--out", help="folder for the per-submission results files (default: DIRECTORY-results)")
    parser.add_argument("--jobs", type=int, help="submissions graded at once (default: number of cores)")
    parser.add_argument("-k", help="select tests as pytest -k does")
    parser.add_argument(
        "--quiet",
        action="store_true",
        help="on a terminal, list the submissions in name order at the end, not one line as each finishes",
    )
    parser.add_argument("--gradebook", metavar="CSV", help="also write the totals in Canvas's gradebook layout here")
    parser.add_argument(
        "--gradebook-column",
        help="the gradebook column of the totals (Canvas assignment; default: the assignment's name)",
    )
    parser.add_argument(
        "--roster",
        metavar="CSV",
        help="a gradebook exported from Canvas: submission folders are matched to its students",
    )
    parser.add_argument(
        "--allow-unisolated",
        action="store_true",
        help="grade even where submissions cannot be isolated (marks are then local checks)",
    )


def _release_arguments(parser):
    parser.add_argument("out_dir", help="an empty or new folder")
    parser.add_argument(
        "--course-repository",
        metavar="OWNER/NAME",
        help="the published student repository whose grader the students' workflow checks out "
        "(default: the repository variable PCL_COURSE_REPOSITORY)",
    )
    parser.add_argument(
        "--course-ref",
        metavar="REF",
        help="the course repository's tag or commit of this release, which the workflow checks out "
        "(default: grader-<the first 12 hex digits of the grader's digest>)",
    )


def _similarity_arguments(parser):
    parser.add_argument(
        "directory",
        help="a folder with one submission per entry, in any layout batch grades "
        "(a clone, its pcl_course/, loose modules, Gradescope's export)",
    )
    parser.add_argument(
        "--report", default="similarity.html", help="the HTML report to write (default similarity.html)"
    )
    parser.add_argument(
        "--threshold",
        type=float,
        default=None,
        metavar="SHARE",
        help="show pairs whose larger share of shared code reaches SHARE (default 0.33)",
    )
    parser.add_argument("--top", type=int, default=100, help="show at most this many pairs (default 100)")


def _gradescope_arguments(parser):
    parser.add_argument("out_zip", help="the .zip to write, e.g. _build/gradescope/autograder-lecture1.zip")
    parser.add_argument(
        "--assignment",
        required=True,
        choices=sorted(ASSIGNMENTS),
        help="the Gradescope assignment this archive grades (one per lecture)",
    )


def _autograde_arguments(parser):
    parser.add_argument("--root", default="/autograder", help="the autograder folder (default /autograder)")
    parser.add_argument("--budget", type=float, metavar="SECONDS", help=argparse.SUPPRESS)
    parser.add_argument("--assignment", required=True, choices=sorted(ASSIGNMENTS), help="the assignment graded")


def _batch(args):
    from grading.instructors.batch import batch

    return batch(args)


def _release(args):
    from grading.instructors.release import course_tag, grader_digest, release

    leaks = release(args.out_dir, args.course_repository, args.course_ref)
    if leaks:
        print("error: the release contains reference code:\n" + "\n".join(leaks[:20]), file=sys.stderr)
        return 1
    digest = grader_digest(args.out_dir)
    print(f"Student repository written to {args.out_dir}")
    print(f"The grader's digest (publish it: the students' check prints it): {digest}")
    print(
        f"Tag the commit of the course repository that holds this release {args.course_ref or course_tag(digest)}"
        " (the students' workflow checks out that ref)"
    )
    return 0


def _gradescope(args):
    from grading.instructors.gradescope import build_archive

    leaks = build_archive(args.out_zip, args.assignment)
    if leaks:
        print("error: the archive would contain reference code:\n" + "\n".join(leaks[:20]), file=sys.stderr)
        return 1
    print(
        f"Gradescope autograder of {args.assignment} written to {args.out_zip}: "
        "upload it as that assignment's autograder"
    )
    return 0


def _autograde(args):
    from grading.instructors.gradescope import autograde

    return autograde(args.root, args.budget, args.assignment)


def _similarity(args):
    from grading.instructors.reports import say
    from grading.instructors.similarity import DISPLAY_THRESHOLD, compare_class, counted, render_report

    root = existing_folder(args.directory)
    threshold = DISPLAY_THRESHOLD if args.threshold is None else args.threshold
    pairs, skipped = compare_class(root)
    report = Path(args.report)
    report.write_text(render_report(pairs, skipped, threshold, args.top), encoding="utf-8")
    for line in skipped:
        say(line)
    shown = [p for p in pairs if p.similarity >= threshold][: args.top]
    for pair in shown[:10]:
        say(f"{pair.similarity:4.0%}  {pair.module}.py  {pair.first}  {pair.second}")
    say(f"{counted(len(shown), 'pair')} at or above {threshold:.0%}; report written to {report}")
    return 0


@dataclass(frozen=True)
class Command:
    """An instructors' command: its one-line help, its arguments (a function of its parser), what runs it."""

    help: str
    arguments: object
    run: object


COMMANDS = {
    "batch": Command("grade every submission in a folder, in parallel", _batch_arguments, _batch),
    "release": Command("write the student repository (no solutions, no hidden tests)", _release_arguments, _release),
    "similarity": Command(
        "pairwise similarity of the exercise modules across a class", _similarity_arguments, _similarity
    ),
    "gradescope": Command("write the Gradescope autograder archive (no solutions)", _gradescope_arguments, _gradescope),
    "autograde": Command(
        "inside a Gradescope container: grade ROOT/submission into ROOT/results/results.json",
        _autograde_arguments,
        _autograde,
    ),
}
