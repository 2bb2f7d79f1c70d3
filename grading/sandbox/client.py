"""The client of a worker process: :class:`Worker` runs a staged submission's functions.

The grading process (which runs the tests and decides the score) never
imports the submission. Each call is sent to a worker process
(``worker.py``) that runs at the strongest level of isolation the machine
allows (:func:`grading.sandbox.walls.isolation`), and answers with plain
data only (:mod:`grading.sandbox.protocol`). A call is limited by the
worker's CPU time (every process and thread of it), with a wall-clock
backstop, so that the machine's load changes no mark.

A call that times out, crashes the worker, leaves a thread or a process
running, or returns something that is not plain data fails that call (and
so that test); the next call starts a fresh worker. A module that cannot be
imported (it raises, exits, crashes or hangs at import) is detected once:
every later call into it fails at once with the same message.
"""

import builtins
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from grading import config, scratch
from grading.errors import ForbiddenAPI, SandboxError
from grading.sandbox import mappings, protocol
from grading.sandbox.arguments import advance_generators, layout, reported_paths
from grading.sandbox.arguments import arrays as arrays_in
from grading.sandbox.bubblewrap import (
    WORKER_FILES,
    bubblewrap_command,
    environment,
    python_executable,
    site_packages,
    spawn,
)
from grading.sandbox.processes import (
    become_subreaper,
    kill_uid,
    living_processes,
    preexec,
    process_table,
    reap,
    stat_of,
)
from grading.sandbox.usage import CallUsage
from grading.sandbox.walls import BUBBLEWRAP, UID, isolation, remove_files_of, rule_sets, rules_uid


