"""The worker process that runs a submission's code (started by :mod:`grading.sandbox.client`).

It is a standalone script: it imports nothing from the grader but its wire
protocol (``protocol.py`` beside it, loaded by path; the format is stated
there), and in the bubblewrap sandbox these two are the only files of the
grader's that exist. It reads call requests from the grader, imports the
submission's module, runs the function and answers on a private copy of
the original stdout. Whatever the submission prints goes to stderr.

Each call is answered in two steps, so that the grader can tell a module
that cannot be imported from a function that fails: first
``{"imported": true}`` (or the import's failure), then the call's answer.
Every array argument lives, for the call, in memory the grader shares
(``EXCHANGE_FD``, a memfd the grader made): the worker copies it there and
hands the function that copy, so a change the function makes in place is
seen by the grader itself, not reported by this process, which the
submission could rewrite. A random generator's new state is sent back, so
that a later call draws on from it.

Outside bubblewrap, before it imports anything of the submission's, the
worker closes the network with a seccomp filter (:func:`close_network`):
every ``socket()`` and ``io_uring_setup()`` fails with ``EACCES``, and so
does every new process (threads stay). As a
dedicated uid without namespaces (a Docker container) the filter is the
wall, and the worker refuses to run without it; under bubblewrap the empty
network namespace is.

As a dedicated uid it also confines its files with Landlock
(:func:`restrict_files`), where the kernel has it: it reads the interpreter,
the environment, the system's libraries and the staged submission, and writes
its home only, whatever else of the machine is world-readable.

Usage: python -I -S worker.py SITE_PACKAGES SUBMISSION_DIR FORBIDDEN_PACKAGES NETWORK EXCHANGE_FD FILES
(FORBIDDEN_PACKAGES comma-separated dotted names, from grading.config; NETWORK is
``required`` or ``optional``: whether the worker may run when the filter
cannot be installed, or ``namespace``: no filter, bubblewrap's network
namespace is the wall; FILES is ``landlock``, required, or ``open``), or
python -I -S worker.py --check-network SITE_PACKAGES CANARY.
"""

import errno
import importlib
import json
import os
import sys
import traceback


class _ForbiddenImports:
    """A meta path finder that refuses the packages the homework forbids (dotted names:
    ``sklearn``, ``scipy.spatial``, and everything under them). It names the rule early;
    the grader's reading of the mapped files is the wall."""

    def __init__(self, packages):
        self.packages = tuple(packages)

    def find_spec(self, name, path=None, target=None):
        if any(name == banned or name.startswith(banned + ".") for banned in self.packages):
            raise ImportError(
                f"{name} is not available to submissions: write your own code (the course forbids it in this module)"
            )
        return None


CLONE_THREAD = 0x00010000  # <linux/sched.h>: a clone that makes a thread, not a process
SOCK_STREAM, SOCK_SEQPACKET = 1, 5  # <linux/net.h>: the socket pairs that cannot address anything else
# Every call the filter fails with EACCES. Sockets (io_uring can open them); kernel objects that
# outlive their processes, out of reach of the grader's cleanup of a uid's files and processes
# (SysV IPC; a uid's keyrings, which the next submission run as that uid would find); watches
# that report other users' file activity (inotify, fanotify); naming or reaching a socket by a
# path (bind, connect, listen on a socket pair); and every new process.
_DENIED_CALLS = (
    "socket",
    "shmget",
    "msgget",
    "semget",
    "add_key",
    "request_key",
    "keyctl",
    "inotify_init",
    "inotify_init1",
    "fanotify_init",
    "bind",
    "connect",
    "listen",
    "execve",
    "execveat",
    "fork",
    "vfork",
)


