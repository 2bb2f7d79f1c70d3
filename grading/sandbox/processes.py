"""The worker's processes: their limits, their accounting, and killing what they leave.

Read from ``/proc`` with plain ``os`` calls (some of these run after every
graded call): who a process belongs to, how many threads a user runs, how
much CPU time a worker used. A worker runs in its own session under
``RLIMIT_AS``, ``RLIMIT_CPU``, ``RLIMIT_FSIZE`` and, as its own user,
``RLIMIT_NPROC`` (:func:`preexec`).
"""

import os
import re
import resource
import signal
import stat
import sys
import time

from grading import config


def tasks_of_user(uid):
    """How many processes and threads the real user ``uid`` has now (what ``RLIMIT_NPROC`` counts)."""
    count = 0
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            if os.stat(entry.path).st_uid == uid:
                count += len(os.listdir(f"{entry.path}/task"))
        except OSError:  # gone since the scan
            continue
    return count


def process_limit(uid):
    """``RLIMIT_NPROC`` for a worker: :data:`config.PROCESS_LIMIT` more tasks than its user has now.

    A dedicated uid has none, so its limit is ``PROCESS_LIMIT``. A grader that
    is not root shares its own uid with its other workers, its test runner
    and the rest of the user's session: a fixed limit would let one
    submission's fork bomb stop a neighbour's worker from starting, or
    refuse a busy session its first worker at all.
    """
    if uid is not None or not sys.platform.startswith("linux"):
        return config.PROCESS_LIMIT
    limit = tasks_of_user(os.getuid()) + config.PROCESS_LIMIT
    _, hard = resource.getrlimit(resource.RLIMIT_NPROC)
    return limit if hard == resource.RLIM_INFINITY else min(limit, hard)


def preexec(uid):
    """Run in the worker's process before exec: its own session, limits, the sandbox uid."""
    nproc = process_limit(uid) if uid is not None or os.geteuid() != 0 else None

    def apply():
        os.setsid()  # its own process group: killed as a whole, forks included
        for limit, value in (
            (resource.RLIMIT_AS, config.MEMORY_LIMIT),
            (resource.RLIMIT_CPU, config.CPU_LIMIT),
            (resource.RLIMIT_FSIZE, config.FILE_SIZE_LIMIT),
            (resource.RLIMIT_CORE, 0),
            (resource.RLIMIT_NOFILE, config.OPEN_FILES_LIMIT),
        ):
            try:
                resource.setrlimit(limit, (value, value))
            except (OSError, ValueError):
                if sys.platform.startswith("linux"):
                    raise
                # macOS refuses some limits (RLIMIT_AS): never isolated there anyway
        if uid is not None:
            os.setgroups([])
            os.setgid(uid)
            os.setuid(uid)
        if nproc is not None:
            resource.setrlimit(resource.RLIMIT_NPROC, (nproc, nproc))

    return apply