class Worker:
    """One worker process for one staged submission; restarted after any failure.

    Parameters
    ----------
    staged_root : path
        The staging folder (:class:`grading.staging.StagedSubmission` root):
        its ``pcl_course/`` is the submission.
    timeout : float
        CPU seconds of one call, its module's import included, counted over
        every process and thread of the worker: a busy machine does not
        change a mark. ``config.CALL_WALL_FACTOR`` times as many wall-clock
        seconds stop a call that waits without computing.
    uid : int, optional
        The preferred dedicated sandbox uid (when the grader is root).
    level : Isolation, optional
        The isolation to use (default: :func:`isolation`'s, the strongest).
    """

    def __init__(self, staged_root, timeout=config.CALL_TIMEOUT, uid=None, level=None):
        self.staged_root = Path(staged_root).resolve()
        self.timeout = timeout
        self.process = None
        self.work = None  # the scratch folder: holds the lock, and self.home
        self.home = None
        self.isolation = level if level is not None else isolation(uid)
        self.uid = self.isolation.uid
        self.broken = {}  # module -> why it cannot be imported
        self.last_modified = []
        self._shared = []  # the last call's array arguments in the memfd: (path, array, offset)
        self.known_pids = None  # the worker's processes at the last count (None: not counted yet)
        self.extra = ()  # the running worker's own forbidden names (its module's, FORBIDDEN_IN_MODULE)
        self.exchange = None  # the memfd that holds a call's array arguments, shared with the worker
        self.exchange_inode = None
        for uid in self._uids():
            remove_files_of(uid)  # what an earlier grader, killed, may have left

    # -- process management ---------------------------------------------------

    def _command(self):
        # Bubblewrap's empty network namespace is the wall (its sandbox has no ldconfig for
        # libseccomp anyway); without one the seccomp filter is, required as a dedicated uid.
        if self.isolation.level == BUBBLEWRAP:
            network = "namespace"
        else:
            network = "required" if self.uid is not None else "optional"
        # Landlock where the probe measured it (the uid level): the worker then refuses to run without it.
        files = "landlock" if self.isolation.level == UID and not self.isolation.files_open else "open"
        tail = [",".join((*config.FORBIDDEN_PACKAGES, *self.extra)), network, str(self.exchange), files]
        if self.isolation.level == BUBBLEWRAP:
            return bubblewrap_command(self.staged_root, tail, self.extra), {}
        python = [
            str(python_executable()[0]),
            "-I",
            "-S",
            str(self.staged_root / WORKER_FILES[0].name),
            str(site_packages()),
            str(self.staged_root),
            *tail,
        ]
        return python, environment(self.home)

    def start(self):
        become_subreaper()
        for source in WORKER_FILES:  # the worker script and its wire protocol, nothing else of the grader's
            shutil.copy(source, self.staged_root / source.name)
            (self.staged_root / source.name).chmod(0o644)
        if self.uid is not None:
            # Readable by this worker's uid (Python lists the folders it imports
            # from), by no other sandbox uid: a classmate's is out of reach.
            os.chown(self.staged_root, 0, self.uid)
            os.chmod(self.staged_root, 0o750)
        # The scratch folder and its lock stay the grader's; the worker's HOME (uid and none
        # levels) is a folder inside it, so no submission can unlock it for a sweep.
        self.work = scratch.folder("grading-home-")
        self.home = os.path.join(self.work, "home")
        os.mkdir(self.home, 0o700)
        if self.uid is not None:
            os.chown(self.work, os.geteuid(), self.uid)
            os.chmod(self.work, 0o710)  # its uid may pass through, to its home, and list nothing
            os.chown(self.home, self.uid, self.uid)
        self.exchange = os.memfd_create("pcl-call-arguments")
        self.exchange_inode = os.fstat(self.exchange).st_ino
        command, env = self._command()
        self.known_pids = None  # a restarted worker's processes are new
        self.stderr = tempfile.TemporaryFile()
        self.process = spawn(
            command,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            env=env,
            cwd=self.home,
            preexec_fn=preexec(self.uid),
            pass_fds=(self.exchange,),
        )
        try:
            header = self._read_header(_Deadline(self, max(self.timeout, 60.0)))
            if not header.get("ready"):
                raise SandboxError(str(header.get("error") or "the worker did not start"), kind=GARBLED)
        except SandboxError as exc:
            self.stop()
            raise SandboxError(f"the sandbox could not start: {exc}", kind=exc.kind) from None
        self.baseline = self._tasks()

    def stop(self):
        if self.process is not None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            self.process.wait()
            self.process = None
            if self.uid is not None:
                kill_uid(self.uid)
            deadline = time.monotonic() + 5.0
            while time.monotonic() < deadline:
                reap()
                if not self._leftovers():
                    break
                time.sleep(0.01)
        work, self.work = self.work, None
        exchange, self.exchange = self.exchange, None
        if exchange is not None:
            os.close(exchange)
        if work:
            scratch.remove(work)

    def close(self):
        """Stop the worker and remove every file its uids left anywhere writable."""
        self.stop()
        for uid in self._uids():
            remove_files_of(uid)

    def _uids(self):
        """The sandbox uids this worker may run as: its slot's, and as a dedicated uid without
        namespaces the slot's uid of each set of rules, for the modules with rules of their own."""
        base = self.isolation.uid
        if base is None:
            return []
        return [base, *(rules_uid(base, extra) for extra in rule_sets())] if self.isolation.level == UID else [base]

    def _leftovers(self):
        if self.uid is not None:
            return any(p[3] == self.uid for p in living_processes())
        return False

    def _pids(self):
        """The worker's living processes: those of its uid, else its process, its descendants and
        the rest of its session (:meth:`_call_processes`)."""
        return [pid for pid, _, zombie in self._call_processes() if not zombie]

    def _call_processes(self):
        """(pid, parent, zombie) of every process a call of this worker started, zombies included.

        With a dedicated uid, every process of that uid. Without one, the
        worker's process, its descendants, and every process of its session
        (the worker is a session leader): an orphan is re-parented to the
        grader, a child subreaper, not to the worker. Bubblewrap's pid
        namespace keeps its orphans under its own init, a descendant.
        """
        table = process_table()
        if self.uid is not None:
            return [(pid, parent, zombie) for pid, parent, _, uid, zombie in table if uid == self.uid]
        root = self.process.pid
        children = {}
        for row in table:
            children.setdefault(row[1], []).append(row)
        found, stack = {}, [row for row in table if row[0] == root or row[2] == root]
        while stack:
            pid, parent, _, _, zombie = stack.pop()
            if pid not in found:
                found[pid] = (pid, parent, zombie)
                stack.extend(children.get(pid, ()))
        return list(found.values())

    def _tasks(self):
        """How many threads the worker runs, over all its processes (remembered for :meth:`cpu_seconds`)."""
        self.known_pids = self._pids()
        return sum(stat_of(pid)[0] for pid in self.known_pids)

    def cpu_seconds(self, pids=None):
        """CPU seconds the worker's processes (``pids``, else all found now) have used so far,
        their reaped children included."""
        return sum(stat_of(pid)[1] for pid in (self._pids() if pids is None else pids))

    def _stderr_tail(self):
        """The last lines the worker wrote to stderr; only the file's end is read."""
        size = self.stderr.seek(0, os.SEEK_END)
        self.stderr.seek(max(0, size - config.STDERR_TAIL_BYTES))
        text = self.stderr.read(config.STDERR_TAIL_BYTES).decode("utf-8", "replace").strip().splitlines()
        return "\n".join(line[:200] for line in text[-5:])

    # -- calls ------------------------------------------------------------------

    def call(self, module, function, args, kwargs):
        """Call ``pcl_course.<module>.<function>(*args, **kwargs)`` in the worker.

        The arguments here are never changed: the function works on copies
        in memory the grader shares with the worker (a memfd), which the
        grader reads back itself. Returns the answer; :attr:`last_modified`
        then holds the paths of the array arguments the call modified in
        place (``["args", 0]`` is the first positional one,
        ``["kwargs", "name"]`` a keyword one), by the grader's own reading.
        A random generator among the arguments draws on from where the call
        left it, as it does in-process: drawing from it is its use, not a
        change of an input (a function of ``rng`` must draw).
        """
        self.last_modified, self._shared = [], []
        if module in self.broken:
            raise SandboxError(self.broken[module], kind=IMPORT)
        extra = tuple(config.FORBIDDEN_IN_MODULE.get(module, ()))
        if self.process is not None and self.extra != extra:
            self.stop()  # a module with rules of its own runs in a worker of its own
        if self.process is None or self.process.poll() is not None:
            self.stop()
            if self.isolation.level == UID and self.extra != extra:
                # No masks: that module's uid is barred from its packages, and nothing the
                # other uid of the slot wrote (a copy of them, say) is left for it to find.
                remove_files_of(self.uid)
                self.uid = rules_uid(self.isolation.uid, extra)
            self.extra = extra
            self.start()
        try:
            result = self._call(module, function, args, kwargs)
        except BaseException as exc:
            from_submission = getattr(exc, "from_submission", False)
            stray = self._stray_tasks() if self.process is not None else False
            # The shared memory is the grader's: read whatever became of the worker (a change,
            # then a timeout, a crash or a thread left running, is a change all the same).
            modified = self._settle_in_place()
            if not from_submission or stray:
                self.stop()  # a timed-out, broken or forking worker never serves another call
            if from_submission and stray:
                error = SandboxError(STRAY_MESSAGE, kind=STRAY)
                error.modified = modified
                raise error from None
            exc.modified = modified
            self._refuse_forbidden_mappings(module)
            raise
        if self._stray_tasks():
            error = SandboxError(STRAY_MESSAGE, kind=STRAY)
            error.modified = self._settle_in_place()
            self.stop()
            raise error
        self._settle_in_place()
        self._refuse_forbidden_mappings(module)
        return result

    def _settle_in_place(self):
        """Read the shared arguments again once the call's threads have ended (the stray check
        waited for them): a thread that changed an input after the answer was sent counts too.
        Returns :attr:`last_modified`, the union of both readings."""
        again = self._changed_in_place(self._shared) if self._shared and self.exchange is not None else []
        known = {tuple(path) for path in self.last_modified}
        self.last_modified = self.last_modified + [path for path in again if tuple(path) not in known]
        return self.last_modified

    def _refuse_forbidden_mappings(self, module):
        """Raise :class:`ForbiddenAPI` if the worker holds a library ``module`` may not use
        (:mod:`grading.sandbox.mappings`), after stopping it: the next call starts clean."""
        if self.process is None:
            return
        found = mappings.violation(self.known_pids or self._pids(), self.extra, self.isolation.level == BUBBLEWRAP)
        if found is not None:
            self.stop()
            raise ForbiddenAPI(module, [f"{found} was loaded while {module}.py ran"])

    def _stray_tasks(self):
        """Whether the worker runs more threads or processes than when it started.

        A thread that was joined before the call returned may still be
        leaving the kernel's task list (``Thread.join`` returns just before
        the thread's last instructions, and a busy machine may not schedule
        them at once): only what outlives a grace period is stray.
        """
        if self.process is None:
            return False
        deadline = time.monotonic() + STRAY_GRACE_SECONDS
        while self._tasks() > self.baseline:
            if time.monotonic() > deadline:
                return True
            time.sleep(0.005)
        return False

    def _call(self, module, function, args, kwargs):
        arguments = {"args": list(args), "kwargs": dict(kwargs)}
        read_only = [path for path, value in arrays_in(arguments, []) if not value.flags.writeable]
        shared, size = layout(arguments)
        self._shared = shared  # read again once the call's threads have ended (_settle_in_place)
        os.ftruncate(self.exchange, 0)  # nothing of an earlier call's
        os.ftruncate(self.exchange, size)
        for _, value, offset in shared:  # written here first: what the memory holds is an argument or its change
            os.pwrite(self.exchange, np.ascontiguousarray(value).reshape(-1).view(np.uint8), offset)
        request = {
            "module": module,
            "function": function,
            "args": args,
            "kwargs": kwargs,
            "read_only": read_only,
            "exchange": [(path, offset) for path, _, offset in shared],
            "exchange_size": size,
        }
        deadline = _Deadline(self, self.timeout)
        try:
            protocol.write_request(self.process.stdin, request)
        except BrokenPipeError:
            raise SandboxError(self._death_message(), kind=DIED) from None
        try:
            header = self._read_header(deadline)
        except SandboxError as exc:
            self.broken[module] = (
                f"{module}.py cannot be imported: {exc}; every test of {module}.py fails until its import is fixed"
            )
            raise SandboxError(self.broken[module], kind=IMPORT) from None
        if not header.get("imported"):
            what = (
                f"raised {header.get('type')}: {header.get('message')}"
                if header.get("phase") == "import" and "type" in header
                else "the worker's answer was garbled"
            )
            where = f" (at {header['where']})" if isinstance(header.get("where"), str) and header["where"] else ""
            self.broken[module] = (
                f"{module}.py cannot be imported: it {what}{where}; every test of "
                f"{module}.py fails until its import is fixed"
            )
            raise SandboxError(self.broken[module], kind=IMPORT)
        answer = self._read_header(deadline)
        arrays = self._read_arrays(answer.get("arrays", []), deadline)
        advance_generators(arguments, answer.get("modified", []))
        self.last_modified = self._changed_in_place(shared)
        for path in reported_paths(arguments, answer.get("reshaped")):
            if path not in self.last_modified:
                self.last_modified.append(path)
        if answer.get("ok") is not True:
            if not isinstance(answer.get("type"), str):
                raise SandboxError("the worker's answer was garbled", kind=GARBLED)
            exc = _exception(answer)
            exc.from_submission = True  # the function raised: the worker itself is fine
            exc.modified = self.last_modified
            raise exc
        return _unwrapped(protocol.decode, answer.get("value"), arrays)

    def _changed_in_place(self, shared):
        """The paths of the array arguments whose copy in the shared memory the call changed:
        read here, from memory the grader made, not from what the worker says."""
        changed = []
        for path, value, offset in shared:
            data = os.pread(self.exchange, value.nbytes, offset)
            if len(data) != value.nbytes:  # the file was cut short: the memory was changed
                changed.append(path)
                continue
            if data != np.ascontiguousarray(value).tobytes():  # bit for bit: 0.0 made -0.0 is a change
                changed.append(path)
        return changed

    # -- reading the worker's frames, every size checked before it is read ---------

    def _wait_readable(self, deadline):
        stream = self.process.stdout.fileno()
        while True:
            remaining = deadline.wall - time.monotonic()
            if remaining <= 0:
                raise SandboxError(
                    f"timed out: the call waited for more than {deadline.wall_seconds:g} s (wall clock)", kind=TIMEOUT
                )
            deadline.usage.check_disk()  # at most every DISK_POLL_SECONDS, calls short or long
            ready, _, _ = select.select([stream], [], [], min(remaining, CPU_POLL_SECONDS))
            if ready:
                return stream
            if self.process.poll() is not None:
                # A dead worker answers nothing: whatever still holds its pipe open (a daemon it
                # forked, outside any namespace) is a leftover, never waited for.
                raise SandboxError(self._death_message(), kind=DIED)
            deadline.usage.check(deadline.cpu_seconds)  # every process of the call, together

    def _read_exactly(self, size, deadline):
        """``size`` bytes of the worker's stdout, into a buffer allocated once (``size`` is checked already)."""
        buffer = bytearray(size)
        view, got = memoryview(buffer), 0
        while got < size:
            stream = self._wait_readable(deadline)
            count = os.readv(stream, [view[got:]])
            if count == 0:
                raise SandboxError(self._death_message(), kind=DIED)
            got += count
        return buffer

    def _read_header(self, deadline):
        return _unwrapped(protocol.read_header, lambda size: self._read_exactly(size, deadline), config.HEADER_LIMIT)

    def _read_arrays(self, declared, deadline):
        """The arrays the answer's header declares: numeric dtypes only, all sizes checked first."""
        return _unwrapped(
            protocol.read_arrays,
            lambda size: self._read_exactly(size, deadline),
            declared,
            config.ANSWER_LIMIT,
            config.MAX_ARRAYS,
        )

    def _death_message(self):
        code = self.process.wait()
        how = f"killed by signal {-code}" if code < 0 else f"exit status {code}"
        hint = ""
        if code in (-signal.SIGKILL, -signal.SIGXCPU, -signal.SIGXFSZ):
            hint = " (a resource limit: memory, CPU time, file size or processes)"
        tail = self._stderr_tail()
        return f"the submission's process died ({how}){hint}" + (f"; its last output:\n{tail}" if tail else "")