# Denied in every mode, bubblewrap too (the grader compiles them for bwrap's --seccomp:
# grading.sandbox.bubblewrap.seccomp_program), each with its errno: what would put storage out of
# the limits' sight. A descriptor passed through a socket pair (SCM_RIGHTS) and closed by its sender
# is in no folder and in no process's table: a memfd or a deleted file held so (5 GiB of RAM,
# 8 GiB of disk) was counted nowhere; io_uring's registered files are the same. POSIX message
# queues outlive every process of the uid, out of reach of its cleanup (a channel from one
# submission to the next). fallocate takes GiBs in milliseconds, between two readings of the disk;
# refused with EOPNOTSUPP, glibc's posix_fallocate writes the blocks itself, at the speed of writing.
DENIED_EVERYWHERE = {
    "sendmsg": errno.EACCES,
    "sendmmsg": errno.EACCES,
    "recvmsg": errno.EACCES,
    "recvmmsg": errno.EACCES,
    "io_uring_setup": errno.EACCES,
    "mq_open": errno.EACCES,
    "mq_unlink": errno.EACCES,
    "mq_timedsend": errno.EACCES,
    "mq_timedreceive": errno.EACCES,
    "mq_notify": errno.EACCES,
    "mq_getsetattr": errno.EACCES,
    "fallocate": errno.EOPNOTSUPP,
    # h77: memory no reading sees. A secret memfd shows no block; pages pinned in a pipe by vmsplice
    # (a huge page kept whole for each byte spliced: 954 MiB held, Pss 29 MB), splice and tee alike;
    # a descriptor table of a thread's own (unshare, or a thread cloned without CLONE_FILES: below),
    # which /proc/PID/fd does not show.
    "memfd_secret": errno.EACCES,
    "vmsplice": errno.EACCES,
    "splice": errno.EACCES,
    "tee": errno.EACCES,
    "unshare": errno.EACCES,
}
CLONE_FILES = 0x00000400  # <linux/sched.h>: the thread shares its parent's descriptor table
SOL_SOCKET, SOCKET_BUFFER_OPTIONS = 1, (7, 8, 32, 33)  # SO_SNDBUF, SO_RCVBUF and their FORCE forms


def syscall_filter(seccomp, network=True):
    """A libseccomp filter (``seccomp``: the pyseccomp module) of :data:`DENIED_EVERYWHERE` and,
    with ``network``, of the network and new processes (:func:`close_network`)."""
    deny = seccomp.SyscallFilter(seccomp.ALLOW)
    for call, code in DENIED_EVERYWHERE.items():
        deny.add_rule(seccomp.ERRNO(code), call)
    # A thread with a descriptor table of its own; clone3's flags are in memory, where no rule can read
    # them: ENOSYS, and glibc falls back to clone.
    thread_alone = seccomp.Arg(0, seccomp.MASKED_EQ, CLONE_THREAD | CLONE_FILES, CLONE_THREAD)
    deny.add_rule(seccomp.ERRNO(errno.EACCES), "clone", thread_alone)
    deny.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    # A socket pair's buffers grown to 8 MiB each held 1 GiB in 66 pairs, counted by no reading.
    for option in SOCKET_BUFFER_OPTIONS:
        buffer = (seccomp.Arg(1, seccomp.EQ, SOL_SOCKET), seccomp.Arg(2, seccomp.EQ, option))
        deny.add_rule(seccomp.ERRNO(errno.EACCES), "setsockopt", *buffer)
    if network:
        for call in _DENIED_CALLS:
            deny.add_rule(seccomp.ERRNO(errno.EACCES), call)
        for kind in range(16):  # socketpair's type, its flags masked off: a stream or a sequenced pair only
            if kind not in (SOCK_STREAM, SOCK_SEQPACKET):
                deny.add_rule(seccomp.ERRNO(errno.EACCES), "socketpair", seccomp.Arg(1, seccomp.MASKED_EQ, 0xF, kind))
        deny.add_rule(seccomp.ERRNO(errno.EACCES), "clone", seccomp.Arg(0, seccomp.MASKED_EQ, CLONE_THREAD, 0))
    return deny


