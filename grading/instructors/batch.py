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

import hashlib
import json
import os
import queue
import stat
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from grading import ASSIGNMENTS, config
from grading.errors import NothingToGrade, StagingError, UsageError, existing_folder
from grading.instructors.gradebook import write_gradebook
from grading.instructors.gradescope import assemble
from grading.instructors.reports import csv_report, say
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


class MetadataError(ValueError):
    """Gradescope's metadata, or one submission's record in it, cannot be used (the message says why)."""


class _MetadataLoader(yaml.SafeLoader):
    """PyYAML's safe loader, its tree bounded in depth and in size, each alias counted as what it repeats.

    An alias repeats a whole subtree for a few bytes ("billion laughs"): a
    576-byte file of merge keys of merge keys took the old reader past 1 GiB
    of address space. Ruby's YAML, which writes Gradescope's export, may
    write an alias where an object repeats, so aliases are read, but each
    counts as many values as the subtree it stands for: the tree as the
    program sees it, expanded, holds at most
    :data:`grading.config.METADATA_MAX_NODES` values. An alias to a node
    still being read (a loop) is refused. The composer is PyYAML's own,
    checked at each node before it is built.
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0
        self._sizes = {}  # anchor -> values of its subtree, expanded

    def _count(self, values):
        self._nodes += values
        if self._nodes > config.METADATA_MAX_NODES:
            raise MetadataError(f"more than {config.METADATA_MAX_NODES} values (an alias counts as what it repeats)")

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            if event.anchor in self.anchors and event.anchor not in self._sizes:
                raise MetadataError(f"an alias inside its own anchor on line {event.start_mark.line + 1}")
            self._count(self._sizes.get(event.anchor, 1))
            return super().compose_node(parent, index)
        self._count(1)
        if self._depth >= config.METADATA_MAX_DEPTH:
            raise MetadataError(f"values nested more than {config.METADATA_MAX_DEPTH} deep")
        before = self._nodes
        self._depth += 1
        try:
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        if event.anchor is not None:
            self._sizes[event.anchor] = self._nodes - before + 1
        return node


def _read_bounded(path, limit):
    """The bytes of the regular file ``path``, refused past ``limit`` bytes or if it is not a regular file."""
    if not stat.S_ISREG(os.lstat(path).st_mode):
        raise MetadataError("not a regular file")
    with open(path, "rb") as handle:
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise MetadataError(f"larger than {limit // 1024**2} MiB")
    return data


def load_metadata(data):
    """Gradescope's ``submission_metadata.yml`` (bytes) as Python data: safe, bounded, never a traceback.

    Raises
    ------
    MetadataError
        Not UTF-8, not YAML, too many values (aliases expanded) or too deeply
        nested, a looping alias, or anything else PyYAML's safe loader refuses.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MetadataError(f"not UTF-8 text (byte {exc.start})") from None
    try:
        return yaml.load(text, Loader=_MetadataLoader)  # a safe loader, stricter still
    except MetadataError:
        raise
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f" on line {mark.line + 1}" if mark else ""
        raise MetadataError(f"not readable YAML ({exc.problem or exc.context}{where})") from None
    except Exception as exc:  # a value PyYAML cannot build: a date out of range, a 5,000-digit integer
        raise MetadataError(f"not readable YAML ({type(exc).__name__}: {exc})") from None


def _field(person, key):
    value = person.get(f":{key}")
    if value is None:
        return ""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise MetadataError(f"a submitter's :{key} is not a text")
    text = str(value).strip()
    if len(text) > config.METADATA_MAX_FIELD:
        raise MetadataError(f"a submitter's :{key} is longer than {config.METADATA_MAX_FIELD} characters")
    return text


def submitters(record):
    """The submitters (``name``, ``sid``, ``email``, each a str) of one submission's record.

    Raises
    ------
    MetadataError
        The record is not a mapping, has no list of submitters, or a
        submitter is not a mapping of short texts.
    """
    if not isinstance(record, dict):
        raise MetadataError("its record is not a mapping")
    people = record.get(":submitters")
    if not isinstance(people, list) or not people:
        raise MetadataError("its record has no list of :submitters")
    if not all(isinstance(person, dict) for person in people):
        raise MetadataError("a submitter is not a mapping")
    return [{key: _field(person, key) for key in ("name", "sid", "email")} for person in people]


def read_gradescope_metadata(root):
    """Folder name -> submitters, from Gradescope's ``submission_metadata.yml`` (none without one).

    Returns
    -------
    people : dict
        Folder name -> list of submitters (see :func:`submitters`).
    problems : list of str
        One line per submission whose record cannot be used, or one for the
        whole file: those submissions are graded under their folders' names.
    """
    path = root / GRADESCOPE_METADATA
    if not os.path.lexists(path):
        return {}, []
    try:
        document = load_metadata(_read_bounded(path, config.METADATA_MAX_BYTES))
        if not isinstance(document, dict):
            raise MetadataError("not a mapping of submission folders")
    except (MetadataError, OSError) as exc:
        reason = exc if isinstance(exc, MetadataError) else (exc.strerror or type(exc).__name__).lower()
        return {}, [f"{GRADESCOPE_METADATA}: {reason}: every submission is graded under its folder's name"]
    people, problems = {}, []
    for folder, record in document.items():
        try:
            people[str(folder)] = submitters(record)
        except MetadataError as exc:
            problems.append(f"{folder}: {exc} in {GRADESCOPE_METADATA}: graded under its folder's name")
    return people, problems