CPU_POLL_SECONDS = 0.25  # how often a waiting call's CPU time is read
STRAY_GRACE_SECONDS = 2.0  # how long a thread or process past the call's end may take to finish exiting
STRAY_MESSAGE = "the submission left processes or threads running after the call returned"

# The kinds of sandbox failure (SandboxError.kind): what a hidden test may say of one.
TIMEOUT, DIED, GARBLED, TOO_LARGE = (
    SandboxError.TIMEOUT,
    SandboxError.DIED,
    SandboxError.GARBLED,
    SandboxError.TOO_LARGE,
)
UNSUPPORTED, IMPORT, STRAY = SandboxError.UNSUPPORTED, SandboxError.IMPORT, SandboxError.STRAY
GENERATOR, RAISED = SandboxError.GENERATOR, SandboxError.RAISED


def _unwrapped(read, *args):
    """``read(*args)``, a malformed answer raised as the :class:`SandboxError` of its kind."""
    try:
        return read(*args)
    except protocol.ProtocolError as exc:
        raise SandboxError(str(exc), kind=exc.kind) from None


@dataclass
class _Deadline:
    """A call's limits: CPU seconds of the call's processes from now, and a wall-clock backstop."""

    worker: Worker
    cpu_seconds: float

    def __post_init__(self):
        # Between calls the worker runs exactly the processes counted after the last one (any more
        # would have stopped it): no need to walk /proc again here, the hot path of every call.
        self.usage = CallUsage(self.worker, self.worker.known_pids)  # grading/sandbox/usage.py
        self.cpu_start = self.usage.start
        self.wall_seconds = self.cpu_seconds * config.CALL_WALL_FACTOR
        self.wall = time.monotonic() + self.wall_seconds


def _exception(answer):
    kind = str(answer.get("type"))[: config.MAX_TEXT]
    message = str(answer.get("message"))[: config.MAX_TEXT]
    where = answer.get("where") if isinstance(answer.get("where"), str) else ""
    where = where[: config.MAX_TEXT]
    shown = f" (at {where})" if where else ""
    cls = getattr(builtins, kind, None) if answer.get("builtin") is True else None
    if isinstance(cls, type) and issubclass(cls, Exception):
        try:
            exc = cls(message)
        except TypeError:  # a builtin whose constructor wants more (UnicodeDecodeError, ...)
            return SandboxError(f"raised {kind}: {message}{shown}", kind=RAISED)
        exc.where = where
        exc.raised_by_submission = answer.get("own") is True
        return exc
    return SandboxError(f"raised {kind}: {message}{shown}", kind=RAISED)
