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

Pairwise similarity of a class's exercise modules (``grading/similarity.py``)::

    python -m grading similarity submissions/ --report similarity.html

Write the Gradescope autograder archive (``grading/gradescope.py``)::

    python -m grading gradescope _build/gradescope/autograder.zip

The exit status is 0 whenever grading ran, whatever the score; 2 for a usage
error (no ``pcl_course/`` found, no test selected); 1 if pytest itself broke.
"""

import argparse
import csv
import importlib.util
import json
import os
import queue
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from grading import ASSIGNMENTS, REPO_ROOT, config
from grading.results import Grading
from grading.runner import PYTEST_EXIT_NO_TESTS, PYTEST_EXIT_USAGE, run_graded_tests


def find_package(submission):
    """The exercise folder of a submission: ``DIR/pcl_course`` or ``DIR`` itself.

    Symbolic links are not followed here: staging (grading/staging.py)
    refuses a linked ``pcl_course`` with one clear line.
    """
    submission = Path(os.path.abspath(submission))
    for candidate in (submission / "pcl_course", submission):
        if candidate.name == "pcl_course" and os.path.lexists(candidate):
            return candidate
    raise SystemExit(f"error: no pcl_course/ package found in {submission}")


def grade(args):
    if args.reference:
        impl_dir = REPO_ROOT / "solutions"
    elif args.submission:
        impl_dir = find_package(args.submission)
    else:
        raise SystemExit("error: give a SUBMISSION directory or --reference")
    results = Path(args.results) if args.results else Path(tempfile.mkdtemp()) / "results.json"
    # The reference and the project's own wrong submissions are trusted code;
    # a student's submission runs in the sandbox.
    sandbox = not args.reference and not args.impl_module
    if sandbox and args.require_isolation:
        from grading.sandbox import isolation

        level = isolation()
        if not level.isolated:
            print(f"error: refusing to grade: the submission could not be isolated ({level.reason})", file=sys.stderr)
            return 1
    code, output = run_graded_tests(
        impl_dir,
        results,
        args.k,
        args.junit,
        args.impl_module,
        sandbox=sandbox,
        call_timeout=args.call_timeout,
        require_isolation=args.require_isolation,
        functions=[*args.function, *ASSIGNMENTS.get(args.assignment, ())],
        budget=args.budget,
        diagnose_always=args.diagnose_always,
    )
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


GRADEBOOK_IDENTITY = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section")  # Canvas's gradebook export
GRADESCOPE_METADATA = "submission_metadata.yml"  # in Gradescope's "Export Submissions" archive


@dataclass
class Folder:
    """One entry of a class folder, and what became of it.

    Attributes
    ----------
    name : str
        The folder's name (a student's login, or Gradescope's ``submission_NNN``).
    submitters : list of dict
        From Gradescope's metadata: ``name``, ``sid``, ``email`` of each
        submitter (several for a group); empty without metadata.
    grading : Grading or None
        The results, when the folder was graded.
    status : str
        ``graded``, or why not: nothing to grade, refused, grading failed.
    note : str
        What was graded from where (as on Gradescope), or the reason in full.
    """

    name: str
    submitters: list = field(default_factory=list)
    grading: Grading = None
    status: str = ""
    note: str = ""

    def identities(self):
        """The names a roster row may know this submission by."""
        keys = {self.name}
        for person in self.submitters:
            keys |= {person["sid"], person["email"], person["email"].split("@")[0]}
        return keys - {""}


def read_gradescope_metadata(root):
    """Folder name -> submitters, from Gradescope's ``submission_metadata.yml`` (empty without one)."""
    path = root / GRADESCOPE_METADATA
    if not path.is_file():
        return {}
    import yaml

    metadata = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    people = {}
    for folder, record in metadata.items():
        submitters = (record or {}).get(":submitters") or []
        people[str(folder)] = [
            {key: str(person.get(f":{key}") or "").strip() for key in ("name", "sid", "email")} for person in submitters
        ]
    return people