def become_subreaper():
    """Adopt the worker's orphans (PR_SET_CHILD_SUBREAPER) so that they can be
    reaped here: a fork bomb's killed children would otherwise stay zombies of
    PID 1, which on some machines never reaps them, and use up RLIMIT_NPROC."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        pass


_STATUS_FIELDS = re.compile(rb"^(State|PPid|Uid|NSpgid|NSsid):\s*(\S+)", re.MULTILINE)  # the first value of each


def _read_proc(path, limit):
    """The first ``limit`` bytes of a /proc file (plain ``os`` calls: read after every call)."""
    handle = os.open(path, os.O_RDONLY)
    try:
        return os.read(handle, limit)
    finally:
        os.close(handle)


def _statuses():
    """(pid, state, parent pid, real uid, process group, session) of every process, zombies
    included, from /proc/PID/status.

    Its ``Uid:`` line holds the real uid first: the owner of a process's
    /proc files is root once it makes itself non-dumpable
    (``prctl(PR_SET_DUMPABLE, 0)``), which would hide it from
    :func:`kill_uid`. ``NSpgid`` and ``NSsid`` hold the group and session
    in our namespace first. The file escapes newlines in the process's name,
    so a name cannot forge a line.
    """
    with os.scandir("/proc") as entries:
        for entry in entries:
            if not entry.name.isdigit():
                continue
            try:
                status = _read_proc(f"/proc/{entry.name}/status", 1 << 16)
                fields = dict(_STATUS_FIELDS.findall(status, status.find(b"\n")))  # after the Name line
                yield (
                    int(entry.name),
                    fields[b"State"],
                    int(fields[b"PPid"]),
                    int(fields[b"Uid"]),
                    int(fields.get(b"NSpgid", -1)),
                    int(fields.get(b"NSsid", -1)),
                )
            except (OSError, KeyError, IndexError, ValueError):
                continue


def living_processes():
    """(pid, parent pid, process group, real uid) of every living process (no zombies).

    Called after every graded call (:func:`_statuses`).
    """
    return [(pid, parent, group, uid) for pid, state, parent, uid, group, _ in _statuses() if state != b"Z"]


def reap():
    try:
        while os.waitpid(-1, os.WNOHANG)[0] > 0:
            pass
    except ChildProcessError:
        pass


def kill_uid(uid):
    """Kill every process of ``uid``: a child that takes that uid and calls ``kill(-1, SIGKILL)``."""
    for _ in range(50):
        if not any(p[3] == uid for p in living_processes()):
            return
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child
            try:
                os.setgroups([])
                os.setgid(uid)
                os.setuid(uid)
                os.kill(-1, signal.SIGKILL)
            finally:
                os._exit(0)
        os.waitpid(pid, 0)
        time.sleep(0.02)
        reap()


_CLOCK_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def stat_of(pid):
    """(threads, CPU seconds with reaped children) of a process, from /proc/PID/stat; (0, 0) once it is gone."""
    try:
        text = _read_proc(f"/proc/{pid}/stat", 4096)
    except OSError:
        return 0, 0.0
    fields = text[text.rfind(b")") + 2 :].split()  # after the name, which may hold spaces
    # fields[0] is field 3 (state): utime, stime, cutime, cstime are fields 14-17, num_threads 20
    return int(fields[17]), sum(int(v) for v in fields[11:15]) / _CLOCK_TICKS


def process_table():
    """(pid, parent pid, session, real uid, zombie) of every process, zombies included.

    A zombie (a process that exited and that nobody reaped yet) still holds
    the CPU time it used, and a call's account must count it: a parent that
    never reaps its children would otherwise hide their time.
    """
    return [(pid, parent, session, uid, state == b"Z") for pid, state, parent, uid, _, session in _statuses()]


def usage_of(pid, memory=True):
    """(start time, CPU seconds of the process itself, CPU seconds of the children it reaped,
    threads, bytes of memory) of a process; None once it is gone.

    The memory is its proportional share of what it maps (``Pss`` of
    ``/proc/PID/smaps_rollup``: a page shared by n processes counts 1/n in
    each, so that a sum over processes counts every page once), else its
    resident set; 0 for a zombie or with ``memory=False``.
    """
    try:
        text = _read_proc(f"/proc/{pid}/stat", 4096)
    except OSError:
        return None
    fields = text[text.rfind(b")") + 2 :].split()
    # fields[0] is field 3: utime 14, stime 15, cutime 16, cstime 17, num_threads 20, starttime 22, rss 24
    own = (int(fields[11]) + int(fields[12])) / _CLOCK_TICKS
    reaped = (int(fields[13]) + int(fields[14])) / _CLOCK_TICKS
    resident = 0
    if memory and fields[0] != b"Z":
        resident = int(fields[21]) * _PAGE_SIZE
        try:
            rollup = _read_proc(f"/proc/{pid}/smaps_rollup", 1 << 14)
            match = _PSS.search(rollup)
            if match:
                resident = int(match.group(1)) * 1024
        except OSError:  # not ours to read (a non-dumpable process of the grader's own user): its RSS
            pass
    return int(fields[19]), own, reaped, int(fields[17]), resident


def unlisted_bytes(pid, counted):
    """Bytes of the files ``pid`` holds open or mapped that no folder lists: memfds, and files
    deleted while open or mapped (in ``/tmp`` or ``/dev/shm``, RAM or disk that no walk of the
    folders finds; a mapping's untouched pages show in no ``Pss``: a deleted file of 3 GiB, mapped
    and closed, was counted nowhere). Each file is counted once over ``counted`` (a set of inode
    numbers shared across one reading of a call's processes; pre-filled to leave a file out).
    The mappings are read where the grader may (``map_files`` needs ``CAP_SYS_ADMIN``: root)."""
    total = 0
    try:  # every thread's table: one of its own (unshare(CLONE_FILES)) is in no other's (h77)
        tables = [f"/proc/{pid}/task/{task}/fd" for task in os.listdir(f"/proc/{pid}/task")]
    except OSError:
        tables = [f"/proc/{pid}/fd"]
    for folder in (*tables, f"/proc/{pid}/map_files"):
        try:
            names = os.listdir(folder)
        except OSError:
            continue
        for name in names:
            try:
                info = os.stat(f"{folder}/{name}")
            except OSError:  # closed or unmapped meanwhile
                continue
            if not stat.S_ISREG(info.st_mode) or info.st_nlink > 0 or info.st_ino in counted:
                continue  # a memfd has no link either
            counted.add(info.st_ino)
            total += info.st_blocks * 512
    return total


def ticks_since_boot():
    """Now, in the unit and from the origin of a process's start time (/proc/PID/stat's field 22)."""
    return time.clock_gettime(time.CLOCK_BOOTTIME) * _CLOCK_TICKS


_PSS = re.compile(rb"^Pss:\s+(\d+) kB", re.MULTILINE)
_PAGE_SIZE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096
