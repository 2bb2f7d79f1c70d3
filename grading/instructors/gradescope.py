"""Gradescope: the autograder archive, and what runs in it for each submission.

``python -m grading gradescope OUT.zip`` writes the archive an instructor
uploads (:func:`build_archive`). Gradescope unpacks it into
``/autograder/source``, runs its ``setup.sh`` once as root to build the
image, then, for every submission in a fresh container, runs
``run_autograder``, which calls ``python -m grading autograde``
(:func:`autograde`):

1. find the student's code in ``/autograder/submission`` (:func:`locate`):
   the whole repository, its ``pcl_course/`` folder, or loose module files;
2. lay it over a pristine copy of the course's ``pcl_course/`` (stubs and
   helpers), so that a module the student did not upload is the stub;
3. grade that with the trusted grader, ``--require-isolation``: the
   submission runs as a dedicated uid that cannot read the course folder
   (``chmod 700`` by ``setup.sh``), in bubblewrap where the image allows it;
4. the results go to ``/autograder/results/results.json``, rewritten after
   every test, with a first line saying what was found and what was missing.

The archive holds the grader, the stubs and helpers, the public and hidden
tests and the pinned requirements; never ``solutions/``. It is scanned for
the reference's code (:mod:`grading.instructors.leakcheck`) before it is written.
"""

import json
import os
import shutil
import stat
import tempfile
import time
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from grading import ASSIGNMENT_MODULES, ASSIGNMENTS, EXERCISE_MODULES, REPO_ROOT, scratch
from grading.config import MAX_TEXT
from grading.errors import NothingToGrade, StagingError
from grading.instructors.leakcheck import find_leaks
from grading.instructors.reports import say
from grading.instructors.shipping import IGNORED, cut_reference_link
from grading.results import Grading, clean, write_atomically
from grading.runner import run_graded_tests
from grading.staging import read_regular_file, stage

TEMPLATES = Path(__file__).with_name("templates") / "gradescope"
COURSE = "course"  # the course copy's folder inside /autograder/source
# What the grader needs, from this repository; solutions/ never.
COURSE_FILES = (
    "pcl_course",
    "grading",
    "tests/graded",
    "tests/hidden",
    "requirements/grading.txt",
    "scripts/check_python.py",
)
SCRIPTS = ("setup.sh", "run_autograder")
ZIP_DATE = (2026, 1, 1, 0, 0, 0)  # every entry's time: the same course gives the same archive

# Where a submission's code may be, below /autograder/submission.
SEARCH_DEPTH = 3
SKIPPED_FOLDERS = {".git", ".venv", "venv", "node_modules", "__MACOSX", "_build", "__pycache__", ".github"}


# -- the archive ------------------------------------------------------------------


def _course_copy(into):
    """The course, as the archive holds it: grader, stubs, helpers, tests."""
    for name in COURSE_FILES:
        source = REPO_ROOT / name
        target = into / name
        if source.is_dir():
            shutil.copytree(source, target, ignore=IGNORED)
        else:
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
    cut_reference_link(into / "pcl_course")  # as in the release


def _zip_entry(name):
    info = zipfile.ZipInfo(name, date_time=ZIP_DATE)
    executable = name in SCRIPTS
    info.external_attr = ((0o755 if executable else 0o644) | stat.S_IFREG) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    return info


def build_archive(out_zip, assignment):
    """Write the Gradescope autograder archive of ``assignment`` to ``out_zip``.

    Parameters
    ----------
    out_zip : path
        The ``.zip`` to write (its folder is created).
    assignment : str
        A key of :data:`grading.config.ASSIGNMENTS`: the archive grades its
        functions only, so each lecture is one Gradescope assignment with
        its own total.

    Returns
    -------
    list of str
        Places in the archive holding the reference's code; the archive is
        written only when this is empty.
    """
    out_zip = Path(out_zip).resolve()
    with tempfile.TemporaryDirectory(prefix="gradescope-") as work:
        root = Path(work)
        _course_copy(root / COURSE)
        if assignment not in ASSIGNMENTS:
            raise ValueError(f"assignment must be one of {sorted(ASSIGNMENTS)}, got {assignment!r}")
        for name in SCRIPTS:
            text = (TEMPLATES / name).read_text().replace("@ASSIGNMENT@", assignment)
            (root / name).write_text(text)
            os.chmod(root / name, (TEMPLATES / name).stat().st_mode & 0o777)
        leaks = find_leaks(root)
        if leaks:
            return leaks
        out_zip.parent.mkdir(parents=True, exist_ok=True)
        temporary = out_zip.with_name(f".{out_zip.name}.part")
        with zipfile.ZipFile(temporary, "w") as archive:
            for path in sorted(p for p in root.rglob("*") if p.is_file()):
                name = path.relative_to(root).as_posix()
                archive.writestr(_zip_entry(name), path.read_bytes())
        os.replace(temporary, out_zip)
    return []