def close_network():
    """Install a seccomp filter that fails every ``socket()`` (any address
    family; ``socketpair()`` of a stream or a sequenced-packet pair stays,
    which can reach no other socket) and ``io_uring_setup()`` (io_uring can
    open sockets) with ``EACCES``, for this process and all it starts, with
    every call of :data:`DENIED_EVERYWHERE` (``sendmsg``: no descriptor
    passed through a socket pair; POSIX message queues; ``fallocate``); and
    ``bind``, ``connect``, ``listen`` (a datagram pair could otherwise send
    to any socket named by a path); ``shmget``, ``msgget`` and ``semget``
    (SysV IPC objects outlive their processes) and ``add_key``,
    ``request_key``, ``keyctl`` (a uid's keyrings outlive them too); the
    watches ``inotify_init``, ``inotify_init1`` and ``fanotify_init``, which
    report other users' file activity; and every new process: ``execve``,
    ``execveat``, ``fork``, ``vfork`` and a ``clone`` without
    ``CLONE_THREAD`` (threads stay), ``clone3`` with ``ENOSYS`` (glibc then
    falls back to ``clone``). A process of the submission's own would run
    outside this worker's checks (its imports, the native code it maps),
    with another Python of the machine's, say, and exit before the call
    ends.

    Syscalls of another ABI (32-bit ``int 0x80``) kill the process
    (libseccomp's default for a foreign architecture).

    Returns
    -------
    str or None
        None when the filter is in place; else why not.
    """
    try:
        import pyseccomp as seccomp  # libseccomp's Python API, over ctypes

        syscall_filter(seccomp).load()  # sets no_new_privs first
    except Exception as exc:  # no libseccomp, or a kernel or container that refuses filters
        return f"no seccomp filter ({type(exc).__name__}: {exc})"
    return None


# Landlock (<linux/landlock.h>): the same syscall numbers on every architecture.
_CREATE_RULESET, _ADD_RULE, _RESTRICT_SELF = 444, 445, 446
_RULESET_VERSION, _RULE_PATH_BENEATH = 1, 1
_EXECUTE, _WRITE_FILE, _READ_FILE, _READ_DIR = 1, 2, 4, 8
_TRUNCATE, _IOCTL_DEV = 1 << 14, 1 << 15
_FILE_RIGHTS = _EXECUTE | _WRITE_FILE | _READ_FILE | _TRUNCATE | _IOCTL_DEV  # the rights a file's rule can hold
_READ = _EXECUTE | _READ_FILE | _READ_DIR

# The loader's folders and cache (bubblewrap binds the same: grading.sandbox.bubblewrap).
SYSTEM_LIBRARIES = ("/usr/lib", "/usr/lib64", "/usr/lib32", "/etc/ld.so.cache")
# Read: the machine's CPUs and memory (sysconf, OpenBLAS, libraries that size their work), the
# time zone, and the worker's own /proc/<pid> entries that a process reads of itself (glibc reads
# maps), not the rest (its net/ and mountinfo describe the host). Written: /dev/null only; not
# /dev/shm, shared by every slot graded at once (no process can be started to share a semaphore).
_DEVICES_READ = (
    "/sys/devices/system/cpu",
    "/proc/cpuinfo",
    "/proc/meminfo",
    *(f"/proc/self/{entry}" for entry in ("maps", "stat", "statm", "status", "fd", "task", "cgroup")),
    "/etc/localtime",
    "/usr/share/zoneinfo",
    "/dev/urandom",
    "/dev/zero",
)
_DEVICES_WRITTEN = ("/dev/null",)


def _handled_rights(abi):
    """Every filesystem right this kernel's Landlock ABI knows (all of them are then denied
    unless a rule grants them)."""
    rights = (1 << 13) - 1  # ABI 1: execute .. make_sym
    if abi >= 2:
        rights |= 1 << 13  # refer (links and renames across folders)
    if abi >= 3:
        rights |= _TRUNCATE
    if abi >= 5:
        rights |= _IOCTL_DEV
    return rights


