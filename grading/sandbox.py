"""Run a submission's functions in a separate, limited worker process.

The grading process (which runs the tests and decides the score) never
imports the submission. Each call is sent to a worker process
(``grading/worker.py``) that

* runs under ``RLIMIT_AS`` (memory), ``RLIMIT_CPU`` and, as an unprivileged
  user, ``RLIMIT_NPROC`` (fork bombs), in its own process group, with an
  environment stripped to the essentials;
* when the grader runs as root with util-linux's ``unshare`` and ``setpriv``,
  runs as ``nobody`` in a private mount namespace where the reference
  solutions and the tests are empty directories;
* answers with plain data only: JSON plus an ``.npz`` read with
  ``allow_pickle=False``. Nothing the worker produced is ever unpickled.

A call that times out, crashes the worker or returns something that is not
plain data fails that call (and so that test); the next call starts a fresh
worker.
"""

import builtins
import json
import os
import pickle
import resource
import secrets
import select
import shutil
import signal
import stat
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from grading import REPO_ROOT
from grading.forbidden import FORBIDDEN_PACKAGES

WORKER = Path(__file__).with_name("worker.py")
MEMORY_LIMIT = 4 * 1024**3      # bytes of address space
CPU_LIMIT = 600                 # CPU seconds for a worker's whole life
PROCESS_LIMIT = 256             # processes of the unprivileged user (fork bombs)
NOBODY = 65534
HIDDEN_FROM_SUBMISSIONS = ("solutions", "tests")  # and the installed FORBIDDEN_PACKAGES


class SandboxError(Exception):
    """The worker failed: timeout, crash, or a result that is not plain data."""


def _limits(unprivileged):
    def apply():
        os.setsid()  # its own process group: killed as a whole, forks included
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
        resource.setrlimit(resource.RLIMIT_CPU, (CPU_LIMIT, CPU_LIMIT))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        if unprivileged:
            resource.setrlimit(resource.RLIMIT_NPROC, (PROCESS_LIMIT, PROCESS_LIMIT))
    return apply


def _make_reachable(path):
    """Let the unprivileged worker reach ``path``: search permission (o+x) on its ancestors.

    A clone in a private directory (``mktemp -d`` is mode 0700) would hide
    the virtual environment's packages from ``nobody``. Search permission
    alone lets it pass through a directory without listing it.
    """
    for parent in Path(path).resolve().parents:
        mode = parent.stat().st_mode
        if not mode & stat.S_IXOTH:
            os.chmod(parent, stat.S_IMODE(mode) | stat.S_IXOTH)


