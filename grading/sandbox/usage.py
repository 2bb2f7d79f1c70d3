"""What one call's processes use together (:class:`CallUsage`): CPU time, memory, tasks and,
as a dedicated uid, disk, read while the call runs by :class:`grading.sandbox.client.Worker`."""

import os
import signal
import stat
import time
from dataclasses import dataclass

from grading import config
from grading.errors import SandboxError
from grading.sandbox.processes import ticks_since_boot, unlisted_bytes, usage_of
from grading.sandbox.walls import BUBBLEWRAP, WORLD_WRITABLE_DEPTH, WRITABLE_ROOTS

TIMEOUT, DIED = SandboxError.TIMEOUT, SandboxError.DIED


class CallUsage:
    """What one call's processes use together: CPU seconds, memory, tasks and, as a dedicated
    uid, disk; read while the call runs (every ``CPU_POLL_SECONDS`` of :mod:`grading.sandbox.client`), the call stopped,
    every process of it killed, as soon as one is over its limit.

    The limits of :func:`grading.sandbox.processes.preexec` hold for each
    process; these hold for the call as a whole, however many processes it
    starts. The call's processes are :meth:`Worker._call_processes`'s:
    zombies count (they keep the CPU time they used until reaped), and a
    process gone since the last reading keeps the CPU time it had then,
    unless its parent, a process of the call, reaped it (that time then
    shows in the parent's reaped children's time). Memory is the sum of
    every living process's proportional share of what it maps (``Pss``):
    shared pages are counted once; and of the memfds they hold open, which
    no mapping need show, and the files they hold open after deleting them
    (each counted once, the call's own arguments left out: they are counted
    where the worker maps them).
    """

    def __init__(self, worker, pids=None):
        self.worker = worker
        self.seen = {}  # pid -> (start time, CPU seconds with reaped children, parent)
        self.gone = 0.0  # CPU seconds of processes gone that no process of the call reaped
        self.held = 0  # bytes of the files its processes hold that no folder lists (last reading)
        rows = [(pid, None, False) for pid in pids] if pids is not None else worker._call_processes()
        # A process first seen later but started before this call (a zombie an earlier call
        # left: the living ones are all in ``pids``) brings its earlier time into the baseline.
        self.since = ticks_since_boot() - 1
        self.start = 0.0
        self.start = self._read(rows, memory=False)[0]  # everything they used so far

    def _read(self, rows, memory=True):
        """(CPU seconds so far, bytes of memory now, tasks now) of the processes ``rows``."""
        cpu, used, tasks, held, current = 0.0, 0, 0, 0, {}
        counted = {self.worker.exchange_inode}  # the call's own arguments: counted where they are mapped
        for pid, parent, _ in rows:
            usage = usage_of(pid, memory)
            if usage is None:
                continue
            start, own, reaped, threads, resident = usage
            current[pid] = (start, own + reaped, parent)
            if self.seen.get(pid, (None,))[0] != start and start < self.since:
                self.start += own + reaped  # not this call's
            if memory:
                unlisted = unlisted_bytes(pid, counted)
                resident, held = resident + unlisted, held + unlisted
            cpu, used, tasks = cpu + own + reaped, used + resident, tasks + threads
        if memory:
            self.held = held
        for pid, (start, total, parent) in self.seen.items():
            if current.get(pid, (None,))[0] == start:
                continue
            if parent not in current:  # reaped by no process of the call: its time would be lost
                self.gone += total
        self.seen = current
        return cpu + self.gone, used, tasks

    def check(self, cpu_limit):
        """Stop the call (kill its processes, raise a :class:`SandboxError`) if it is over a limit."""
        rows = self.worker._call_processes()
        cpu, used, tasks = self._read(rows)
        why = None
        if cpu - self.start > cpu_limit:
            why = f"timed out: the call used more than {cpu_limit:g} s of CPU time", TIMEOUT
        elif used > config.CALL_MEMORY_LIMIT:
            why = f"the call used more than {_size(config.CALL_MEMORY_LIMIT)} of memory across its processes", DIED
        elif tasks > config.PROCESS_LIMIT:
            why = f"the call ran more than {config.PROCESS_LIMIT} processes and threads at once", DIED
        if why is not None:
            self._stop(rows, *why)

    def check_disk(self):
        """As a dedicated uid without bubblewrap (whose tmpfs are capped): stop the call if the
        files the uid owns where it can write, with those its processes hold open or mapped that
        no folder lists (deleted, memfds: :attr:`held`, from the last reading of :meth:`check`),
        are past a limit of :func:`files_limits` (bytes, entries, nesting). Read at most every
        :data:`DISK_POLL_SECONDS`, whether the calls are long or short, and then no more often
        than keeps the walk of those folders under :data:`DISK_WALK_SHARE` of the grader's CPU."""
        uid = self.worker.uid
        if uid is None or self.worker.isolation.level == BUBBLEWRAP:
            return
        if time.monotonic() < _DISK_NEXT.get(uid, 0.0):
            return
        limits = files_limits()
        walk_started = time.thread_time()
        found = files_usage_of(uid, (*WRITABLE_ROOTS, self.worker.work), limits)
        walk = time.thread_time() - walk_started
        _DISK_NEXT[uid] = time.monotonic() + max(DISK_POLL_SECONDS, walk / DISK_WALK_SHARE)
        message = None
        if found.bytes + self.held > limits.bytes:
            message = f"the submission wrote more than {_size(limits.bytes)} of files"
        elif found.entries > limits.entries:
            message = f"the submission made more than {limits.entries} files and folders"
        elif found.depth > limits.depth:
            message = f"the submission nested folders more than {limits.depth} deep"
        if message is not None:
            self._stop(self.worker._call_processes(), message, DIED)

    def _stop(self, rows, message, kind):
        """Kill the call's processes ``rows`` and raise the verdict."""
        for pid, _, _ in rows:  # at once, before anything else runs: the worker is stopped after
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        raise SandboxError(message, kind=kind)