def restrict_files(readable, writable):
    """Confine this process and all it starts with Landlock: ``readable`` paths (and what lies
    below them) can be read and run, ``writable`` ones written too, nothing else of the machine
    can be touched, whatever its mode bits; and, where the kernel knows them, no TCP, no
    abstract unix socket and no signal outside the sandbox.

    Unprivileged and without namespaces: what the uid mode (a container that forbids namespaces)
    lacked, where a submission could read any world-readable file (another copy of the course,
    say). Needs ``no_new_privs``, which :func:`close_network` sets. Paths that do not exist are
    skipped. Returns None when in place; else why not (an old kernel, a container that refuses
    the calls).
    """
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long

    def call(*args):
        result = libc.syscall(*(ctypes.c_long(a) if isinstance(a, int) else a for a in args))
        if result < 0:
            raise OSError(ctypes.get_errno(), os.strerror(ctypes.get_errno()))
        return result

    class Ruleset(ctypes.Structure):
        _fields_ = [("fs", ctypes.c_uint64), ("net", ctypes.c_uint64), ("scoped", ctypes.c_uint64)]

    class PathBeneath(ctypes.Structure):
        _pack_ = 1
        _fields_ = [("allowed", ctypes.c_uint64), ("fd", ctypes.c_int32)]

    try:
        abi = call(_CREATE_RULESET, None, 0, _RULESET_VERSION)
        handled = _handled_rights(abi)
        attributes = Ruleset(handled, 3 if abi >= 4 else 0, 3 if abi >= 6 else 0)  # TCP bind, connect; scopes
        ruleset = call(_CREATE_RULESET, ctypes.byref(attributes), ctypes.sizeof(attributes), 0)
        try:
            grants = [(path, _READ) for path in readable] + [(path, handled) for path in writable]
            for path, rights in grants:
                try:
                    fd = os.open(path, os.O_PATH | os.O_CLOEXEC)
                except OSError:
                    continue  # not on this machine
                try:
                    if not os.path.isdir(path):
                        rights &= _FILE_RIGHTS
                    rule = PathBeneath(rights & handled, fd)
                    call(_ADD_RULE, ruleset, _RULE_PATH_BENEATH, ctypes.byref(rule), 0)
                finally:
                    os.close(fd)
            call(_RESTRICT_SELF, ruleset, 0)
        finally:
            os.close(ruleset)
    except OSError as exc:
        return f"no Landlock ({exc.strerror or exc})"
    return None


def landlocked_paths(site_packages, submission, home):
    """(readable, writable) for :func:`restrict_files`: the interpreter's libraries, the
    environment's site-packages, the system's libraries, the staged submission (with this
    script) and the worker's home."""
    base = os.path.realpath(os.path.join(sys.base_prefix, "lib"))
    readable = [base, os.path.realpath(site_packages), *SYSTEM_LIBRARIES, *_DEVICES_READ, submission]
    return readable, [home, *_DEVICES_WRITTEN]


def _check_network(site_packages, canary):
    """Measure, do not infer: after :func:`close_network`, a socket and a new process must be
    refused, and a thread must still start; then, under :func:`restrict_files`, ``canary`` (a
    world-readable file outside the paths it grants) must be unreadable and the environment's
    site-packages readable. Prints ``closed`` (the network), ``why`` and ``files`` (None: the
    files are confined; else why not)."""
    import socket
    import subprocess
    import threading

    sys.path.append(site_packages)
    why_not = close_network()
    if why_not is None:
        try:
            socket.socket(socket.AF_INET, socket.SOCK_STREAM).close()
            why_not = "a socket could still be opened under the seccomp filter"
        except PermissionError:
            pass
    if why_not is None:
        try:
            subprocess.run([sys.executable, "-c", "pass"], check=False)
            why_not = "a program could still be started under the seccomp filter"
        except PermissionError:
            pass
    if why_not is None:
        try:
            if os.fork() == 0:
                os._exit(0)
            why_not = "a process could still be forked under the seccomp filter"
        except PermissionError:
            pass
    if why_not is None:
        thread = threading.Thread(target=lambda: None)
        try:
            thread.start()
            thread.join()
        except RuntimeError as exc:
            why_not = f"a thread could not start under the seccomp filter ({exc})"
    here = os.path.dirname(os.path.abspath(__file__))
    files = restrict_files(*landlocked_paths(site_packages, here, here)) if why_not is None else "not tried"
    if files is None:
        try:
            open(canary).close()
            files = f"{canary} could still be read under Landlock"
        except PermissionError:
            pass
    if files is None:
        try:
            os.listdir(site_packages)
            import decimal  # noqa: F401 -- a module of the standard library, with its C part, still loads
        except OSError as exc:
            files = f"the environment could not be read under Landlock ({exc})"
    print(json.dumps({"closed": why_not is None, "why": why_not, "files": files}))


