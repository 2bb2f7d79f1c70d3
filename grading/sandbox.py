"""Run a staged submission's functions in a separate, isolated worker process.

The grading process (which runs the tests and decides the score) never
imports the submission. Each call is sent to a worker process
(``grading/worker.py``) that runs at the strongest level of isolation the
machine allows (:func:`isolation`):

``bubblewrap``
    ``bwrap --unshare-all`` (user, pid, network, ipc, uts and cgroup
    namespaces), ``--die-with-parent``, ``--new-session``, a cleared
    environment, and a filesystem built from nothing: read-only binds of the
    interpreter (``sys.base_prefix``), the system libraries, the
    environment's site-packages with every forbidden package and every
    editable-install file masked, the staged submission and the worker
    script; a size-capped tmpfs for ``/tmp`` (also ``HOME``), the only
    writable place (the root is remounted read-only); its own ``/proc`` and
    a minimal ``/dev``. No repository, ``.git``, tests, solutions,
    ``grading/`` or other submission exists there.
``uid``
    No namespaces (a container that forbids them), but the grader is root:
    the worker runs as a dedicated unprivileged uid (one per ``batch`` slot)
    and the grader bars every sandbox uid from the forbidden packages with a
    POSIX ACL (:func:`bar_sandbox_uids`), then checks, as that uid, that
    the course's tests, solutions and ``.git`` and those packages cannot be
    read, and that a seccomp filter closes the network
    (``grading/worker.py``'s ``close_network``; the worker refuses to run
    without it). Everything that uid left running is killed after each
    worker, and every file it owns in the world-writable folders is removed
    before and after each submission (:func:`remove_files_of`).
``none``
    Neither: the worker runs as the grader's own user, with the resource
    limits only. Grading still runs, but the result is a local check, not a
    mark, and says so; ``--require-isolation`` refuses this level.

At every level the worker runs under ``RLIMIT_AS``, ``RLIMIT_CPU``,
``RLIMIT_FSIZE`` and, as its own user, ``RLIMIT_NPROC``, and answers with
plain data only, over its stdout: a JSON header, then raw numeric arrays
whose dtype and shape the header declares, every size checked against
:mod:`grading.config`'s caps before anything is allocated. The grader never
opens a path the worker names, and never unpickles or decompresses what the
worker sent. A call is limited by the worker's CPU time (every process and
thread of it), with a wall-clock backstop, so that the machine's load
changes no mark.

A call that times out, crashes the worker, leaves a thread or a process
running, or returns something that is not plain data fails that call (and
so that test); the next call starts a fresh worker. A module that cannot be imported (it raises, exits, crashes or hangs
at import) is detected once: every later call into it fails at once with
the same message.
"""

import builtins
import json
import os
import pickle
import re
import resource
import select
import shutil
import signal
import stat
import struct
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from grading import REPO_ROOT, config
from grading.errors import SandboxError

WORKER = Path(__file__).with_name("worker.py")
MAGIC = b"PCLW"
PROTECTED = ("tests", "solutions", ".git")  # of the course copy: never readable by a submission

# Paths inside the bubblewrap sandbox.
SANDBOX_PYTHON_ROOT = "/python"
SANDBOX_SITE = "/sandbox/site-packages"
SANDBOX_WORKER = "/sandbox/worker.py"
SANDBOX_SUBMISSION = "/submission"

BUBBLEWRAP, UID, NONE = "bubblewrap", "uid", "none"


@dataclass(frozen=True)
class Isolation:
    """How a worker is isolated: ``level`` (bubblewrap, uid or none), the
    uid that runs it (None: the grader's own) and, below bubblewrap, why."""

    level: str
    uid: int = None
    reason: str = ""

    @property
    def isolated(self):
        return self.level != NONE

    def describe(self):
        if self.level == BUBBLEWRAP:
            who = f"uid {self.uid}" if self.uid is not None else "the grader's user"
            return f"isolated: bubblewrap sandbox (no network, no files of the grader's), as {who}"
        if self.level == UID:
            return (
                f"isolated: dedicated uid {self.uid} that cannot read the grader's files, network closed by "
                f"a seccomp filter; no namespaces ({self.reason})"
            )
        return f"NOT ISOLATED ({self.reason}): this is a local check, not a mark"


def _site_packages():
    import sysconfig

    return Path(sysconfig.get_paths()["purelib"]).resolve()


def _python():
    """The interpreter's real path and its path relative to ``sys.base_prefix``."""
    executable = Path(sys.executable).resolve()
    base = Path(sys.base_prefix).resolve()
    try:
        return executable, executable.relative_to(base)
    except ValueError:
        return executable, None


def _make_reachable(path):
    """Let the sandbox user reach ``path``: search permission (o+x) on its ancestors.

    Search permission alone lets it pass through a directory without listing
    it: a virtual environment under a private directory (``mktemp -d`` is
    mode 0700, ``/root`` too) would otherwise be out of the sandbox user's
    reach, and bubblewrap, which runs as that user, could not bind it.
    """
    for parent in [*Path(path).resolve().parents]:
        mode = parent.stat().st_mode
        if not mode & stat.S_IXOTH:
            os.chmod(parent, stat.S_IMODE(mode) | stat.S_IXOTH)