def write_gradebook(path, assignment, folders, roster=None):
    """Write the marks in the layout of Canvas's gradebook (its export, re-imported).

    Columns ``Student, ID, SIS User ID, SIS Login ID, Section`` and one
    column ``assignment`` holding each total, after a ``Points Possible``
    row. With ``roster`` (a gradebook exported from the course), each
    submission is matched to the student whose SIS Login ID, SIS User ID or
    ID is its folder's name or, with Gradescope's metadata, a submitter's
    SID, email or email login; every identity column is copied from the
    roster. A folder that held nothing gradable, or was refused, scores 0,
    as on Gradescope (marks.csv says why); students without a folder get an
    empty cell (no change on import). Without a roster, one row per folder
    (per submitter, with metadata).
    """
    possible = max((f.grading.max_score for f in folders if f.grading), default=0)

    def mark(folder):
        return f"{folder.grading.score:g}" if folder.grading else "0"

    rows = []
    if roster:
        with open(roster, newline="", encoding="utf-8-sig") as handle:
            students = [row for row in csv.DictReader(handle) if row.get("Student", "").strip() != "Points Possible"]
        missing = [column for column in GRADEBOOK_IDENTITY if students and column not in students[0]]
        if missing:
            raise SystemExit(
                f"error: the roster {roster} has no column {', '.join(missing)}: export it from the gradebook"
            )
        matched = set()
        for student in students:
            keys = {student.get(c, "").strip() for c in ("SIS Login ID", "SIS User ID", "ID")} - {""}
            folder = next((f for f in folders if f.identities() & keys), None)
            matched.add(folder.name if folder else None)
            rows.append([*(student.get(c, "") for c in GRADEBOOK_IDENTITY), mark(folder) if folder else ""])
        for folder in folders:
            if folder.name not in matched:
                print(
                    f"{folder.name}: in no roster row (by SIS Login ID, SIS User ID or ID): not in the gradebook file"
                )
    else:
        for folder in folders:
            people = folder.submitters or [{"name": folder.name, "sid": "", "email": folder.name}]
            rows += [[p["name"], "", p["sid"], p["email"] or folder.name, "", mark(folder)] for p in people]
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow([*GRADEBOOK_IDENTITY, assignment])
        writer.writerow(["Points Possible", "", "", "", "", f"{possible:g}"])
        writer.writerows(rows)
    print(f"Gradebook (Canvas layout, column {assignment!r}) written to {path}")


def class_folders(root):
    """Every entry of the class folder, in name order: hidden entries and Gradescope's metadata aside."""
    entries = sorted(p for p in root.iterdir() if not p.name.startswith(".") and p.name != GRADESCOPE_METADATA)
    if not entries:
        raise SystemExit(f"error: {root} is empty")
    return entries


def batch(args):
    from grading.errors import StagingError
    from grading.gradescope import assemble

    root = Path(args.directory).resolve()
    entries = class_folders(root)
    metadata = read_gradescope_metadata(root)
    out = Path(args.out).resolve() if args.out else root.parent / f"{root.name}-results"
    out.mkdir(parents=True, exist_ok=True)
    jobs = max(1, min(args.jobs or os.cpu_count() or 1, config.SANDBOX_UID_SLOTS))
    require = not args.allow_unisolated
    if require:
        from grading.sandbox import UID, isolation, permission_wall

        level = isolation()
        if not level.isolated:
            raise SystemExit(
                f"error: refusing to grade the class: submissions could not be isolated "
                f"({level.reason}); --allow-unisolated grades anyway, as a local check"
            )
        if level.level == UID:
            # No namespace hides the class here: its folders must be out of the sandbox uids' reach.
            os.chmod(out, 0o700)
            wall = permission_wall(level.uid, [root, out])
            if wall is not None:
                raise SystemExit(
                    f"error: refusing to grade the class: {wall.split(':')[0]}: make {root} unreadable "
                    f"to others (chmod 700 {root}), so that no submission reads a classmate's"
                )
    # One dedicated sandbox uid per parallel slot: two submissions graded at
    # once never share a uid, and whatever one left running is killed before
    # its slot grades the next.
    slots = queue.Queue()
    for slot in range(jobs):
        slots.put(config.SANDBOX_UID_BASE + slot)

    def grade_one(entry):
        folder = Folder(entry.name, metadata.get(entry.name, []))
        if entry.is_symlink() or not entry.is_dir():
            folder.status, folder.note = "not graded", "not a folder (a link or a file): nothing graded"
            return folder, ""
        # Laid over the course's stubs as on Gradescope: a whole clone, its pcl_course/, or loose modules.
        with tempfile.TemporaryDirectory(prefix="batch-", dir=out) as work:
            try:
                package, folder.note = assemble(entry, work, args.assignment)
            except StagingError as exc:
                folder.status, folder.note = "not graded", f"refused: {exc}"
                return folder, ""
            results = out / f"{entry.name}.json"
            uid = slots.get()
            try:
                code, output = run_graded_tests(
                    package,
                    results,
                    args.k,
                    sandbox=True,
                    require_isolation=require,
                    sandbox_uid=uid,
                    note=folder.note,
                    functions=list(ASSIGNMENTS[args.assignment]),
                )
            finally:
                slots.put(uid)
        if code not in (0, 1) or not results.exists():
            folder.status = "grading failed"
            return folder, output
        folder.grading, folder.status = Grading.from_gradescope(json.loads(results.read_text())), "graded"
        return folder, output

    # Each grading is its own pytest process: threads only wait for them.
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        graded = list(pool.map(grade_one, entries))
    folders = [folder for folder, _ in graded]

    functions = [
        f for f in ASSIGNMENTS[args.assignment] if any(d.grading and f in d.grading.per_function() for d in folders)
    ]
    csv_path = Path(args.csv) if args.csv else out / "marks.csv"
    with open(csv_path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["submission", "submitters", "score", "max_score", "status", "note", *functions])
        for folder in folders:
            people = "; ".join(f"{p['name']} <{p['email']}> {p['sid']}".strip() for p in folder.submitters)
            if folder.grading is None:
                writer.writerow([folder.name, people, 0, "", folder.status, folder.note, *[""] * len(functions)])
                continue
            per_function = folder.grading.per_function()
            writer.writerow(
                [
                    folder.name,
                    people,
                    f"{folder.grading.score:g}",
                    f"{folder.grading.max_score:g}",
                    folder.status,
                    folder.note,
                    *[f"{per_function.get(f, (0, 0))[0]:g}" for f in functions],
                ]
            )
    if args.gradebook:
        write_gradebook(args.gradebook, args.gradebook_column or args.assignment, folders, args.roster)
    for folder, output in graded:
        mark = f"{folder.grading.score:g} / {folder.grading.max_score:g}" if folder.grading else folder.status
        print(f"{folder.name}: {mark}" + ("" if folder.grading else f" ({folder.note})" if folder.note else ""))
        if folder.status == "grading failed":
            print(output, file=sys.stderr)
    counts = {status: sum(f.status == status for f in folders) for status in ("graded", "not graded", "grading failed")}
    print(f"{len(folders)} entries: " + ", ".join(f"{n} {status}" for status, n in counts.items() if n))
    print(f"Marks written to {csv_path}; results files in {out}")
    return 0