def _generators(value, path, np):
    """(path, generator) of every random generator inside the arguments."""
    if isinstance(value, np.random.Generator):
        yield path, value
    elif type(value) in (tuple, list):
        for i, item in enumerate(value):
            yield from _generators(item, [*path, i], np)
    elif type(value) is dict:
        for key, item in value.items():
            yield from _generators(item, [*path, key], np)


def _substituted(value, path, new):
    """``value`` with the item at ``path`` replaced by ``new`` (tuples rebuilt, lists and dicts
    changed in place)."""
    if not path:
        return new
    head, rest = path[0], path[1:]
    if type(value) is tuple:
        return tuple(_substituted(item, rest, new) if i == head else item for i, item in enumerate(value))
    value[head] = _substituted(value[head], rest, new)
    return value


def _shared(arguments, request, exchange, np):
    """``arguments`` with every array the grader placed in the shared memory replaced by its
    copy there (read-only flags kept): what the function changes, the grader sees."""
    import mmap

    size = request.get("exchange_size", 0)
    if not size or exchange is None:
        return arguments
    memory = mmap.mmap(exchange, size)
    for path, offset in request["exchange"]:
        value = arguments
        for step in path:
            value = value[step]
        copy = np.ndarray(value.shape, value.dtype, buffer=memory, offset=offset)
        copy[...] = value
        copy.flags.writeable = value.flags.writeable
        arguments = _substituted(arguments, path, copy)
    return arguments


def _shape_of(value, path, np, out, kept):
    """What a call may change of its arguments besides their arrays' bytes (which the grader reads
    in the shared memory itself): each list's and dict's items (an array by identity, anything
    else by type and value) and each array's shape, dtype and strides (a writeable flag set
    changes no value). ``out``: path -> record; ``kept``: every array seen, held so that no
    new array can take a replaced one's identity."""
    if type(value) in (list, dict):
        items = list(value.items()) if type(value) is dict else list(enumerate(value))
        out[tuple(path)] = [
            (key, id(item) if isinstance(item, np.ndarray) else (type(item), _plain(item))) for key, item in items
        ]
        for key, item in items:
            _shape_of(item, [*path, key], np, out, kept)
    elif type(value) is tuple:
        for i, item in enumerate(value):
            _shape_of(item, [*path, i], np, out, kept)
    elif isinstance(value, np.ndarray):
        kept.append(value)
        out[tuple(path)] = (value.shape, value.dtype.str, value.strides)


def _plain(item):
    """A value to compare an item by (its repr: a NaN equals itself, -0.0 differs from 0.0), or its
    identity where comparing could run its code."""
    return repr(item) if type(item) in (bool, int, float, str, type(None)) else id(item)


def _reshaped(before, after):
    """The paths (lists) whose record changed between two :func:`_shape_of` readings."""
    return [list(path) for path, record in before.items() if after.get(path) != record]


def _failure(exc):
    frames = traceback.extract_tb(exc.__traceback__)
    own = [f for f in frames if "pcl_course" in f.filename]
    return {
        "ok": False,
        "type": type(exc).__name__,
        "builtin": type(exc).__module__ == "builtins",
        "message": str(exc)[:2000],
        "where": f"{os.path.basename(own[-1].filename)}:{own[-1].lineno} in {own[-1].name}" if own else "",
        # raised by a statement of the submission's own package (a check of its own), not inside a library
        "own": bool(frames) and "pcl_course" in frames[-1].filename,
    }


