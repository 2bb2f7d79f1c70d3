"""What one call's processes use together (:class:`CallUsage`): CPU time, memory, tasks and,
as a dedicated uid, disk, read while the call runs by :class:`grading.sandbox.client.Worker`."""

import os
import signal
import time

from grading import config
from grading.errors import SandboxError
from grading.sandbox.processes import ticks_since_boot, unlisted_bytes, usage_of
from grading.sandbox.walls import BUBBLEWRAP, WRITABLE_ROOTS, files_of

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
        rows = [(pid, None, False) for pid in pids] if pids is not None else worker._call_processes()
        # A process first seen later but started before this call (a zombie an earlier call
        # left: the living ones are all in ``pids``) brings its earlier time into the baseline.
        self.since = ticks_since_boot() - 1
        self.start = 0.0
        self.start = self._read(rows, memory=False)[0]  # everything they used so far

    def _read(self, rows, memory=True):
        """(CPU seconds so far, bytes of memory now, tasks now) of the processes ``rows``."""
        cpu, used, tasks, current = 0.0, 0, 0, {}
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
                resident += unlisted_bytes(pid, counted)
            cpu, used, tasks = cpu + own + reaped, used + resident, tasks + threads
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
        files the uid owns where it can write exceed :data:`config.DISK_LIMIT`. Read at most every
        :data:`DISK_POLL_SECONDS` (a walk of those folders), whether the calls are long or short."""
        uid = self.worker.uid
        if uid is None or self.worker.isolation.level == BUBBLEWRAP:
            return
        now = time.monotonic()
        if now - _DISK_CHECKED.get(uid, 0.0) < DISK_POLL_SECONDS:
            return
        written = disk_usage_of(uid, (*WRITABLE_ROOTS, self.worker.work))
        _DISK_CHECKED[uid] = time.monotonic()
        if written > config.DISK_LIMIT:
            message = f"the submission wrote more than {_size(config.DISK_LIMIT)} of files"
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
_DISK_CHECKED = {}  # uid -> when its files were last summed (time.monotonic)


def _size(count):
    """A byte count as people write it (4 GiB, 256 MiB)."""
    for unit, size in (("GiB", 1024**3), ("MiB", 1024**2), ("KiB", 1024)):
        if count >= size:
            return f"{count / size:g} {unit}"
    return f"{count} bytes"


def disk_usage_of(uid, roots):
    """Bytes of the files ``uid`` owns below ``roots`` (allocated blocks: a sparse file counts
    what it holds), found as :func:`grading.sandbox.walls.remove_files_of` finds them."""
    return sum(info.st_blocks * 512 for _, info in files_of(uid, roots, into_own=True))
