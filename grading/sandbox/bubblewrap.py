"""The bubblewrap command that runs a worker: its binds, masks and environment.

The sandbox's filesystem is built from nothing: read-only binds of the
interpreter (``sys.base_prefix``), the system libraries and the
environment's site-packages, with every forbidden package and every
editable-install file masked (:func:`masked_paths`, also what the uid level
bars with ACLs); the staged submission, the worker script and its wire
protocol; a size-capped tmpfs for ``/tmp`` (also ``HOME``) and a smaller one for
``/dev/shm``, the only writable places (the masks and ``/dev`` itself are
read-only); its own ``/proc`` and a minimal ``/dev``. No repository,
``.git``, tests, solutions, ``grading/`` or other submission exists there.
The worker runs under the seccomp filter of the calls denied in every mode
(:data:`grading.sandbox.worker.DENIED_EVERYWHERE`), compiled here and
handed to ``bwrap --seccomp`` (:func:`seccomp_program`).
"""

import os
import subprocess
import sys
import tempfile
from functools import cache
from pathlib import Path

from grading import config
from grading.sandbox.worker import SYSTEM_LIBRARIES, syscall_filter

WORKER = Path(__file__).with_name("worker.py")  # the script a worker runs
PROTOCOL = Path(__file__).with_name("protocol.py")  # the wire format, beside it in every staging folder
WORKER_FILES = (WORKER, PROTOCOL)

# Paths inside the bubblewrap sandbox.
SANDBOX_PYTHON_ROOT = "/python"
SANDBOX_SITE = "/sandbox/site-packages"
SANDBOX_WORKER = "/sandbox/worker.py"
SANDBOX_PROTOCOL = "/sandbox/protocol.py"
SANDBOX_SUBMISSION = "/submission"


def site_packages():
    """The environment's site-packages folder (resolved)."""
    import sysconfig

    return Path(sysconfig.get_paths()["purelib"]).resolve()


def python_executable():
    """The interpreter's real path and its path relative to ``sys.base_prefix``."""
    executable = Path(sys.executable).resolve()
    base = Path(sys.base_prefix).resolve()
    try:
        return executable, executable.relative_to(base)
    except ValueError:
        return executable, None


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


def _masked_entries(site, extra=()):
    """Entries of a site folder the submission must not see: the forbidden
    packages (their modules, compiled libraries, bundled ``.libs`` and
    metadata), the editable install's files, which point back into the
    course repository, and the dotted names of ``extra`` (one exercise
    module's, :data:`grading.config.FORBIDDEN_IN_MODULE`: ``scipy.spatial``
    is the folder ``scipy/spatial``)."""
    forbidden = set(config.FORBIDDEN_PACKAGES) | {name for name in extra if "." not in name}
    masked = {
        path
        for name in extra
        if "." in name and not name.startswith("pcl_course.")
        for path in (site.joinpath(*name.split(".")), site.joinpath(*name.split(".")).with_suffix(".py"))
        if path.exists()
    }
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
    """The system's library folders that exist here (bound into the sandbox as they are; the
    worker's Landlock rules grant the same, :data:`grading.sandbox.worker.SYSTEM_LIBRARIES`)."""
    return [path for path in SYSTEM_LIBRARIES if Path(path).is_dir()]


def _import_roots():
    """(host folder, sandbox folder) of every folder the sandbox could import from."""
    base = Path(sys.base_prefix).resolve()
    return [(Path(p), p) for p in _system_roots()] + [(base, SANDBOX_PYTHON_ROOT), (site_packages(), SANDBOX_SITE)]


@cache
def masked_paths(extra=()):
    """Every entry, in every folder the sandbox could import from, that a submission must not
    reach: the forbidden packages and the editable install's files, and the dotted names of
    ``extra`` (a tuple: one exercise module's own, :func:`_masked_entries`)."""
    found = []
    for root, _ in _import_roots():
        for site_dir in _site_dirs(root):
            found += [entry for entry in _masked_entries(site_dir, extra) if entry not in found]
    return tuple(found)


def sandbox_roots():
    """(host folder, sandbox folder) of every folder bound into the sandbox that holds code."""
    return _import_roots()