# -- finding a submission's code -----------------------------------------------------


@dataclass
class Located:
    """Where a submission's code is.

    Attributes
    ----------
    package : Path or None
        Its ``pcl_course/`` folder, when it has one (the whole repository or
        the folder was uploaded).
    modules : dict
        Otherwise: exercise module name -> the loose file (``pca.py``, ...).
    ignored : list of str
        Loose ``.py`` files that are not exercise modules (never graded).
    """

    package: Path = None
    modules: dict = field(default_factory=dict)
    ignored: list = field(default_factory=list)


def _walk(root):
    """``(depth, folder, entries)`` below ``root``, breadth first, never through a link."""
    queue = [(0, Path(root))]
    while queue:
        depth, folder = queue.pop(0)
        try:
            entries = sorted(os.scandir(folder), key=lambda e: e.name)
        except OSError:
            continue
        yield depth, folder, entries
        if depth < SEARCH_DEPTH:
            queue += [
                (depth + 1, Path(e.path))
                for e in entries
                if e.is_dir(follow_symlinks=False) and e.name not in SKIPPED_FOLDERS and not e.name.startswith(".")
            ]


def locate(submission):
    """Find the code in a Gradescope submission folder.

    The shallowest folder named ``pcl_course`` wins (an upload of the whole
    repository, or of the folder). Without one, the exercise modules are
    looked for as loose files (an upload of ``pca.py``, ``normals.py``, ...),
    the shallowest of each name.

    Raises
    ------
    StagingError
        When two candidates are equally shallow: the grader does not guess.
    """
    packages, loose = [], {}
    for depth, _folder, entries in _walk(submission):
        for entry in entries:
            if entry.name == "pcl_course" and (entry.is_dir(follow_symlinks=False) or entry.is_symlink()):
                packages.append((depth, Path(entry.path)))
            elif entry.name.endswith(".py") and entry.name[:-3] in EXERCISE_MODULES:
                loose.setdefault(entry.name[:-3], []).append((depth, Path(entry.path)))
    if packages:
        shallowest = [path for depth, path in packages if depth == packages[0][0]]
        if len(shallowest) > 1:
            shown = ", ".join(str(p.relative_to(submission)) for p in shallowest)
            raise StagingError(f"the submission holds several pcl_course/ folders ({shown}): upload one")
        return Located(package=shallowest[0])
    located = Located()
    for name, places in sorted(loose.items()):
        places.sort(key=lambda place: place[0])
        tied = [path for depth, path in places if depth == places[0][0]]
        if len(tied) > 1:
            shown = ", ".join(str(p.relative_to(submission)) for p in tied)
            raise StagingError(f"the submission holds several {name}.py ({shown}): upload one")
        located.modules[name] = tied[0]
    if located.modules:
        folder = next(iter(located.modules.values())).parent
        located.ignored = sorted(
            e.name for e in os.scandir(folder) if e.name.endswith(".py") and e.name[:-3] not in EXERCISE_MODULES
        )
    return located


@dataclass
class Assembled:
    """A submission's code laid over the course's stubs (:func:`lay_over_stubs`).

    Attributes
    ----------
    package : Path
        The ``pcl_course/`` to grade: the stubs, the submission's files over them.
    found : list of str
        The exercise modules the submission holds (``pca``: its ``pca.py``,
        or a package ``pca/``).
    where : str
        Where they were found: ``"pcl_course/"``, ``"the uploaded files"``, ``"code/"``.
    ignored : list of str
        Loose ``.py`` files that are not exercise modules (never graded).
    """

    package: Path
    found: list
    where: str
    ignored: list = field(default_factory=list)


def lay_over_stubs(submission, into, modules=EXERCISE_MODULES):
    """Lay the submission's code over a pristine ``pcl_course/`` in ``into``.

    The one reading of a submission's layout: ``assemble`` (Gradescope's
    ``autograde``, ``batch``) and the similarity report call it. Every file
    of the submission is read as staging reads it (regular files only, no
    link followed, with caps): a link, a device or compiled code refuses the
    whole submission.

    ``modules`` are the exercise modules looked for, named when none is found.

    Returns
    -------
    Assembled

    Raises
    ------
    NothingToGrade
        When no exercise module was found (a :class:`StagingError`).
    StagingError
        When the submission cannot be staged.
    """
    submission = Path(submission)
    located = locate(submission)
    package = Path(into) / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=IGNORED)
    if located.package is not None:
        staged = stage(located.package, Path(into) / "staged")
        for relative in staged.files:
            target = package / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(staged.package / relative, target)
        shutil.rmtree(staged.root)
        where = located.package.relative_to(submission).as_posix() + "/"
        found = [m for m in EXERCISE_MODULES if f"{m}.py" in staged.files or f"{m}/__init__.py" in staged.files]
    elif located.modules:
        for name, path in located.modules.items():
            (package / f"{name}.py").write_bytes(read_regular_file(path, f"{path.relative_to(submission)}"))
        where = sorted({p.parent.relative_to(submission).as_posix() for p in located.modules.values()})
        where = "the uploaded files" if where == ["."] else ", ".join(f"{w}/" for w in where)
        found = list(located.modules)
    else:
        raise NothingToGrade(modules)
    return Assembled(package, found, where, located.ignored)