def _site_dirs(root):
    """Folders under ``root`` that Python may import packages from."""
    patterns = (
        "lib/python3*/site-packages",
        "lib/python3*/dist-packages",
        "lib/python3/dist-packages",
        "local/lib/python3*/site-packages",
        "local/lib/python3*/dist-packages",
        "python3*/site-packages",
        "python3*/dist-packages",
        "python3/dist-packages",
    )
    found = {root} if root.name in ("site-packages", "dist-packages") else set()
    for pattern in patterns:
        found.update(p for p in root.glob(pattern) if p.is_dir())
    return sorted(found)


def _installed_paths(dist_info):
    """The paths a distribution installed, relative to its site folder (first column of its RECORD)."""
    try:
        record = (dist_info / "RECORD").read_text(errors="replace")
    except OSError:
        return set()
    paths = (line.split(",", 1)[0] for line in record.splitlines())
    return {path for path in paths if path and not path.startswith("..")}


def _masked_entries(site):
    """Entries of a site folder the submission must not see: the forbidden
    packages (their modules, compiled libraries, bundled ``.libs`` and
    metadata) and the editable install's files, which point back into the
    course repository."""
    forbidden = set(config.FORBIDDEN_PACKAGES)
    masked = set()
    for entry in site.iterdir():
        stem = entry.name.split(".")[0].split("-")[0]
        if entry.name.startswith(("pcl_course", "pcl-course")) and entry.name.endswith(".dist-info"):
            # This course's own editable install: every file it wrote points back into the repository.
            masked.add(entry)
            outside = [path for path in _installed_paths(entry) if not path.startswith(f"{entry.name}/")]
            masked.update(site / path for path in outside if (site / path).is_file())
        elif stem in forbidden or entry.name.startswith("__editable__") or entry.name.endswith(".egg-link"):
            masked.add(entry)
        elif entry.name.endswith(".dist-info"):
            # A distribution named otherwise (scikit_learn) that installs a forbidden module (sklearn).
            tops = {path.split("/", 1)[0] for path in _installed_paths(entry)}
            if {top.split(".")[0] for top in tops} & forbidden:
                masked.update(site / top for top in tops if (site / top).exists() or (site / top).is_symlink())
    return sorted(masked)


def _system_roots():
    """The system's library folders that exist here (bound into the sandbox as they are)."""
    return [path for path in ("/usr/lib", "/usr/lib64", "/usr/lib32") if Path(path).is_dir()]


def _import_roots():
    """(host folder, sandbox folder) of every folder the sandbox could import from."""
    base = Path(sys.base_prefix).resolve()
    return [(Path(p), p) for p in _system_roots()] + [(base, SANDBOX_PYTHON_ROOT), (_site_packages(), SANDBOX_SITE)]


@cache
def masked_paths():
    """Every entry, in every folder the sandbox could import from, that a submission must not
    reach: the forbidden packages and the editable install's files (:func:`_masked_entries`)."""
    found = []
    for root, _ in _import_roots():
        for site_dir in _site_dirs(root):
            found += [entry for entry in _masked_entries(site_dir) if entry not in found]
    return tuple(found)


@cache
def _environment_binds():
    """The options that bind the interpreter, the system libraries and the
    site-packages, with every forbidden package masked: the same for every
    worker of this process, and slow to find (every distribution's metadata
    is read), so found once."""
    options = []
    for source in _system_roots():
        options += ["--ro-bind", source, source, "--symlink", f"usr/{Path(source).name}", f"/{Path(source).name}"]
    options += ["--ro-bind-try", "/etc/ld.so.cache", "/etc/ld.so.cache"]
    roots = _import_roots()
    for source, target in roots[len(_system_roots()) :]:
        options += ["--ro-bind", str(source), target]
    # Mask the forbidden packages wherever the sandbox could import them from.
    for entry in masked_paths():
        source_root, target_root = next((s, t) for s, t in roots if s in entry.parents)
        target = f"{target_root}/{entry.relative_to(source_root)}"
        if entry.is_dir() and not entry.is_symlink():
            options += ["--tmpfs", target]
        else:
            options += ["--ro-bind", "/dev/null", target]
    return tuple(options)


def bar_sandbox_uids(paths):
    """Deny every sandbox uid all access to ``paths`` with a POSIX ACL (``setfacl``).

    Without namespaces nothing can hide a file from a process, but a named
    ACL entry with no permission bars that one uid and changes nothing for
    anyone else (the grader, the book's build, other users of the
    environment). A folder barred is barred whole: nothing below it can be
    reached. Returns None when done, else why not.
    """
    if not paths:
        return None
    if not shutil.which("setfacl"):
        return "setfacl is not installed, to bar the sandbox uids from the forbidden packages (apt-get install acl)"
    uids = range(config.SANDBOX_UID_BASE, config.SANDBOX_UID_BASE + config.SANDBOX_UID_SLOTS)
    entries = ",".join(f"u:{uid}:---" for uid in uids)
    completed = subprocess.run(
        ["setfacl", "-P", "-m", entries, "--", *[str(p) for p in paths]], capture_output=True, text=True
    )
    if completed.returncode != 0:
        why = (completed.stderr.strip().splitlines() or ["?"])[-1]
        return f"the sandbox uids could not be barred from the forbidden packages ({why})"
    return None