@cache
def _environment_binds(extra=()):
    """The options that bind the interpreter, the system libraries and the
    site-packages, with every forbidden package masked (and ``extra``, one
    exercise module's own): the same for every worker of this process with
    the same ``extra``, and slow to find (every distribution's metadata is
    read), so found once."""
    options = []
    for source in _system_roots():
        options += ["--ro-bind", source, source, "--symlink", f"usr/{Path(source).name}", f"/{Path(source).name}"]
    for source in SYSTEM_LIBRARIES:
        if Path(source).is_file():
            options += ["--ro-bind", source, source]  # the loader's cache
    roots = _import_roots()
    for source, target in roots[len(_system_roots()) :]:
        options += ["--ro-bind", str(source), target]
    # Mask the forbidden packages wherever the sandbox could import them from.
    for entry in masked_paths(extra):
        source_root, target_root = next((s, t) for s, t in roots if s in entry.parents)
        target = f"{target_root}/{entry.relative_to(source_root)}"
        if entry.is_dir() and not entry.is_symlink():
            options += ["--tmpfs", target, "--remount-ro", target]  # an empty folder, never a place to write
        else:
            options += ["--ro-bind", "/dev/null", target]
    return tuple(options)


def bubblewrap_command(staged_root, python_argv_tail, extra=()):
    """The ``bwrap`` command line that runs the worker on a staged submission, with the
    forbidden packages masked, and ``extra`` too (a tuple of dotted names: one exercise
    module's own, :data:`grading.config.FORBIDDEN_IN_MODULE`)."""
    executable, relative = python_executable()
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
        *_environment_binds(tuple(extra)),
    ]
    command += [
        "--ro-bind",
        str(staged_root / "pcl_course"),
        f"{SANDBOX_SUBMISSION}/pcl_course",
        "--ro-bind",
        str(staged_root / WORKER.name),
        SANDBOX_WORKER,
        "--ro-bind",
        str(staged_root / PROTOCOL.name),
        SANDBOX_PROTOCOL,
        "--proc",
        "/proc",
        "--dev",
        "/dev",
        # POSIX shared memory (multiprocessing's locks) in a capped tmpfs of its own, and
        # nothing else of /dev writable: the devices are bound in, the folder read-only.
        "--size",
        str(config.SHM_SIZE),
        "--tmpfs",
        "/dev/shm",
        "--remount-ro",
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
    for key, value in environment("/tmp").items():
        command += ["--setenv", key, value]
    python = f"{SANDBOX_PYTHON_ROOT}/{relative}" if relative is not None else str(executable)
    return [*command, "--", python, "-I", "-S", SANDBOX_WORKER, SANDBOX_SITE, SANDBOX_SUBMISSION, *python_argv_tail]


@cache
def seccomp_program():
    """The compiled (cBPF) seccomp filter of :data:`grading.sandbox.worker.DENIED_EVERYWHERE`,
    as ``bwrap --seccomp`` reads it: the sandbox has no ``ldconfig`` to find libseccomp by."""
    try:
        import pyseccomp

        with tempfile.TemporaryFile() as compiled:
            syscall_filter(pyseccomp, network=False).export_bpf(compiled)
            compiled.seek(0)
            return compiled.read()
    except Exception as exc:  # no libseccomp: bubblewrap is then not a level this machine has
        raise OSError(f"no seccomp filter for bubblewrap ({type(exc).__name__}: {exc})") from None


def _pipe_of(data):
    """The read end of a pipe that holds ``data`` (a few kB at most: the pipe's buffer) and is closed."""
    read, write = os.pipe()
    try:
        os.write(write, data)
    finally:
        os.close(write)
    return read


def spawn(command, **kwargs):
    """Start ``command``; a ``bwrap`` command gets its arguments through a pipe
    (``--args FD``), so that no path of the grader's shows in the sandbox's
    ``/proc/1/cmdline``, and its seccomp filter through another (``--seccomp FD``)."""
    if command[0] != "bwrap":
        return subprocess.Popen(command, **kwargs)
    end = command.index("--")  # the options go through the pipe, the sandbox's own command line stays
    program = _pipe_of(seccomp_program())
    options = [*command[1:end], "--seccomp", str(program)]
    read = _pipe_of(b"".join(arg.encode() + b"\0" for arg in options))
    try:
        passed = (read, program, *kwargs.pop("pass_fds", ()))
        return subprocess.Popen(["bwrap", "--args", str(read), *command[end:]], pass_fds=passed, **kwargs)
    finally:
        os.close(read)
        os.close(program)


def environment(home):
    """The environment variables of a worker whose home (and temporary folder) is ``home``."""
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