def assemble(submission, into, assignment=None):
    """Lay the submission's code over a pristine ``pcl_course/`` in ``into`` (:func:`lay_over_stubs`).

    ``assignment`` (a key of :data:`grading.config.ASSIGNMENTS`) names the
    modules the note reports as found or missing; None: every exercise module.

    Returns
    -------
    package : Path
        ``into / "pcl_course"``, ready to grade.
    note : str
        One Markdown line: what was found, from where, and what was missing.

    Raises
    ------
    NothingToGrade
        When none of the assignment's modules was found (another lecture's files only, or none).
    StagingError
        When the submission cannot be staged.
    """
    graded = ASSIGNMENT_MODULES[assignment] if assignment else EXERCISE_MODULES
    assembled = lay_over_stubs(submission, into, graded)
    found = [m for m in assembled.found if m in graded]
    if not found:
        raise NothingToGrade(graded)
    missing = [m for m in graded if m not in found]
    note = f"Graded from {assembled.where}: " + ", ".join(f"`{m}.py`" for m in found) + "."
    if missing:
        note += " Missing (graded as the course's stub, 0 points): " + ", ".join(f"`{m}.py`" for m in missing) + "."
    if assembled.ignored:
        note += " Not graded (not exercise modules): " + ", ".join(f"`{n}`" for n in assembled.ignored) + "."
    return assembled.package, note


# -- one submission, in the container -------------------------------------------------


def _failure_results(message, started):
    grading = Grading(note=clean(message), execution_time=time.monotonic() - started)
    return grading.to_gradescope()


def _write_json(path, content):
    write_atomically(path, json.dumps(content, indent=2))


def seal_platform_files(root):
    """Make everything Gradescope put in the container (``root``: its upload, the course's
    source, ``submission_metadata.json`` with every earlier submission's results, hidden tests
    included) and everything the grader writes there readable by root only.

    The submission runs as another uid (or in bubblewrap, where none of it exists); the
    grader and Gradescope's harness run as root.
    """
    os.chmod(root, 0o700)
    for entry in Path(root).iterdir():
        if entry.is_file() and not entry.is_symlink():
            os.chmod(entry, 0o600)


def autograde(root="/autograder", budget=None, assignment="lecture1"):
    """Grade ``root/submission`` into ``root/results/results.json``; return the exit status.

    Only the functions of ``assignment`` are graded: its archive is one
    Gradescope assignment (:func:`build_archive`).

    A submission that cannot be graded (nothing found, refused by staging,
    or a container where it cannot be isolated) still gets a results file,
    with score 0 and one line that says why.
    """
    from grading.sandbox import isolation, protect

    started = time.monotonic()
    root = Path(root)
    results = root / "results" / "results.json"
    results.parent.mkdir(parents=True, exist_ok=True)
    seal_platform_files(root)
    protect(root)  # the permission probe checks, as the sandbox uid, that none of it can be read
    level = isolation()
    if not level.isolated:
        message = (
            f"The autograder could not isolate submissions here ({level.reason}). "
            "This is a problem of the autograder's set-up, not of your code: tell your instructor."
        )
        _write_json(results, _failure_results(message, started))
        print(message)
        return 1
    work = Path(scratch.folder("gradescope-submission-"))
    try:
        try:
            package, note = assemble(root / "submission", work, assignment)
        except StagingError as exc:
            message = str(exc) if isinstance(exc, NothingToGrade) else f"submission refused: {exc}"
            _write_json(results, _failure_results(message, started))
            say(message)  # names the submission's files: escaped, as every text a student chose
            return 0
        say(note)
        remaining = None if budget is None else max(0.0, budget - (time.monotonic() - started))
        code, output = run_graded_tests(
            package,
            results,
            sandbox=True,
            require_isolation=True,
            note=note,
            budget=remaining,
            function=list(ASSIGNMENTS[assignment]),
        )
        say(output, newlines=True, limit=max(MAX_TEXT, 6 * len(output)))
        if code not in (0, 1) or not results.exists():
            message = f"The grading run broke (pytest exit code {code}): tell your instructor."
            _write_json(results, _failure_results(message, started))
            print(message)
            return 1
        return 0
    finally:
        scratch.remove(work)
