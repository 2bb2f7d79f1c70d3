"""The advisory check's test of the grader (``.github/check_grader.py``, written by the release).

Usage::

    python3 -I check_grader.py SUBMISSION --course COURSE PATH...
    python3 -I check_grader.py SUBMISSION --manifest FILE --digest SHA256 PATH...

Every ``PATH`` (a folder or a file, relative to ``SUBMISSION``) is read
without following a link: a symbolic link, FIFO, device, socket, hard link
or a name with a control character, anywhere among them or in the folders
that lead to them, refuses the check. Then:

* with ``--course``, the entries (their list, their kinds and their bytes)
  must equal ``COURSE``'s, read the same way: the course repository checked
  out at the release's tag, which the student cannot rewrite;
* with ``--manifest``, the files must be exactly those of the ``sha256sum``
  manifest ``FILE`` (relative to ``SUBMISSION``), and ``FILE``'s own SHA-256
  must be ``SHA256``, which the workflow records. Both are files of the
  student's repository: this catches an edit of the grader, not a forgery.

Standard library only (it runs before the grading environment exists).
Exit status 0 when identical, 1 with one line per problem otherwise.
"""

import argparse
import hashlib
import os
import stat
import sys

FOLDER = "folder"  # an entry's kind in a listing; a file's is its SHA-256
SPECIAL = (
    (stat.S_ISLNK, "a symbolic link"),
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)
SHOWN = 20  # problems listed at most; the count says how many more


def shown(name):
    """``name`` as printed: quoted and escaped when it holds a character a terminal hides."""
    return name if name.isprintable() and "`" not in name else ascii(name)


def _kind(mode):
    return next((what for test, what in SPECIAL if test(mode)), "not a regular file or folder")


def _sha256(path):
    descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(descriptor, "rb") as handle:
        return hashlib.sha256(handle.read()).hexdigest()


def _parents(paths):
    """The folders that lead to ``paths`` (``tests`` for ``tests/graded``)."""
    parents = set()
    for path in paths:
        parts = path.split("/")
        parents.update("/".join(parts[:i]) for i in range(1, len(parts)))
    return sorted(parents)


def read_tree(root, paths):
    """The entries under ``paths`` of ``root``, read without following a link.

    Parameters
    ----------
    root : str
        A repository's folder.
    paths : list of str
        Folders and files of the grader, relative to ``root``.

    Returns
    -------
    entries : dict
        Relative name -> :data:`FOLDER` or the file's SHA-256; a missing
        path is absent.
    refused : list of str
        One line per entry that is not a regular file or a folder, or whose
        name a reader could not see.
    """
    entries, refused = {}, []
    for parent in _parents(paths):
        try:
            mode = os.lstat(os.path.join(root, parent)).st_mode
        except FileNotFoundError:
            continue
        if not stat.S_ISDIR(mode):
            refused.append(f"{shown(parent)}/ is {_kind(mode)}, not a folder")
    pending = list(paths)
    while pending:
        name = pending.pop()
        path = os.path.join(root, name)
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            continue
        if not name.isprintable():
            refused.append(f"{shown(name)} has a name with a control or unprintable character")
        elif stat.S_ISDIR(info.st_mode):
            entries[name] = FOLDER
            pending += [f"{name}/{child}" for child in os.listdir(path)]
        elif not stat.S_ISREG(info.st_mode):
            refused.append(f"{shown(name)} is {_kind(info.st_mode)}")
        elif info.st_nlink > 1:
            refused.append(f"{shown(name)} is a hard link (one of {info.st_nlink} names of a file)")
        else:
            entries[name] = _sha256(path)
    return entries, refused


def compare(entries, expected, source):
    """One line per entry of ``entries`` that differs from ``expected`` (``source`` names it)."""
    problems = []
    for name in sorted(set(entries) | set(expected)):
        mine, theirs = entries.get(name), expected.get(name)
        if mine == theirs:
            continue
        if mine is None:
            problems.append(f"{shown(name)} is missing ({source} has it)")
        elif theirs is None:
            problems.append(f"{shown(name)} was added (not in {source})")
        elif FOLDER in (mine, theirs):
            problems.append(f"{shown(name)} is a {'folder' if mine == FOLDER else 'file'} here, not in {source}")
        else:
            problems.append(f"{shown(name)} differs from {source}")
    return problems


def read_manifest(root, manifest, digest, paths):
    """The entries a ``sha256sum`` manifest lists under ``paths``, and its problems.

    The manifest must be a regular file whose SHA-256 is ``digest``: the
    manifest the workflow recorded at release, not a regenerated one.
    """
    path = os.path.join(root, manifest)
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return {}, [f"{manifest} is missing"]
    if not stat.S_ISREG(info.st_mode):
        return {}, [f"{manifest} is {_kind(info.st_mode)}"]
    actual = _sha256(path)
    if actual != digest:
        return {}, [f"{manifest} is not the release's (its SHA-256 is {actual}, the workflow records {digest})"]
    expected = {}
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            sha, _, name = line.rstrip("\n").partition("  ")
            expected[name] = sha
    above = set(_parents(paths))  # folders that lead to the grader's paths, not part of it
    expected.update({parent: FOLDER for parent in _parents(expected) if parent not in above})
    return expected, []


def check(submission, paths, course=None, manifest=None, digest=None):
    """The problems of ``submission``'s grader ``paths``: an empty list when it is the course's.

    Parameters
    ----------
    submission : str
        The student's repository.
    paths : list of str
        The grader's folders and files, relative to a repository's root.
    course : str, optional
        The course repository at the release's tag: compared entry by entry.
    manifest, digest : str, optional
        Without ``course``: the manifest (relative to ``submission``) and its
        recorded SHA-256.
    """
    entries, problems = read_tree(submission, paths)
    if course is not None:
        expected, refused = read_tree(course, paths)
        problems += [f"the course's {line}" for line in refused]
        return problems + compare(entries, expected, "the course's grader")
    expected, refused = read_manifest(submission, manifest, digest, paths)
    return problems + refused + ([] if refused else compare(entries, expected, manifest))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("submission")
    parser.add_argument("paths", nargs="+", metavar="PATH")
    parser.add_argument("--course")
    parser.add_argument("--manifest")
    parser.add_argument("--digest")
    args = parser.parse_args(argv)
    if (args.course is None) == (args.manifest is None or args.digest is None):
        parser.error("give --course, or --manifest and --digest")
    problems = check(args.submission, args.paths, args.course, args.manifest, args.digest)
    against = "the course repository's grader" if args.course else f"the release's manifest ({args.manifest})"
    if not problems:
        print(f"The grader ({', '.join(args.paths)}) is identical to {against}, with no link.")
        return 0
    print(f"::error::this repository's grader differs from {against}: {len(problems)} problem(s)")
    print("\n".join(problems[:SHOWN]))
    if len(problems) > SHOWN:
        print(f"... and {len(problems) - SHOWN} more")
    return 1


if __name__ == "__main__":
    sys.exit(main())