DISK_POLL_SECONDS = 0.25  # how often the files of a dedicated uid are summed, at most
# The share of a core the grader spends summing them, at most: 9,990 empty folders (under the
# entry limit) took the grader 2.57 s of CPU per 10 s at a reading every 0.25 s (h75).
DISK_WALK_SHARE = 0.1
_DISK_NEXT = {}  # uid -> when its files are next summed (time.monotonic)


def _size(count):
    """A byte count as people write it (4 GiB, 256 MiB)."""
    for unit, size in (("GiB", 1024**3), ("MiB", 1024**2), ("KiB", 1024)):
        if count >= size:
            return f"{count / size:g} {unit}"
    return f"{count} bytes"


@dataclass(frozen=True)
class FilesUsage:
    """What a uid owns where it can write, or the limits of it: ``bytes`` of allocated blocks (a
    sparse file counts what it holds), ``entries`` (files, folders, links, ...) and ``depth``,
    the deepest nesting of its own folders."""

    bytes: int = 0
    entries: int = 0
    depth: int = 0

    def past(self, limits):
        return self.bytes > limits.bytes or self.entries > limits.entries or self.depth > limits.depth


def files_limits():
    """The :class:`FilesUsage` a dedicated uid may reach (read from :mod:`grading.config` when asked)."""
    return FilesUsage(config.DISK_LIMIT, config.FILES_LIMIT, config.FOLDER_DEPTH_LIMIT)


# O_NOATIME: a listing the walk makes must not show in the folder's access time, by which a
# submission saw the walk arrive and moved its files out of its way (26 walks dodged: h75).
_FOLDER = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NOATIME


def _open_folder(name, dir_fd=None):
    """A descriptor of the folder ``name``, its access time left alone where this user may (its
    owner, or root); links never followed."""
    try:
        return os.open(name, _FOLDER, dir_fd=dir_fd)
    except PermissionError:  # O_NOATIME on a folder not ours, without CAP_FOWNER
        return os.open(name, _FOLDER & ~os.O_NOATIME, dir_fd=dir_fd)


def files_usage_of(uid, roots, limits=None):
    """The :class:`FilesUsage` of the entries ``uid`` owns below ``roots``, found where
    :func:`grading.sandbox.walls.files_of` finds them, and whole below its own folders.

    Walked by file descriptors (``openat``, links never followed), not by path strings: a
    file below a path longer than ``PATH_MAX`` counts like any other (a walk by paths skipped
    what it could not name, and 1,000 MB went uncounted that way). The walk holds two
    descriptors per level of the folder it is in; with ``limits``, it stops as soon as a count
    is past its limit, so that its cost and its descriptors are bounded by them whatever the
    uid made (300,000 empty files, or folders nested 10,000 deep).
    """
    used = FilesUsage()
    for root in roots:
        if not root:
            continue
        try:
            top = _open_folder(root)
        except OSError:
            continue
        used = _walk(uid, top, used, limits)
        if limits is not None and used.past(limits):
            break
    return used


def _walk(uid, top, used, limits):
    """Add to ``used`` the entries below the open folder ``top`` (closed here) that ``uid`` owns."""
    total, entries, deepest = used.bytes, used.entries, used.depth
    most = limits if limits is not None else FilesUsage(float("inf"), float("inf"), float("inf"))
    frames = []  # (descriptor, its listing, depth, depth of the uid's own folders)
    try:
        frames.append((top, os.scandir(top), 0, 0))
        while frames:
            folder, listing, depth, own_depth = frames[-1]
            entry = next(listing, None)
            if entry is None:
                frames.pop()
                listing.close()
                os.close(folder)
                continue
            try:
                info = entry.stat(follow_symlinks=False)
            except OSError:
                continue
            owned, folder_entry = info.st_uid == uid, stat.S_ISDIR(info.st_mode)
            if owned:
                total, entries = total + info.st_blocks * 512, entries + 1
                deepest = max(deepest, own_depth + folder_entry)
                if total > most.bytes or entries > most.entries or deepest > most.depth:
                    break
            if not folder_entry:
                continue
            if owned:
                child_own_depth = own_depth + 1
            elif own_depth == 0 and info.st_mode & stat.S_IWOTH and depth < WORLD_WRITABLE_DEPTH:
                child_own_depth = 0
            else:
                continue
            try:
                child = _open_folder(entry.name, dir_fd=folder)
            except OSError:  # gone, or made a link since it was listed
                continue
            try:
                frames.append((child, os.scandir(child), depth + 1, child_own_depth))
            except OSError:
                os.close(child)
    finally:
        for folder, listing, _, _ in frames:
            listing.close()
            os.close(folder)
    return FilesUsage(total, entries, deepest)