def _bubblewrap_command(staged_root, python_argv_tail):
    """The ``bwrap`` command line that runs the worker on a staged submission."""
    executable, relative = _python()
    command = [
        "bwrap",
        "--unshare-all",
        "--unshare-user",
        "--disable-userns",
        "--die-with-parent",
        "--new-session",
        "--clearenv",
        "--hostname",
        "sandbox",
        "--cap-drop",
        "ALL",
        *_environment_binds(),
    ]
    command += [
        "--ro-bind",
        str(staged_root / "pcl_course"),
        f"{SANDBOX_SUBMISSION}/pcl_course",
        "--ro-bind",
        str(staged_root / WORKER.name),
        SANDBOX_WORKER,
        "--proc",
        "/proc",
        "--dev",
        "/dev",
        "--size",
        str(config.TMP_SIZE),
        "--tmpfs",
        "/tmp",
        "--chdir",
        "/tmp",
        # Last, after every bind: the root (a tmpfs of bubblewrap's, in RAM and uncapped)
        # read-only, so that the capped /tmp is the only place the submission can write.
        "--remount-ro",
        "/",
    ]
    for key, value in _environment("/tmp").items():
        command += ["--setenv", key, value]
    python = f"{SANDBOX_PYTHON_ROOT}/{relative}" if relative is not None else str(executable)
    return [*command, "--", python, "-I", "-S", SANDBOX_WORKER, SANDBOX_SITE, SANDBOX_SUBMISSION, *python_argv_tail]


def _spawn(command, **kwargs):
    """Start ``command``; a ``bwrap`` command gets its arguments through a pipe
    (``--args FD``), so that no path of the grader's shows in the sandbox's
    ``/proc/1/cmdline``."""
    if command[0] != "bwrap":
        return subprocess.Popen(command, **kwargs)
    end = command.index("--")  # the options go through the pipe, the sandbox's own command line stays
    read, write = os.pipe()
    try:
        os.write(write, b"".join(arg.encode() + b"\0" for arg in command[1:end]))
    finally:
        os.close(write)
    try:
        return subprocess.Popen(["bwrap", "--args", str(read), *command[end:]], pass_fds=(read,), **kwargs)
    finally:
        os.close(read)


def _environment(home):
    return {
        "PATH": "/usr/bin:/bin",
        "HOME": home,
        "TMPDIR": home,
        "LANG": "C.UTF-8",
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "NUMBA_NUM_THREADS": "1",
        "NUMBA_CACHE_DIR": f"{home}/numba",
        "OPEN3D_DISABLE_WEB_VISUALIZER": "true",
        "MPLBACKEND": "Agg",
    }


def _tasks_of_user(uid):
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


def _process_limit(uid):
    """``RLIMIT_NPROC`` for a worker: :data:`config.PROCESS_LIMIT` more tasks than its user has now.

    A dedicated uid has none, so its limit is ``PROCESS_LIMIT``. A grader that
    is not root shares its own uid with its other workers, its test runner
    and the rest of the user's session: a fixed limit would let one
    submission's fork bomb stop a neighbour's worker from starting, or
    refuse a busy session its first worker at all.
    """
    if uid is not None or not sys.platform.startswith("linux"):
        return config.PROCESS_LIMIT
    limit = _tasks_of_user(os.getuid()) + config.PROCESS_LIMIT
    _, hard = resource.getrlimit(resource.RLIMIT_NPROC)
    return limit if hard == resource.RLIM_INFINITY else min(limit, hard)