def class_folders(root):
    """Every entry of the class folder, in name order: hidden entries and Gradescope's metadata aside.

    Names are the file system's, decoded as :func:`os.fsdecode` does: a
    byte that is not UTF-8 (a Latin-1 ``é``) is kept as a lone surrogate,
    so the entry can still be opened; the reports escape it
    (:mod:`grading.instructors.reports`).
    """
    entries = sorted(p for p in root.iterdir() if not p.name.startswith(".") and p.name != GRADESCOPE_METADATA)
    if not entries:
        raise UsageError(f"{root} is empty: no submission to grade")
    return entries


def results_name(name):
    """The results file of the entry ``name``: ``NAME.json``, or, past a file name's 255 bytes, its start and a hash."""
    raw = os.fsencode(name)
    if len(raw) <= 250:
        return f"{name}.json"
    return os.fsdecode(raw[:200]) + f"-{hashlib.sha256(raw).hexdigest()[:16]}.json"


def marks_row(folder, functions):
    """``folder``'s row of ``marks.csv``: its columns, then one per function of ``functions``."""
    people = "; ".join(f"{p['name']} <{p['email']}> {p['sid']}".strip() for p in folder.submitters)
    if folder.grading is None:
        return [folder.name, people, 0, "", folder.status, folder.note, *[""] * len(functions)]
    per_function = folder.grading.per_function()
    return [
        folder.name,
        people,
        f"{folder.grading.score:g}",
        f"{folder.grading.max_score:g}",
        folder.status,
        folder.note,
        *[f"{per_function[f][0]:g}" if f in per_function else "" for f in functions],
    ]


def _mark_line(folder):
    """``name: 7 / 10``, or ``name: not graded (why)``."""
    mark = f"{folder.grading.score:g} / {folder.grading.max_score:g}" if folder.grading else folder.status
    return f"{folder.name}: {mark}" + ("" if folder.grading else f" ({folder.note})" if folder.note else "")


def batch(args):
    """``python -m grading batch``: grade every entry of a class folder (see the module docstring).

    Every text a student chose (a folder's name, a submitter's name, SID or
    email) reaches the terminal and the CSV files only through
    :mod:`grading.instructors.reports`. The rows of ``marks.csv`` are
    written (and flushed) as the class is graded, in name order, and an
    entry whose grading breaks the grader itself is recorded as ``grading
    failed``: the class's marks are never lost to one entry.
    """
    root = existing_folder(args.directory).resolve()
    entries = class_folders(root)
    metadata, problems = read_gradescope_metadata(root)
    for line in problems:
        say(line)
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
            except NothingToGrade as exc:
                folder.status, folder.note = "not graded", str(exc)
                return folder, ""
            except StagingError as exc:
                folder.status, folder.note = "not graded", f"refused: {exc}"
                return folder, ""
            results = out / results_name(entry.name)
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

    def account_for(entry):
        started = time.monotonic()
        try:
            folder, output = grade_one(entry)
        except Exception as exc:  # one entry the grader could not handle never costs the others their rows
            folder, output = Folder(entry.name, metadata.get(entry.name, [])), ""
            folder.status = "grading failed"
            folder.note = f"the grader broke on this entry: {type(exc).__name__}: {exc}"
        if progress:  # as each finishes, whatever its place in name order
            with finished_lock:
                finished.append(entry)
                say(f"[{len(finished)}/{len(entries)}] {_mark_line(folder)} ({time.monotonic() - started:.0f} s)")
        return folder, output

    # On a terminal, a line as each submission finishes; in a log, a line per submission in name order.
    progress = not args.quiet and sys.stdout.isatty()
    finished, finished_lock = [], threading.Lock()

    # The columns: every function of the assignment (empty where -k left it out).
    functions = list(ASSIGNMENTS[args.assignment])
    csv_path = Path(args.csv) if args.csv else out / "marks.csv"
    folders = []
    with csv_report(csv_path) as marks, ThreadPoolExecutor(max_workers=jobs) as pool:
        marks.writerow(["submission", "submitters", "score", "max_score", "status", "note", *functions])
        # Each grading is its own pytest process: threads only wait for them. Rows come in name order.
        for folder, output in pool.map(account_for, entries):
            folders.append(folder)
            marks.writerow(marks_row(folder, functions))
            if not progress:
                say(_mark_line(folder))
            if folder.status == "grading failed" and output:
                say(output, file=sys.stderr, newlines=True, limit=config.MAX_TEXT * 10)
    if args.gradebook:
        write_gradebook(args.gradebook, args.gradebook_column or args.assignment, folders, args.roster)
    counts = {status: sum(f.status == status for f in folders) for status in ("graded", "not graded", "grading failed")}
    say(f"{len(folders)} entries: " + ", ".join(f"{n} {status}" for status, n in counts.items() if n))
    say(f"Marks written to {csv_path}; results files in {out}")
    return 0
