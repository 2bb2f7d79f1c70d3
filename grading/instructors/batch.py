"""Grade a whole class on one machine: ``python -m grading batch``.

Each entry of a class folder (a student's clone, its ``pcl_course/``, loose
module files, or Gradescope's exported submissions with their
``submission_metadata.yml``) is laid over the course's stubs as on
Gradescope (:func:`grading.instructors.gradescope.assemble`) and graded in
its own pytest process, isolated, several at once, one dedicated sandbox
uid per parallel slot. The marks go to ``marks.csv`` (per function, with
why an entry was not graded) and, on request, to a Canvas gradebook
(:mod:`grading.instructors.gradebook`).
"""

import csv
import json
import os
import queue
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from grading import ASSIGNMENTS, config
from grading.errors import StagingError
from grading.instructors.gradebook import write_gradebook
from grading.instructors.gradescope import assemble
from grading.results import Grading
from grading.runner import run_graded_tests

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


def class_folders(root):
    """Every entry of the class folder, in name order: hidden entries and Gradescope's metadata aside."""
    entries = sorted(p for p in root.iterdir() if not p.name.startswith(".") and p.name != GRADESCOPE_METADATA)
    if not entries:
        raise SystemExit(f"error: {root} is empty")
    return entries


def batch(args):
    """``python -m grading batch``: grade every entry of a class folder (see the module docstring)."""
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
                    keyword=args.k,
                    sandbox=True,
                    require_isolation=require,
                    sandbox_uid=uid,
                    note=folder.note,
                    function=list(ASSIGNMENTS[args.assignment]),
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
