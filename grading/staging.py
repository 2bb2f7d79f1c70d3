"""Copy a submission's ``pcl_course/`` into a folder of the grader's own.

The grader never grades a student's files where they lie: it stages a copy
first, and everything after (the forbidden-API scan, the sandbox's
read-only view) works on that copy. Staging follows no symbolic link and
copies only regular files, each opened with ``O_NOFOLLOW`` relative to its
already-opened parent folder, so that a file swapped for a link while the
copy runs is refused too. Anything else (a symbolic link, a device, a FIFO,
a socket, a file with several hard links, compiled code, too many or too
large files) refuses the whole submission with one line that says why: a
grade is never given to a tree the grader had to mutilate.
"""

import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

from grading import config, scratch
from grading.errors import StagingError


@dataclass
class StagedSubmission:
    """A staged copy of a submission's ``pcl_course/``.

    Attributes
    ----------
    root : Path
        A folder of the grader's; the copy is ``root / "pcl_course"``.
    files : list of str
        The staged files, relative to the package (``"pca.py"``, ``"sub/x.py"``).
    """

    root: Path
    files: list = field(default_factory=list)

    @property
    def package(self):
        return self.root / "pcl_course"


_KINDS = {
    stat.S_IFLNK: "a symbolic link",
    stat.S_IFCHR: "a device",
    stat.S_IFBLK: "a device",
    stat.S_IFIFO: "a FIFO",
    stat.S_IFSOCK: "a socket",
}


def _kind(mode):
    return _KINDS.get(stat.S_IFMT(mode), "not a regular file")


def _open_directory(name, dir_fd, shown):
    try:
        return os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=dir_fd)
    except OSError as exc:
        raise StagingError(f"{shown} cannot be read as a folder ({exc.strerror.lower()})") from None


class _Budget:
    def __init__(self):
        self.files = 0
        self.bytes = 0

    def take(self, size, shown):
        self.files += 1
        self.bytes += size
        if self.files > config.STAGE_MAX_FILES:
            raise StagingError(f"pcl_course/ holds more than {config.STAGE_MAX_FILES} files")
        if size > config.STAGE_MAX_FILE_BYTES:
            raise StagingError(f"{shown} is larger than {config.STAGE_MAX_FILE_BYTES // 1024**2} MiB")
        if self.bytes > config.STAGE_MAX_TOTAL_BYTES:
            raise StagingError(f"pcl_course/ holds more than {config.STAGE_MAX_TOTAL_BYTES // 1024**2} MiB")


def _read_regular_file(name, dir_fd, shown):
    """The bytes of ``name``, refused unless it is a regular file with one link."""
    before = os.stat(name, dir_fd=dir_fd, follow_symlinks=False)
    if not stat.S_ISREG(before.st_mode):
        raise StagingError(f"{shown} is {_kind(before.st_mode)}: submit regular files only")
    if before.st_nlink != 1:
        raise StagingError(f"{shown} is a hard link to another file: submit regular files only")
    fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, dir_fd=dir_fd)
    try:
        opened = os.fstat(fd)
        if (opened.st_dev, opened.st_ino) != (before.st_dev, before.st_ino) or not stat.S_ISREG(opened.st_mode):
            raise StagingError(f"{shown} changed while it was being copied")
        chunks, size = [], 0
        while size <= config.STAGE_MAX_FILE_BYTES:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def read_regular_file(path, shown):
    """The bytes of the file ``path``, read as staging reads a submission's files.

    A loose file of a submission (an uploaded ``pca.py``): refused unless it is
    a regular file with one link and at most
    :data:`grading.config.STAGE_MAX_FILE_BYTES` long; ``shown`` names it in
    the error.

    Raises
    ------
    StagingError
    """
    path = Path(path)
    parent_fd = _open_directory(str(path.parent), None, f"the folder of {shown}")
    try:
        data = _read_regular_file(path.name, parent_fd, shown)
    finally:
        os.close(parent_fd)
    _Budget().take(len(data), shown)
    return data


def _copy_tree(dir_fd, target, relative, budget, files, depth):
    if depth > config.STAGE_MAX_DEPTH:
        raise StagingError(f"pcl_course/{relative} is nested more than {config.STAGE_MAX_DEPTH} folders deep")
    target.mkdir(mode=0o755)
    with os.scandir(dir_fd) as entries:
        names = sorted(entry.name for entry in entries)
    for name in names:
        if name in config.STAGE_SKIPPED_NAMES:
            continue
        shown = f"pcl_course/{relative}{name}"
        info = os.stat(name, dir_fd=dir_fd, follow_symlinks=False)
        if stat.S_ISDIR(info.st_mode):
            child = _open_directory(name, dir_fd, shown)
            try:
                _copy_tree(child, target / name, f"{relative}{name}/", budget, files, depth + 1)
            finally:
                os.close(child)
            continue
        if name.endswith(config.STAGE_REFUSED_SUFFIXES) and stat.S_ISREG(info.st_mode):
            raise StagingError(f"{shown} is compiled code: submit Python source files only")
        data = _read_regular_file(name, dir_fd, shown)
        budget.take(len(data), shown)  # what was read, not what the folder announced
        path = target / name
        path.write_bytes(data)
        path.chmod(0o644)
        files.append(f"{relative}{name}")


def stage(package_dir, into=None):
    """Stage the submission's package ``package_dir`` (its ``pcl_course/``).

    Parameters
    ----------
    package_dir : path
        The submission's ``pcl_course/`` folder. It must itself be a real
        folder, not a symbolic link.
    into : path, optional
        An empty folder of the grader's to hold the copy (default: a new
        temporary folder, mode 0700).

    Returns
    -------
    StagedSubmission

    Raises
    ------
    StagingError
        With one line naming the first entry that cannot be staged.
    """
    package_dir = Path(package_dir)
    root = Path(into) if into is not None else Path(scratch.folder("grading-staged-"))
    root.mkdir(parents=True, exist_ok=True)
    root.chmod(0o700)  # the worker opens it to its own uid only (grading/sandbox/)
    parent_fd = _open_directory(str(package_dir.parent), None, "the submission's folder")
    try:
        info = os.stat(package_dir.name, dir_fd=parent_fd, follow_symlinks=False)
        if not stat.S_ISDIR(info.st_mode):
            raise StagingError(f"pcl_course is {_kind(info.st_mode)}, not a folder")
        package_fd = _open_directory(package_dir.name, parent_fd, "pcl_course/")
    finally:
        os.close(parent_fd)
    staged = StagedSubmission(root)
    try:
        _copy_tree(package_fd, staged.package, "", _Budget(), staged.files, 0)
    finally:
        os.close(package_fd)
    return staged