def similarity(args):
    from grading.similarity import DISPLAY_THRESHOLD, compare_class, counted, render_report

    root = Path(args.directory)
    if not root.is_dir():
        raise SystemExit(f"error: {root} is not a folder")
    threshold = DISPLAY_THRESHOLD if args.threshold is None else args.threshold
    pairs, skipped = compare_class(root)
    report = Path(args.report)
    report.write_text(render_report(pairs, skipped, threshold, args.top))
    for line in skipped:
        print(line)
    shown = [p for p in pairs if p.similarity >= threshold][: args.top]
    for pair in shown[:10]:
        print(f"{pair.similarity:4.0%}  {pair.module}.py  {pair.first}  {pair.second}")
    print(f"{counted(len(shown), 'pair')} at or above {threshold:.0%}; report written to {report}")
    return 0


INSTRUCTOR_COMMANDS = {
    "batch": "grading.gradescope",
    "release": "grading.release",
    "gradescope": "grading.gradescope",
    "similarity": "grading.similarity",
    "autograde": "grading.gradescope",
}


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m grading", description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    g = commands.add_parser("grade", help="grade a submission or the reference")
    g.add_argument("submission", nargs="?", help="a student's clone (holding pcl_course/)")
    g.add_argument("--reference", action="store_true", help="grade solutions/ instead")
    g.add_argument("--results", help="write the Gradescope results JSON here")
    g.add_argument("--junit", help="also write JUnit XML here")
    g.add_argument("-k", help="select tests as pytest -k does (e.g. -k pca)")
    g.add_argument(
        "--budget",
        type=float,
        metavar="SECONDS",
        help=f"wall-clock budget of the whole grading (default {config.SUBMISSION_BUDGET:g}); "
        "tests not started by then score 0",
    )
    g.add_argument(
        "--function",
        action="append",
        default=[],
        metavar="NAME",
        help="grade only this function's tests (by their grades marker); repeatable",
    )
    g.add_argument(
        "--assignment",
        choices=sorted(ASSIGNMENTS),
        help="grade only this assignment's functions (one per lecture; default: every graded function)",
    )
    g.add_argument(
        "--call-timeout",
        type=float,
        help=f"CPU seconds one call of a submission may take (default {config.CALL_TIMEOUT:g})",
    )
    g.add_argument(
        "--require-isolation",
        action="store_true",
        help="refuse to grade unless the submission runs isolated (bubblewrap, or root with a "
        "dedicated uid); for official marks",
    )
    g.add_argument("--require-full", action="store_true", help="exit 1 unless every selected test passed")
    g.add_argument(
        "--impl-module", action="append", default=[], metavar="MODULE=FILE", help=argparse.SUPPRESS
    )  # mutation checks: replace one module
    g.add_argument("--diagnose-always", action="store_true", help=argparse.SUPPRESS)  # false-diagnosis checks
    b = commands.add_parser("batch", help="grade every submission in a folder, in parallel")
    b.add_argument(
        "directory",
        help="a folder with one submission per subdirectory (a clone, its pcl_course/, or loose modules), "
        "or Gradescope's exported submissions with their submission_metadata.yml",
    )
    b.add_argument(
        "--assignment",
        required=True,
        choices=sorted(ASSIGNMENTS),
        help="the assignment to grade (one per lecture): its functions make the total",
    )
    b.add_argument("--csv", help="where to write the marks (default: OUT/marks.csv)")
    b.add_argument("--out", help="folder for the per-submission results files (default: DIRECTORY-results)")
    b.add_argument("--jobs", type=int, help="submissions graded at once (default: number of cores)")
    b.add_argument("-k", help="select tests as pytest -k does")
    b.add_argument("--gradebook", metavar="CSV", help="also write the totals in Canvas's gradebook layout here")
    b.add_argument(
        "--gradebook-column",
        help="the gradebook column of the totals (Canvas assignment; default: the assignment's name)",
    )
    b.add_argument(
        "--roster",
        metavar="CSV",
        help="a gradebook exported from Canvas: submission folders are matched to its students",
    )
    b.add_argument(
        "--allow-unisolated",
        action="store_true",
        help="grade even where submissions cannot be isolated (marks are then local checks)",
    )
    r = commands.add_parser("release", help="write the student repository (no solutions, no hidden tests)")
    r.add_argument("out_dir", help="an empty or new folder")
    r.add_argument(
        "--course-repository",
        metavar="OWNER/NAME",
        help="the published student repository whose grader the students' workflow checks out "
        "(default: the repository variable PCL_COURSE_REPOSITORY)",
    )
    s = commands.add_parser("similarity", help="pairwise similarity of the exercise modules across a class")
    s.add_argument("directory", help="a folder with one student clone (holding pcl_course/) per subdirectory")
    s.add_argument("--report", default="similarity.html", help="the HTML report to write (default similarity.html)")
    s.add_argument(
        "--threshold",
        type=float,
        default=None,
        metavar="SHARE",
        help="show pairs whose larger share of shared code reaches SHARE (default 0.33)",
    )
    s.add_argument("--top", type=int, default=100, help="show at most this many pairs (default 100)")
    z = commands.add_parser("gradescope", help="write the Gradescope autograder archive (no solutions)")
    z.add_argument("out_zip", help="the .zip to write, e.g. _build/gradescope/autograder-lecture1.zip")
    z.add_argument(
        "--assignment",
        required=True,
        choices=sorted(ASSIGNMENTS),
        help="the Gradescope assignment this archive grades (one per lecture)",
    )
    a = commands.add_parser(
        "autograde", help="inside a Gradescope container: grade ROOT/submission into ROOT/results/results.json"
    )
    a.add_argument("--root", default="/autograder", help="the autograder folder (default /autograder)")
    a.add_argument("--budget", type=float, metavar="SECONDS", help=argparse.SUPPRESS)
    a.add_argument("--assignment", required=True, choices=sorted(ASSIGNMENTS), help="the assignment graded")
    args = parser.parse_args(argv)
    module = INSTRUCTOR_COMMANDS.get(args.command)
    if module and importlib.util.find_spec(module) is None:
        print(f"error: `{args.command}` is an instructors' command, not in the student repository", file=sys.stderr)
        return 2
    if args.command == "similarity":
        return similarity(args)
    if args.command == "gradescope":
        from grading.gradescope import build_archive

        leaks = build_archive(args.out_zip, args.assignment)
        if leaks:
            print("error: the archive would contain reference code:\n" + "\n".join(leaks[:20]), file=sys.stderr)
            return 1
        print(
            f"Gradescope autograder of {args.assignment} written to {args.out_zip}: "
            "upload it as that assignment's autograder"
        )
        return 0
    if args.command == "autograde":
        from grading.gradescope import autograde

        return autograde(args.root, args.budget, args.assignment)
    if args.command == "release":
        from grading.release import release

        leaks = release(args.out_dir, args.course_repository)
        if leaks:
            print("error: the release contains reference code:\n" + "\n".join(leaks[:20]), file=sys.stderr)
            return 1
        print(f"Student repository written to {args.out_dir}")
        return 0
    if args.command == "grade":
        return grade(args)
    if args.command == "batch":
        return batch(args)
    return 2
