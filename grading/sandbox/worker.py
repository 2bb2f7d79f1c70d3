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

Usage: python -I -S worker.py SITE_PACKAGES SUBMISSION_DIR FORBIDDEN_PACKAGES NETWORK EXCHANGE_FD
(FORBIDDEN_PACKAGES comma-separated dotted names, from grading.config; NETWORK is
``required`` or ``optional``: whether the worker may run when the filter
cannot be installed, or ``namespace``: no filter, bubblewrap's network
namespace is the wall), or python -I -S worker.py --check-network SITE_PACKAGES.
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


def close_network():
    """Install a seccomp filter that fails every ``socket()`` (any address
    family; ``socketpair()`` stays) and ``io_uring_setup()`` (io_uring can
    open sockets) with ``EACCES``, for this process and all it starts; and
    ``shmget``, ``msgget`` and ``semget`` (SysV IPC objects outlive their
    processes; POSIX shared memory is a file in ``/dev/shm``, counted and
    removed like the others); and every new process: ``execve``,
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

        deny = seccomp.SyscallFilter(seccomp.ALLOW)
        # SysV IPC objects outlive every process that made them (and, as a uid's, reach the next
        # submission): refused too. Bubblewrap's IPC namespace dies with the sandbox instead.
        for call in ("socket", "io_uring_setup", "shmget", "msgget", "semget", "execve", "execveat", "fork", "vfork"):
            deny.add_rule(seccomp.ERRNO(errno.EACCES), call)
        deny.add_rule(seccomp.ERRNO(errno.EACCES), "clone", seccomp.Arg(0, seccomp.MASKED_EQ, CLONE_THREAD, 0))
        deny.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")  # its flags are in memory: no rule can read them
        deny.load()  # sets no_new_privs first
    except Exception as exc:  # no libseccomp, or a kernel or container that refuses filters
        return f"no seccomp filter ({type(exc).__name__}: {exc})"
    return None


def _check_network(site_packages):
    """Measure, do not infer: after :func:`close_network`, a socket and a new process must be
    refused, and a thread must still start."""
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
    print(json.dumps({"closed": why_not is None, "why": why_not}))


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
    sender.send(answer, arrays)


def main():
    if sys.argv[1] == "--check-network":
        return _check_network(sys.argv[2])
    site_packages, submission, forbidden, network = sys.argv[1], sys.argv[2], sys.argv[3].split(","), sys.argv[4]
    exchange = int(sys.argv[5]) if len(sys.argv) > 5 else None
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
    sys.meta_path.insert(0, _ForbiddenImports(forbidden))
    sys.path.insert(0, submission)
    import numpy as np

    sender.send({"ready": True})
    while (request := wire.read_request(requests)) is not None:
        _call(request, wire, sender, np, exchange)


if __name__ == "__main__":
    main()
