"""What a worker's processes have mapped: the run-time wall against forbidden libraries.

The static scan (:mod:`grading.forbidden`) reads what a submission says it
imports; this module reads what its processes actually hold. Native code
runs only from memory mapped from a file, and the kernel lists every such
mapping in ``/proc/PID/maps``, which the grader reads from outside the
sandbox, where the submission cannot change it. After each call
:func:`violation` names

* a **forbidden library**: any file of a package the calling module may not
  use (:func:`grading.sandbox.bubblewrap.masked_paths`: the packages every
  module is refused, and the module's own, such as ``scipy.spatial`` in
  ``nn.py``), however it was imported: a computed name, ``exec``, a coding
  line, a helper module that imports it;
* **foreign native code**: an executable mapping of a file outside the
  interpreter, the environment's site-packages and the system libraries
  (the only code the course installs): a copy of scikit-learn unpacked into
  another folder, a compiled library written to ``/tmp``.

Under bubblewrap a mapping's path is the sandbox's (``/sandbox/site-packages``
for the host's site-packages), and it is translated back before matching.
What the reading cannot see: a library unmapped before the call returns
(``dlclose``) or used in a child that exits first. The environment's
forbidden packages are out of such a process's reach (masked under
bubblewrap; barred by ACLs for the sandbox uids, a module's own for its
set of rules' uid, :func:`grading.sandbox.walls.rules_uid`), so it would need a
library the submission carries as data in its source and writes out itself
(staging refuses compiled files, not text): a deliberate forgery, which
this module does not claim to stop.
"""

import os
import re
import shutil
from functools import cache
from pathlib import Path

from grading.sandbox.bubblewrap import masked_paths, python_executable, sandbox_roots


def _package_name(entry, site):
    """The dotted name a masked entry of ``site`` stands for (``scipy.spatial``, ``sklearn``)."""
    parts = list(entry.relative_to(site).parts)
    parts[-1] = parts[-1].split(".")[0].split("-")[0]
    return ".".join(parts)


@cache
def forbidden_files(extra=()):
    """(host path, dotted name) of every masked entry for a module forbidden ``extra`` too."""
    found = []
    for entry in masked_paths(extra):
        site = next((p for p in entry.parents if p.name in ("site-packages", "dist-packages")), entry.parent)
        found.append((entry, _package_name(entry, site)))
    return tuple(found)


@cache
def allowed_code_roots():
    """Host folders whose files may be mapped executable: the interpreter, the environment's
    site-packages and the system libraries, each resolved, and bubblewrap itself (its own
    processes stand between the grader and the worker)."""
    roots = {Path(host).resolve() for host, _ in sandbox_roots()}
    roots.add(python_executable()[0])
    if shutil.which("bwrap"):
        roots.add(Path(shutil.which("bwrap")).resolve())
    return tuple(sorted(roots))


def _host_path(path, bubblewrap):
    """A mapped file's path on the host, as a string (a sandbox path is translated back)."""
    if bubblewrap:
        for host, inside in _sandbox_prefixes():
            if path.startswith(inside):
                return host + path[len(inside) :]
    return path


@cache
def _sandbox_prefixes():
    return tuple((f"{str(host).rstrip('/')}/", f"{inside.rstrip('/')}/") for host, inside in sandbox_roots())


_MAPPING = re.compile(rb"^\S+ \S\S(\S)\S \S+ \S+ [1-9]\d* +(/[^\n]*)$", re.MULTILINE)  # perms' x, a file's path


def mapped_files(pid):
    """{path: executable} of every file ``pid`` has mapped, from ``/proc/PID/maps``
    (empty if the process is gone). Read after every call: one read, one regular expression
    (anonymous mappings have inode 0, and are skipped by it)."""
    try:
        handle = os.open(f"/proc/{pid}/maps", os.O_RDONLY)
        try:
            chunks = []
            while chunk := os.read(handle, 1 << 16):
                chunks.append(chunk)
        finally:
            os.close(handle)
    except OSError:
        return {}
    files = {}
    for executable, path in _MAPPING.findall(b"".join(chunks)):
        name = os.fsdecode(path)
        files[name] = files.get(name, False) or executable == b"x"
    return files


@cache
def _prefixes(extra):
    """((forbidden folder + "/", dotted name) ..., (allowed folder + "/") ...) for a module
    forbidden ``extra`` too: strings, for the hot path of every call."""
    forbidden = tuple((f"{str(entry).rstrip('/')}/", name) for entry, name in forbidden_files(extra))
    allowed = tuple(f"{str(root).rstrip('/')}/" for root in allowed_code_roots())
    return forbidden, allowed


def _under(path, prefixes):
    """Whether ``path`` (a string) is one of ``prefixes`` (strings ending in ``/``) or below it."""
    return path.startswith(prefixes) or f"{path}/".startswith(prefixes)


def violation(pids, extra=(), bubblewrap=False):
    """What the processes ``pids`` hold that a module forbidden ``extra`` may not, else None.

    Parameters
    ----------
    pids : iterable of int
        The worker's processes.
    extra : tuple of str
        The calling module's own forbidden names (dotted).
    bubblewrap : bool
        The processes run under bubblewrap (their paths are the sandbox's).

    Returns
    -------
    str or None
        ``"scipy.spatial"`` (a forbidden package, by its dotted name) or
        ``"native code from outside the environment"``; None if clean.
    """
    forbidden, allowed = _prefixes(tuple(extra))
    every_forbidden = tuple(prefix for prefix, _ in forbidden)
    for pid in pids:
        for raw, executable in mapped_files(pid).items():
            path = _host_path(raw.removesuffix(" (deleted)"), bubblewrap)
            if _under(path, every_forbidden):
                return next(name for prefix, name in forbidden if _under(path, (prefix,)))
            if executable and not _under(path, allowed):
                return "native code from outside the environment"
    return None