def _become_subreaper():
    """Adopt the worker's orphans (PR_SET_CHILD_SUBREAPER) so that they can be
    reaped here: a fork bomb's killed children would otherwise stay zombies of
    PID 1, which on some machines never reaps them, and use up RLIMIT_NPROC."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        pass


def _group_members(pgid):
    members = 0
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[2]) == pgid:  # the process group: field 5 of /proc/PID/stat
            members += 1
    return members


def _installed_packages(names):
    """Directories of the installed packages ``names`` (without importing them)."""
    import importlib.util

    found = []
    for name in names:
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.submodule_search_locations:
            found.extend(Path(p) for p in spec.submodule_search_locations)
    return found


def namespace_available():
    return os.geteuid() == 0 and bool(shutil.which("unshare")) and bool(shutil.which("setpriv"))


class Worker:
    """One worker process for one submission; restarted after any failure."""

    def __init__(self, clone_dir, timeout=60.0):
        self.clone_dir = str(Path(clone_dir).resolve())
        self.timeout = timeout
        self.process = None
        self.isolated = namespace_available()

    # -- process management ---------------------------------------------------

    def _command(self, nonce, work, clone):
        python = [sys.executable, "-I", str(Path(work) / WORKER.name), clone, nonce, work,
                  ",".join(FORBIDDEN_PACKAGES)]
        if not self.isolated:
            return python
        hidden = [REPO_ROOT / d for d in HIDDEN_FROM_SUBMISSIONS if (REPO_ROOT / d).is_dir()]
        hidden += [p for p in _installed_packages(FORBIDDEN_PACKAGES)]
        mounts = " && ".join(f"mount -t tmpfs -o size=64k,mode=0755 none '{path}'" for path in hidden)
        drop = ["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups", "--"]
        script = f"{mounts} && exec \"$@\"" if mounts else "exec \"$@\""
        return ["unshare", "--mount", "--propagation", "private", "--fork", "--",
                "sh", "-c", script, "sh", *drop, *python]

    def start(self):
        _become_subreaper()
        self.nonce = secrets.token_hex(8)
        self.work = tempfile.mkdtemp(prefix="grading-worker-")
        # The worker runs a snapshot of the package in its own directory: it
        # needs no access to wherever the clone lives, and only pcl_course/
        # comes along (no conftest.py, sitecustomize.py or .pth next to it).
        clone = Path(self.work) / "submission"
        shutil.copytree(Path(self.clone_dir) / "pcl_course", clone / "pcl_course",
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        shutil.copy(WORKER, Path(self.work) / WORKER.name)  # readable wherever the grader lives
        if self.isolated:
            _make_reachable(Path(sys.prefix) / "lib")  # the environment's packages
            for path in [Path(self.work), *Path(self.work).rglob("*")]:
                os.chown(path, NOBODY, NOBODY)
        self.stderr = tempfile.TemporaryFile()
        env = {"PATH": "/usr/bin:/bin", "HOME": self.work, "LANG": "C.UTF-8", "TMPDIR": self.work,
               "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
               "OPEN3D_DISABLE_WEB_VISUALIZER": "true", "MPLBACKEND": "Agg"}
        self.process = subprocess.Popen(
            self._command(self.nonce, self.work, str(clone)), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=self.stderr, env=env, cwd=self.work, preexec_fn=_limits(self.isolated),
        )
        self.buffer = b""

    def stop(self):
        if self.process is not None:
            pgid = self.process.pid
            try:
                os.killpg(pgid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            self.process.wait()
            self.process = None
            deadline = time.monotonic() + 5.0
            while _group_members(pgid) and time.monotonic() < deadline:
                try:
                    while os.waitpid(-1, os.WNOHANG)[0] > 0:
                        pass
                except ChildProcessError:
                    pass
                time.sleep(0.01)
        if getattr(self, "work", None):
            shutil.rmtree(self.work, ignore_errors=True)
            self.work = None

    def _stderr_tail(self):
        self.stderr.seek(0)
        text = self.stderr.read().decode("utf-8", "replace").strip().splitlines()
        return "\n".join(text[-5:])

    # -- calls ------------------------------------------------------------------

    def call(self, module, function, args, kwargs):
        if self.process is None or self.process.poll() is not None:
            self.stop()
            self.start()
        try:
            result = self._call(module, function, args, kwargs)
        except BaseException as exc:
            if not getattr(exc, "from_submission", False) or self._stray_processes():
                self.stop()  # a timed-out, broken or forking worker never serves another call
            if self.process is None and getattr(exc, "from_submission", False):
                raise SandboxError("the submission started processes of its own (a fork bomb?)") from None
            raise
        if self._stray_processes():
            self.stop()
            raise SandboxError("the submission started processes of its own (a fork bomb?)")
        return result

    def _stray_processes(self):
        """Whether the worker's process group holds more than the worker itself."""
        expected = 2 if self.isolated else 1  # unshare and the worker, or the worker alone
        return self.process is not None and _group_members(self.process.pid) > expected

    def _call(self, module, function, args, kwargs):
        request = pickle.dumps({"module": module, "function": function, "args": args, "kwargs": kwargs})
        try:
            self.process.stdin.write(struct.pack("<Q", len(request)) + request)
            self.process.stdin.flush()
        except BrokenPipeError:
            raise SandboxError(self._death_message()) from None
        line = self._read_line()
        answer = json.loads(line)
        if not answer["ok"]:
            exc = _exception(answer)
            exc.from_submission = True  # the function raised: the worker itself is fine
            raise exc
        arrays = {}
        if "npz" in answer:
            with np.load(answer["npz"], allow_pickle=False) as npz:
                arrays = {key: npz[key] for key in npz.files}
            os.unlink(answer["npz"])
        return _decode(answer["value"], arrays)

    def _read_line(self):
        deadline = time.monotonic() + self.timeout
        stream = self.process.stdout.fileno()
        marker = self.nonce.encode()
        while True:
            newline = self.buffer.find(b"\n")
            if newline >= 0:
                line, self.buffer = self.buffer[:newline], self.buffer[newline + 1:]
                if line.startswith(marker):
                    return line[len(marker):].decode("utf-8")
                continue  # not an answer of the worker's: ignore it
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise SandboxError(f"timed out: the call ran for more than {self.timeout:g} s")
            ready, _, _ = select.select([stream], [], [], remaining)
            if ready:
                chunk = os.read(stream, 1 << 16)
                if not chunk:
                    raise SandboxError(self._death_message())
                self.buffer += chunk

    def _death_message(self):
        code = self.process.wait()
        how = f"killed by signal {-code}" if code < 0 else f"exit status {code}"
        hint = ""
        if code in (-signal.SIGKILL, -signal.SIGXCPU):
            hint = " (a resource limit: memory, CPU time or processes)"
        tail = self._stderr_tail()
        return f"the submission's process died ({how}){hint}" + (f"; its last output:\n{tail}" if tail else "")


def _exception(answer):
    kind = answer["type"]
    message = answer["message"]
    where = f" (at {answer['where']})" if answer.get("where") else ""
    cls = getattr(builtins, kind, None) if answer.get("builtin") else None
    if isinstance(cls, type) and issubclass(cls, Exception):
        try:
            exc = cls(message)
        except TypeError:  # a builtin whose constructor wants more (UnicodeDecodeError, ...)
            return SandboxError(f"raised {kind}: {message}{where}")
        exc.where = answer.get("where", "")
        return exc
    return SandboxError(f"raised {kind}: {message}{where}")


def _decode(node, arrays):
    kind = node["t"]
    if kind == "ndarray":
        return arrays[node["k"]]
    if kind == "json":
        return node["v"]
    if kind == "npscalar":
        return np.dtype(node["dtype"]).type(node["v"])
    if kind in ("tuple", "list"):
        items = [_decode(item, arrays) for item in node["items"]]
        return tuple(items) if kind == "tuple" else items
    if kind == "dict":
        return {key: _decode(value, arrays) for key, value in node["items"].items()}
    raise SandboxError(f"returned {node['what']}: return plain numpy arrays, numbers, strings, "
                       "tuples, lists or dicts")