def _load_protocol():
    """The wire protocol, from ``protocol.py`` beside this script (the sandbox has no ``grading``)."""
    import importlib.util

    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "protocol.py")
    spec = importlib.util.spec_from_file_location("_pcl_grading_protocol", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _call(request, wire, sender, np, exchange=None):
    try:
        module = importlib.import_module(f"pcl_course.{request['module']}")
    except BaseException as exc:  # noqa: B902 -- SystemExit at import is an answer too
        sender.send({**_failure(exc), "phase": "import"})
        return
    sender.send({"imported": True})
    arguments = {"args": list(request["args"]), "kwargs": dict(request["kwargs"])}
    for path in request.get("read_only", ()):
        array = arguments
        for step in path:
            array = array[step]
        array.flags.writeable = False
    arguments = _shared(arguments, request, exchange, np)
    watched = [(path, value, value.bit_generator.state) for path, value in _generators(arguments, [], np)]
    layout, kept = {}, []
    _shape_of(arguments, [], np, layout, kept)
    try:
        function = getattr(module, request["function"], None)
        if function is None:
            raise AttributeError(f"{request['module']}.py defines no function {request['function']}")
        result = function(*arguments["args"], **arguments["kwargs"])
        arrays = []
        answer = {"ok": True, "value": wire.encode(result, arrays)}
    except BaseException as exc:  # noqa: B902 -- KeyboardInterrupt and SystemExit are answers too
        arrays, answer = [], _failure(exc)
    modified = []
    for path, value, before in watched:
        if value.bit_generator.state != before:
            modified.append({"path": path, "state": value.bit_generator.state})
    answer["modified"] = modified  # the generators; the grader reads the arrays it shared itself
    after = {}
    _shape_of(arguments, [], np, after, kept)
    answer["reshaped"] = _reshaped(layout, after)  # lists, dicts and arrays' layouts: the worker's word
    sender.send(answer, arrays)


def main():
    if sys.argv[1] == "--check-network":
        return _check_network(sys.argv[2], sys.argv[3])
    site_packages, submission, forbidden, network = sys.argv[1], sys.argv[2], sys.argv[3].split(","), sys.argv[4]
    exchange = int(sys.argv[5]) if len(sys.argv) > 5 else None
    files = sys.argv[6] if len(sys.argv) > 6 else "open"
    answers = os.fdopen(os.dup(1), "wb", buffering=0)
    os.dup2(2, 1)  # the submission's prints go to stderr, not into the protocol
    sys.stdout = sys.stderr
    requests = sys.stdin.buffer
    sys.path[:] = [p for p in sys.path if p and os.path.isdir(p)] + [site_packages]
    wire = _load_protocol()  # imports numpy, from the environment's site-packages
    sender = wire.Sender(answers)
    # Before the forbidden-import finder: pyseccomp is the grader's. Under bubblewrap the
    # network namespace is the wall already.
    why_not = close_network() if network != "namespace" else None
    if why_not is not None and network == "required":
        sender.send({"ready": False, "error": f"the network could not be closed: {why_not}"})
        return
    if files == "landlock":  # the grader measured that Landlock works here: required
        home = os.environ.get("HOME") or os.getcwd()
        why_not = restrict_files(*landlocked_paths(site_packages, os.path.dirname(os.path.abspath(__file__)), home))
        if why_not is not None:
            sender.send({"ready": False, "error": f"the files could not be confined: {why_not}"})
            return
    sys.meta_path.insert(0, _ForbiddenImports(forbidden))
    sys.path.insert(0, submission)
    import numpy as np

    sender.send({"ready": True})
    while (request := wire.read_request(requests)) is not None:
        _call(request, wire, sender, np, exchange)


if __name__ == "__main__":
    main()
