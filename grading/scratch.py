"""The grader's scratch folders in the temporary directory, and the sweep of those a killed grading left.

A grading stopped by SIGKILL (a platform's time limit, an instructor's Ctrl-\\, the OOM killer)
cannot remove what it made: a staged copy of a student's package, the options file naming it,
the worker's home. Each such folder holds a lock file that the process that made it keeps
locked (``flock``) while it lives; the kernel releases the lock when that process ends, however
it ends. A folder whose lock can be taken is one nobody uses any more, and the next grading on
the machine removes it (:func:`sweep`), so no student's work outlives its grading by more than
that.
"""

import os
import shutil
import stat
import subprocess
import tempfile
import time

try:
    import fcntl
except ImportError:  # Windows: the grader says there that it needs Linux or macOS; nothing is locked
    fcntl = None

LOCK = ".grading-lock"
# The prefixes of every folder made by folder() (a sweep removes no other folder).
PREFIXES = ("grading-staged-", "grading-options-", "grading-home-", "grading-results-", "gradescope-submission-")
# A folder without its lock file is being made (the lock appears by a rename, already locked) or
# predates locks: it is swept once this old.
UNLOCKED_AGE = 3600.0

_held = {}  # folder -> the descriptor of its locked lock file, open while the folder is in use


def folder(prefix):
    """A new folder (mode 0700) in the temporary directory, locked by this process until
    :func:`remove` or the process's end.

    ``prefix`` must be one of :data:`PREFIXES`. The lock file is locked before it is given its
    name, so a concurrent sweep sees either no lock file (a new folder: left alone) or a held lock.
    """
    if prefix not in PREFIXES:
        raise ValueError(f"prefix must be one of {', '.join(PREFIXES)}, got {prefix!r}")
    made = tempfile.mkdtemp(prefix=prefix)
    if fcntl is None:
        return made
    making = os.path.join(made, LOCK + ".new")
    descriptor = os.open(making, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    fcntl.flock(descriptor, fcntl.LOCK_EX)
    os.rename(making, os.path.join(made, LOCK))
    _held[made] = descriptor
    return made


def remove(path):
    """Remove a folder made by :func:`folder`, and release its lock."""
    path = str(path)
    try:
        remove_tree(path)
    finally:
        descriptor = _held.pop(path, None)
        if descriptor is not None:
            os.close(descriptor)


def remove_tree(path):
    """Remove the folder ``path`` and everything in it, links not followed, however deep.

    ``shutil.rmtree``, and ``rm -rf`` where it fails: before Python 3.12 it recurses once per level, and a submission's
    home nested a few thousand folders deep made it raise RecursionError (past ignore_errors),
    which left the folder, and then every later grading's sweep broke on it. Such a tree goes to
    ``rm -rf``, which walks iteratively; what it cannot remove is left for a later sweep.
    """
    try:
        shutil.rmtree(path, ignore_errors=True)
    except RecursionError:  # only for such trees: a process per removal would cost every grading
        subprocess.run(["rm", "-rf", "--", str(path)], stdin=subprocess.DEVNULL, capture_output=True, check=False)


def sweep(directory=None):
    """Remove the scratch folders in ``directory`` (the temporary directory) that no living
    process holds. Returns how many were removed.

    Folders of other users are left alone; so is any entry that is not a plain folder with one of
    :data:`PREFIXES`. A folder of this user's whose lock is not a regular file of this user's
    (a directory, a link, another uid's file) is treated as a folder without a lock.
    """
    directory = directory or tempfile.gettempdir()
    removed = 0
    if fcntl is None:
        return removed
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return 0
    for entry in entries:
        if not entry.name.startswith(PREFIXES) or not entry.is_dir(follow_symlinks=False):
            continue
        if _abandoned(entry):
            remove_tree(entry.path)
            removed += 1
    return removed


def _abandoned(entry):
    lock = os.path.join(entry.path, LOCK)
    try:
        folder = entry.stat(follow_symlinks=False)
    except OSError:
        return False
    if folder.st_uid != os.geteuid():
        return False  # another user's: theirs to sweep
    try:
        found = os.lstat(lock)
    except FileNotFoundError:
        return time.time() - folder.st_mtime > UNLOCKED_AGE
    except OSError:
        return False
    if not stat.S_ISREG(found.st_mode) or found.st_uid != os.geteuid():
        # Not a lock this user made (folder() makes a regular file of its own): nobody can
        # hold it, so it is treated as a missing lock, and the folder is swept once old.
        return time.time() - folder.st_mtime > UNLOCKED_AGE
    try:
        descriptor = os.open(lock, os.O_RDWR | os.O_NOFOLLOW)
    except OSError:
        return False
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:  # held: in use
        return False
    finally:
        os.close(descriptor)  # the lock, if taken, goes with it: the folder is removed next
    return True