def _preexec(uid):
    """Run in the worker's process before exec: its own session, limits, the sandbox uid."""
    process_limit = _process_limit(uid) if uid is not None or os.geteuid() != 0 else None

    def apply():
        os.setsid()  # its own process group: killed as a whole, forks included
        for limit, value in (
            (resource.RLIMIT_AS, config.MEMORY_LIMIT),
            (resource.RLIMIT_CPU, config.CPU_LIMIT),
            (resource.RLIMIT_FSIZE, config.FILE_SIZE_LIMIT),
            (resource.RLIMIT_CORE, 0),
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
        if process_limit is not None:
            resource.setrlimit(resource.RLIMIT_NPROC, (process_limit, process_limit))

    return apply


def _become_subreaper():
    """Adopt the worker's orphans (PR_SET_CHILD_SUBREAPER) so that they can be
    reaped here: a fork bomb's killed children would otherwise stay zombies of
    PID 1, which on some machines never reaps them, and use up RLIMIT_NPROC."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        pass


_STATUS_FIELDS = re.compile(rb"^(State|PPid|Uid|NSpgid):\s*(\S+)", re.MULTILINE)  # Uid: the real one first


def _processes():
    """(pid, parent pid, process group, real uid) of every living process (no zombies).

    From /proc/PID/status, whose ``Uid:`` line holds the real uid: the owner
    of a process's /proc files is root once it makes itself non-dumpable
    (``prctl(PR_SET_DUMPABLE, 0)``), which would hide it from
    :func:`kill_uid`. Called after every graded call, so plain ``os`` calls
    rather than ``pathlib``. The status file escapes newlines in the
    process's name, so a name cannot forge a line.
    """
    found = []
    with os.scandir("/proc") as entries:
        for entry in entries:
            if not entry.name.isdigit():
                continue
            try:
                handle = os.open(f"/proc/{entry.name}/status", os.O_RDONLY)
                try:
                    status = os.read(handle, 1 << 16)
                finally:
                    os.close(handle)
                fields = dict(_STATUS_FIELDS.findall(status, status.find(b"\n")))  # after the Name line
                state, parent, uid = fields[b"State"], int(fields[b"PPid"]), int(fields[b"Uid"])
                group = int(fields.get(b"NSpgid", -1))
            except (OSError, KeyError, IndexError, ValueError):
                continue
            if state != b"Z":
                found.append((int(entry.name), parent, group, uid))
    return found


def _reap():
    try:
        while os.waitpid(-1, os.WNOHANG)[0] > 0:
            pass
    except ChildProcessError:
        pass


def kill_uid(uid):
    """Kill every process of ``uid``: a child that takes that uid and calls ``kill(-1, SIGKILL)``."""
    for _ in range(50):
        if not any(p[3] == uid for p in _processes()):
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
        _reap()


# The folders where any user may create files: what a dedicated uid can leave behind.
WRITABLE_ROOTS = ("/tmp", "/var/tmp", "/dev/shm", "/run/lock", "/var/lock", "/dev/mqueue")


def remove_files_of(uid, roots=WRITABLE_ROOTS):
    """Remove every file and folder that ``uid`` owns below ``roots``.

    A dedicated uid can create entries only where others may write: in
    world-writable folders (recursed into) and in its own folders (removed
    whole). Called before and after each submission in the uid mode, whose
    processes are all dead by then, so that nothing one submission wrote is
    there for the next one to find. Links are removed, never followed.
    """
    stack = [(root, 0) for root in roots]
    while stack:
        folder, depth = stack.pop()
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            try:
                info = entry.stat(follow_symlinks=False)
            except OSError:
                continue
            is_folder = stat.S_ISDIR(info.st_mode)
            if info.st_uid == uid:
                if is_folder:
                    shutil.rmtree(entry.path, ignore_errors=True)
                else:
                    try:
                        os.unlink(entry.path)
                    except OSError:
                        pass
            elif is_folder and info.st_mode & stat.S_IWOTH and depth < 32:
                stack.append((entry.path, depth + 1))


def _probe_script(paths):
    return (
        "import os, sys\n"
        f"sys.path.append({str(_site_packages())!r})\n"
        "import numpy\n"
        "readable = []\n"
        f"for path in {[str(p) for p in paths]!r}:\n"
        "    try:\n"
        "        os.listdir(path) if os.path.isdir(path) else open(path).close()\n"
        "        readable.append(path)\n"
        "    except OSError:\n"
        "        pass\n"
        "import json\n"
        "print(json.dumps(readable))\n"
    )


_HELD_UIDS = {}  # uid -> the open lock file that reserves it for this process


def reserve_uid(preferred=None):
    """A sandbox uid that no other grading process on this machine uses now.

    The uids of :data:`grading.config.SANDBOX_UID_BASE` onwards are reserved
    with an exclusive ``flock`` on a lock file in a root-only folder, held
    until this process exits: two graders (two ``batch`` slots, two test
    workers, two instructors) never share a uid, so that killing what one
    left running never touches the other.
    """
    import fcntl

    if _HELD_UIDS:
        return next(iter(_HELD_UIDS))
    folder = Path(tempfile.gettempdir()) / "pcl-grading-uids"
    folder.mkdir(mode=0o700, exist_ok=True)
    if folder.stat().st_uid != os.geteuid() or stat.S_IMODE(folder.stat().st_mode) & 0o077:
        raise SandboxError(f"{folder} must belong to the grader's user with mode 0700")
    base, slots = config.SANDBOX_UID_BASE, config.SANDBOX_UID_SLOTS
    order = list(range(base, base + slots))
    if preferred is not None and preferred in order:
        order.remove(preferred)
        order.insert(0, preferred)
    for uid in order:
        handle = open(folder / f"{uid}.lock", "w")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        _HELD_UIDS[uid] = handle
        return uid
    raise SandboxError(f"all {slots} sandbox uids from {base} are in use by other graders")


def _bubblewrap_works(uid):
    """None if a bubblewrap worker starts here for ``uid``, else why not."""
    if not shutil.which("bwrap"):
        return "bubblewrap (bwrap) is not installed"
    staged = Path(tempfile.mkdtemp(prefix="grading-probe-"))
    try:
        os.chmod(staged, 0o711)
        (staged / "pcl_course").mkdir(mode=0o755)
        (staged / WORKER.name).write_text("import sys\n")  # the worker itself imports numpy
        (staged / WORKER.name).chmod(0o644)
        probe = _spawn(
            _bubblewrap_command(staged, []),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=_preexec(uid),
            env={},
        )
        _, stderr = probe.communicate(timeout=60)
        if probe.returncode == 0:
            return None
        return "bubblewrap cannot run here: " + (stderr.strip().splitlines() or ["?"])[-1]
    except (OSError, subprocess.SubprocessError) as exc:
        return f"bubblewrap cannot run here: {exc}"
    finally:
        shutil.rmtree(staged, ignore_errors=True)
        if uid is not None:
            kill_uid(uid)


def permission_wall(uid, protected):
    """None if ``uid`` can run Python here but read none of ``protected``, else why not.

    Run as ``uid`` itself: what it can read is measured, not inferred from
    mode bits.
    """
    try:
        completed = subprocess.run(
            [str(_python()[0]), "-I", "-S", "-c", _probe_script(protected)],
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=_preexec(uid),
            env={},
            cwd="/",
        )
    except (OSError, subprocess.SubprocessError) as exc:
        return f"uid {uid} cannot run Python: {exc}"
    finally:
        kill_uid(uid)
    if completed.returncode != 0:
        return f"uid {uid} cannot use the Python environment at {sys.prefix}"
    lines = [line for line in completed.stdout.splitlines() if line.startswith("[")]
    readable = json.loads(lines[-1]) if lines else ["?"]
    if readable:
        if readable[0] in {str(p) for p in masked_paths()}:
            return f"uid {uid} can still read the forbidden package {readable[0]}"
        return (
            f"uid {uid} can read {readable[0]}: make the course folder {REPO_ROOT} unreadable to others "
            f"(chmod 700) and keep the Python environment outside it"
        )
    return None


def network_wall(uid):
    """None if a worker running as ``uid`` can close its network (seccomp), else why not.

    Run as ``uid`` with the worker's own code (``--check-network``): the
    socket it then fails to open is measured, not assumed.
    """
    folder = tempfile.mkdtemp(prefix="grading-network-")  # the course's copy is out of the uid's reach
    os.chmod(folder, 0o755)
    os.chmod(shutil.copy(WORKER, folder), 0o644)
    try:
        completed = subprocess.run(
            [str(_python()[0]), "-I", "-S", f"{folder}/{WORKER.name}", "--check-network", str(_site_packages())],
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=_preexec(uid),
            env={"PATH": "/usr/bin:/bin"},
            cwd="/",
        )
        answer = json.loads(completed.stdout.strip().splitlines()[-1])
    except (OSError, subprocess.SubprocessError) as exc:
        return f"the network could not be closed: the check failed ({exc})"
    except (ValueError, IndexError):
        why = (completed.stderr.strip().splitlines() or ["no output"])[-1]
        return f"the network could not be closed: the check failed ({why})"
    finally:
        kill_uid(uid)
        shutil.rmtree(folder, ignore_errors=True)
    return None if answer.get("closed") else f"the network could not be closed: {answer.get('why')}"


@cache
def isolation(uid=None):
    """The strongest isolation available here for the sandbox ``uid``.

    Parameters
    ----------
    uid : int, optional
        The preferred dedicated uid when the grader is root (the one
        reserved is :func:`reserve_uid`'s); ignored otherwise.

    Returns
    -------
    Isolation
        ``bubblewrap`` if a worker starts in it (unless
        :data:`grading.config.SANDBOX_NAMESPACES` is off); else ``uid`` if
        the grader is root and the dedicated uid can read none of the
        course's :data:`PROTECTED` folders; else ``none``, with the reasons.
    """
    root = os.geteuid() == 0
    uid = reserve_uid(uid) if root else None
    _become_subreaper()  # the probe's orphans come back here to be reaped
    if root:
        _make_reachable(Path(sys.base_prefix) / "lib")
        _make_reachable(_site_packages())
    if config.SANDBOX_NAMESPACES:
        why_not = _bubblewrap_works(uid)
        if why_not is None:
            return Isolation(BUBBLEWRAP, uid)
    else:
        why_not = "namespaces switched off (PCL_SANDBOX_NAMESPACES=0)"
    if not root:
        return Isolation(NONE, None, f"{why_not}; the grader is not root, so no dedicated uid")
    # The second wall: a dedicated uid that can read neither the grader's files nor the forbidden packages.
    barred = bar_sandbox_uids(masked_paths())
    if barred is not None:
        return Isolation(NONE, None, f"{why_not}; {barred}")
    protected = [REPO_ROOT / name for name in PROTECTED if (REPO_ROOT / name).exists()]
    wall = permission_wall(uid, [*protected, *masked_paths()])
    if wall is not None:
        return Isolation(NONE, None, f"{why_not}; {wall}")
    network = network_wall(uid)
    if network is not None:
        return Isolation(NONE, None, f"{why_not}; {network}")
    return Isolation(UID, uid, why_not)


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
        self.work = None
        self.isolation = level if level is not None else isolation(uid)
        self.uid = self.isolation.uid
        self.broken = {}  # module -> why it cannot be imported
        self.last_modified = []
        self.known_pids = None  # the worker's processes at the last count (None: not counted yet)
        if self.uid is not None:
            remove_files_of(self.uid)  # what an earlier grader, killed, may have left

    # -- process management ---------------------------------------------------

    def _command(self):
        # Bubblewrap's empty network namespace is the wall (its sandbox has no ldconfig for
        # libseccomp anyway); without one the seccomp filter is, required as a dedicated uid.
        if self.isolation.level == BUBBLEWRAP:
            network = "namespace"
        else:
            network = "required" if self.uid is not None else "optional"
        tail = [",".join(config.FORBIDDEN_PACKAGES), network]
        if self.isolation.level == BUBBLEWRAP:
            return _bubblewrap_command(self.staged_root, tail), {}
        python = [
            str(_python()[0]),
            "-I",
            "-S",
            str(self.staged_root / WORKER.name),
            str(_site_packages()),
            str(self.staged_root),
            *tail,
        ]
        return python, _environment(self.work)

    def start(self):
        _become_subreaper()
        shutil.copy(WORKER, self.staged_root / WORKER.name)
        (self.staged_root / WORKER.name).chmod(0o644)
        if self.uid is not None:
            # Readable by this worker's uid (Python lists the folders it imports
            # from), by no other sandbox uid: a classmate's is out of reach.
            os.chown(self.staged_root, 0, self.uid)
            os.chmod(self.staged_root, 0o750)
        self.work = tempfile.mkdtemp(prefix="grading-home-")  # HOME of the uid and none levels
        if self.uid is not None:
            os.chown(self.work, self.uid, self.uid)
        command, env = self._command()
        self.known_pids = None  # a restarted worker's processes are new
        self.stderr = tempfile.TemporaryFile()
        self.process = _spawn(
            command,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            env=env,
            cwd=self.work,
            preexec_fn=_preexec(self.uid),
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
                _reap()
                if not self._leftovers():
                    break
                time.sleep(0.01)
        if self.work:
            shutil.rmtree(self.work, ignore_errors=True)
            self.work = None

    def close(self):
        """Stop the worker and remove every file its uid left anywhere writable."""
        self.stop()
        if self.uid is not None:
            remove_files_of(self.uid)

    def _leftovers(self):
        if self.uid is not None:
            return any(p[3] == self.uid for p in _processes())
        return False

    def _pids(self):
        """The worker's processes: those of its uid, else its process and descendants."""
        processes = _processes()
        if self.uid is not None:
            return [p[0] for p in processes if p[3] == self.uid]
        children = {}
        for pid, parent, _, _ in processes:
            children.setdefault(parent, []).append(pid)
        found, stack = [], [self.process.pid]
        while stack:
            pid = stack.pop()
            found.append(pid)
            stack.extend(children.get(pid, ()))
        return found

    def _tasks(self):
        """How many threads the worker runs, over all its processes (remembered for :meth:`cpu_seconds`)."""
        self.known_pids = self._pids()
        return sum(_stat(pid)[0] for pid in self.known_pids)

    def cpu_seconds(self, pids=None):
        """CPU seconds the worker's processes (``pids``, else all found now) have used so far,
        their reaped children included."""
        return sum(_stat(pid)[1] for pid in (self._pids() if pids is None else pids))

    def _stderr_tail(self):
        """The last lines the worker wrote to stderr; only the file's end is read."""
        size = self.stderr.seek(0, os.SEEK_END)
        self.stderr.seek(max(0, size - config.STDERR_TAIL_BYTES))
        text = self.stderr.read(config.STDERR_TAIL_BYTES).decode("utf-8", "replace").strip().splitlines()
        return "\n".join(line[:200] for line in text[-5:])

    # -- calls ------------------------------------------------------------------

    def call(self, module, function, args, kwargs):
        """Call ``pcl_course.<module>.<function>(*args, **kwargs)`` in the worker.

        The arguments here are never changed: the worker works on its own
        copies. Returns the answer; :attr:`last_modified` then holds the
        paths of the arguments the call modified in place (``["args", 0]``
        is the first positional one, ``["kwargs", "name"]`` a keyword one).
        A random generator among the arguments draws on from where the call
        left it.
        """
        self.last_modified = []
        if module in self.broken:
            raise SandboxError(self.broken[module], kind=IMPORT)
        if self.process is None or self.process.poll() is not None:
            self.stop()
            self.start()
        try:
            result = self._call(module, function, args, kwargs)
        except BaseException as exc:
            from_submission = getattr(exc, "from_submission", False)
            stray = self._stray_tasks() if self.process is not None else False
            if not from_submission or stray:
                self.stop()  # a timed-out, broken or forking worker never serves another call
            if from_submission and stray:
                raise SandboxError(STRAY_MESSAGE, kind=STRAY) from None
            raise
        if self._stray_tasks():
            self.stop()
            raise SandboxError(STRAY_MESSAGE, kind=STRAY)
        return result

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
        read_only = [path for path, value in _arrays(arguments, []) if not value.flags.writeable]
        request = pickle.dumps(
            {"module": module, "function": function, "args": args, "kwargs": kwargs, "read_only": read_only}
        )
        deadline = _Deadline(self, self.timeout)
        try:
            self.process.stdin.write(struct.pack("<Q", len(request)) + request)
            self.process.stdin.flush()
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
        self.last_modified = _modified_paths(arguments, answer.get("modified", []))
        if answer.get("ok") is not True:
            if not isinstance(answer.get("type"), str):
                raise SandboxError("the worker's answer was garbled", kind=GARBLED)
            exc = _exception(answer)
            exc.from_submission = True  # the function raised: the worker itself is fine
            exc.modified = self.last_modified
            raise exc
        return _decode(answer.get("value"), arrays)

    # -- reading the worker's frames, every size checked before it is read ---------

    def _wait_readable(self, deadline):
        stream = self.process.stdout.fileno()
        while True:
            remaining = deadline.wall - time.monotonic()
            if remaining <= 0:
                raise SandboxError(
                    f"timed out: the call waited for more than {deadline.wall_seconds:g} s (wall clock)", kind=TIMEOUT
                )
            ready, _, _ = select.select([stream], [], [], min(remaining, CPU_POLL_SECONDS))
            if ready:
                return stream
            if self.cpu_seconds() - deadline.cpu_start > deadline.cpu_seconds:
                raise SandboxError(
                    f"timed out: the call used more than {deadline.cpu_seconds:g} s of CPU time", kind=TIMEOUT
                )

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

    def _frame_size(self, deadline, limit):
        head = self._read_exactly(12, deadline)
        size = struct.unpack("<Q", head[4:])[0]
        if bytes(head[:4]) != MAGIC:
            raise SandboxError("the worker's answer was garbled", kind=GARBLED)
        if size > limit:
            raise SandboxError(_too_large(size, limit), kind=TOO_LARGE)
        return size

    def _read_header(self, deadline):
        size = self._frame_size(deadline, config.HEADER_LIMIT)
        try:
            header = json.loads(self._read_exactly(size, deadline).decode("utf-8"))
        except (ValueError, RecursionError):
            raise SandboxError("the worker's answer was garbled", kind=GARBLED) from None
        if not isinstance(header, dict):
            raise SandboxError("the worker's answer was garbled", kind=GARBLED)
        return header

    def _read_arrays(self, declared, deadline):
        """The arrays the answer's header declares: numeric dtypes only, all sizes checked first."""
        if not isinstance(declared, list) or len(declared) > config.MAX_ARRAYS:
            raise SandboxError("the worker's answer was garbled (too many arrays)", kind=GARBLED)
        layouts = [_layout(entry) for entry in declared]
        total = sum(dtype.itemsize * int(np.prod(shape, dtype=object)) for dtype, shape in layouts)
        if total > config.ANSWER_LIMIT:
            raise SandboxError(_too_large(total, config.ANSWER_LIMIT), kind=TOO_LARGE)
        arrays = []
        for dtype, shape in layouts:
            nbytes = dtype.itemsize * int(np.prod(shape, dtype=object))
            if self._frame_size(deadline, nbytes) != nbytes:
                raise SandboxError("the worker's answer was garbled", kind=GARBLED)
            data = self._read_exactly(nbytes, deadline)
            arrays.append(np.frombuffer(data, dtype=dtype).reshape(shape))
        return arrays

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


@dataclass
class _Deadline:
    """A call's limits: CPU seconds of the worker from now, and a wall-clock backstop."""

    worker: Worker
    cpu_seconds: float

    def __post_init__(self):
        # Between calls the worker runs exactly the processes counted after the last one (any more
        # would have stopped it): no need to walk /proc again here, the hot path of every call.
        self.cpu_start = self.worker.cpu_seconds(self.worker.known_pids)
        self.wall_seconds = self.cpu_seconds * config.CALL_WALL_FACTOR
        self.wall = time.monotonic() + self.wall_seconds


_CLOCK_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _stat(pid):
    """(threads, CPU seconds with reaped children) of a process, from /proc/PID/stat; (0, 0) once it is gone."""
    try:
        handle = os.open(f"/proc/{pid}/stat", os.O_RDONLY)
        try:
            text = os.read(handle, 4096)
        finally:
            os.close(handle)
    except OSError:
        return 0, 0.0
    fields = text[text.rfind(b")") + 2 :].split()  # after the name, which may hold spaces
    # fields[0] is field 3 (state): utime, stime, cutime, cstime are fields 14-17, num_threads 20
    return int(fields[17]), sum(int(v) for v in fields[11:15]) / _CLOCK_TICKS


def _too_large(size, limit):
    return f"the answer is too large ({size / 2**20:.2f} MiB, at most {limit / 2**20:.2f} MiB)"


_NUMERIC_DTYPE = re.compile(r"^[<>|=]?[biufc][1-9][0-9]?$")


def _numeric_dtype(text):
    """A plain numeric dtype from its ``dtype.str`` (no object, void, structured or string dtype), else None."""
    if not isinstance(text, str) or not _NUMERIC_DTYPE.match(text):
        return None
    try:
        dtype = np.dtype(text)
    except TypeError:
        return None
    return dtype if dtype.kind in "biufc" and dtype.itemsize <= 16 else None


def _layout(entry):
    """(dtype, shape) of a declared array, checked: a numeric dtype and at most 32 non-negative extents."""
    if isinstance(entry, dict):
        dtype, shape = _numeric_dtype(entry.get("dtype")), entry.get("shape")
        if (
            dtype is not None
            and isinstance(shape, list)
            and len(shape) <= 32
            and all(type(n) is int and 0 <= n < 2**62 for n in shape)
        ):
            return dtype, tuple(shape)
        if dtype is None and isinstance(entry.get("dtype"), str):
            raise SandboxError(
                "returned an array of a dtype that is not numeric: return numeric numpy arrays", kind=UNSUPPORTED
            )
    raise SandboxError("the worker's answer was garbled", kind=GARBLED)


def _arrays(value, path):
    """(path, array) of every ndarray inside nested tuples, lists and dicts."""
    if type(value) is np.ndarray:
        yield path, value
    elif type(value) in (tuple, list):
        for i, item in enumerate(value):
            yield from _arrays(item, [*path, i])
    elif type(value) is dict:
        for key, item in value.items():
            yield from _arrays(item, [*path, key])


def _modified_paths(arguments, modified):
    """The paths of the arguments the call modified, as the worker names them; a random
    generator takes the new state the worker sent (checked: one its own stream reaches)."""
    if not isinstance(modified, list) or len(modified) > config.MAX_ARRAYS:
        raise SandboxError("the worker's answer was garbled", kind=GARBLED)
    paths = []
    for change in modified:
        try:
            target = arguments
            for step in change["path"]:
                target = target[step]
        except (KeyError, IndexError, TypeError):
            raise SandboxError("the worker's answer was garbled", kind=GARBLED) from None
        if isinstance(target, np.random.Generator):
            set_generator_state(target, change.get("state"))
        elif type(target) is not np.ndarray:
            raise SandboxError("the worker's answer was garbled", kind=GARBLED)
        paths.append(list(change["path"]))
    return paths


def set_generator_state(generator, state):
    """Give ``generator`` a state the worker sent back, if its own stream could reach it.

    PCG64's state is a position on one stream (``inc``): any 128-bit
    position on the same stream is one the generator reaches by drawing,
    any other (another ``inc``, another bit generator, a malformed state)
    is refused, so that no submission hands the grader a stream of its
    choosing.
    """
    current = generator.bit_generator.state
    ok = (
        isinstance(state, dict)
        and set(state) == set(current)
        and state.get("bit_generator") == current["bit_generator"] in ("PCG64", "PCG64DXSM")
        and isinstance(state.get("state"), dict)
        and set(state["state"]) == {"state", "inc"}
        and state["state"]["inc"] == current["state"]["inc"]
        and type(state["state"]["state"]) is int
        and 0 <= state["state"]["state"] < 2**128
        and state.get("has_uint32") in (0, 1)
        and type(state.get("uinteger")) is int
        and 0 <= state["uinteger"] < 2**32
    )
    if not ok:
        raise SandboxError(
            "the random generator came back in a state its own stream cannot reach: draw from it, never set it",
            kind=GENERATOR,
        )
    generator.bit_generator.state = state


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
        return exc
    return SandboxError(f"raised {kind}: {message}{shown}", kind=RAISED)


def _decode(node, arrays):
    if not isinstance(node, dict):
        raise SandboxError("the worker's answer was garbled", kind=GARBLED)
    kind = node.get("t")
    try:
        if kind == "ndarray":
            if type(node["k"]) is int and 0 <= node["k"] < len(arrays):
                return arrays[node["k"]]
        elif kind == "json":
            value = node["v"]
            if value is None or type(value) in (bool, int, float, str):
                return value
        elif kind == "npscalar":
            dtype = _numeric_dtype(node["dtype"])
            if dtype is not None:
                return dtype.type(node["v"])
        elif kind in ("tuple", "list"):
            items = [_decode(item, arrays) for item in node["items"]]
            return tuple(items) if kind == "tuple" else items
        elif kind == "dict":
            return {str(key): _decode(value, arrays) for key, value in node["items"].items()}
        elif kind == "unsupported":
            raise SandboxError(
                f"returned {str(node.get('what'))[:200]}: return plain numpy arrays, numbers, strings, tuples, "
                "lists or dicts",
                kind=UNSUPPORTED,
            )
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError, RecursionError):
        pass
    raise SandboxError("the worker's answer was garbled", kind=GARBLED)
