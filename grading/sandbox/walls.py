"""The walls around a worker: the isolation levels, what each one needs, and what a sandbox uid leaves.

``bubblewrap``
    ``bwrap --unshare-all`` (user, pid, network, ipc, uts and cgroup
    namespaces), ``--die-with-parent``, ``--new-session``, a cleared
    environment and a filesystem built from nothing
    (:mod:`grading.sandbox.bubblewrap`).
``uid``
    No namespaces (a container that forbids them), but the grader is root:
    the worker runs as a dedicated unprivileged uid (one per ``batch`` slot,
    reserved by :func:`reserve_uid`) and the grader bars every sandbox uid
    from the forbidden packages with a POSIX ACL (:func:`bar_sandbox_uids`),
    then checks, as that uid, that the course's tests, solutions and
    ``.git``, those packages and the files of the grading itself (the
    platform's, such as Gradescope's ``/autograder`` with its record of
    earlier results; ``batch``'s class folder and reports: :func:`protect`)
    cannot be read (:func:`permission_wall`),
    and that a seccomp filter closes the network (:func:`worker_walls`; the
    worker refuses to run without it). Where the kernel has Landlock (and the
    container lets it be used), the same probe measures that the worker can
    confine its files to the interpreter, the environment, the system's
    libraries, the submission and its home; the worker then refuses to run
    without it, and a world-readable file elsewhere (another copy of the
    course) is out of its reach too. Without it, the level says so. Everything that uid left running is
    killed after each worker, and every file it owns in the world-writable
    folders is removed before and after each submission
    (:func:`remove_files_of`).
``none``
    Neither: the worker runs as the grader's own user, with the resource
    limits only. Grading still runs, but the result is a local check, not a
    mark, and says so; ``--require-isolation`` refuses this level.
"""

import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from grading import REPO_ROOT, config
from grading.errors import SandboxError
from grading.sandbox.bubblewrap import (
    PROTOCOL,
    WORKER,
    bubblewrap_command,
    masked_paths,
    python_executable,
    site_packages,
    spawn,
)
from grading.sandbox.processes import become_subreaper, kill_uid, preexec
from grading.scratch import remove_tree

PROTECTED = ("tests", "solutions", ".git")  # of the course copy: never readable by a submission
# Folders of the grading's own (the platform's: Gradescope's /autograder, with its
# submission_metadata.json of earlier results; batch's class folder and reports), named by the
# command that grades in PCL_PROTECTED_PATHS (os.pathsep-separated) so that the grading process
# it starts probes them too.
PROTECTED_PATHS_VARIABLE = "PCL_PROTECTED_PATHS"


def protect(*paths):
    """Name ``paths`` (folders or files) as never readable by a sandbox uid: the permission
    probe (:func:`permission_wall`, run by :func:`isolation`) checks them, in this process and
    in every grading process it starts."""
    named = [p for p in os.environ.get(PROTECTED_PATHS_VARIABLE, "").split(os.pathsep) if p]
    named += [str(Path(path).resolve()) for path in paths if str(Path(path).resolve()) not in named]
    os.environ[PROTECTED_PATHS_VARIABLE] = os.pathsep.join(named)
    isolation.cache_clear()


def protected_paths():
    """Every existing path a submission must not read: the course copy's :data:`PROTECTED`
    folders and the paths named by :func:`protect`."""
    course = [REPO_ROOT / name for name in PROTECTED]
    named = [Path(p) for p in os.environ.get(PROTECTED_PATHS_VARIABLE, "").split(os.pathsep) if p]
    return [path for path in [*course, *named] if path.exists()]


BUBBLEWRAP, UID, NONE = "bubblewrap", "uid", "none"


@dataclass(frozen=True)
class Isolation:
    """How a worker is isolated: ``level`` (bubblewrap, uid or none), the
    uid that runs it (None: the grader's own) and, below bubblewrap, why."""

    level: str
    uid: int = None
    reason: str = ""
    files_open: str = ""  # the uid level: why Landlock does not confine its files ("": it does)

    @property
    def isolated(self):
        return self.level != NONE

    def describe(self):
        if self.level == BUBBLEWRAP:
            who = f"uid {self.uid}" if self.uid is not None else "the grader's user"
            return f"isolated: bubblewrap sandbox (no network, no files of the grader's), as {who}"
        if self.level == UID:
            files = (
                "files confined by Landlock to the interpreter, its libraries and the submission"
                if not self.files_open
                else f"other world-readable files of the machine readable ({self.files_open})"
            )
            return (
                f"isolated: dedicated uid {self.uid} that cannot read the grader's files, network and new "
                f"processes closed by a seccomp filter, {files}; no namespaces ({self.reason})"
            )
        return f"NOT ISOLATED ({self.reason}): this is a local check, not a mark"


def make_reachable(path):
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


def rule_sets():
    """The distinct sets of names the modules' own rules forbid (``FORBIDDEN_IN_MODULE``'s values,
    in order, each a tuple): set g (0, 1, ...) runs as its slot's uid ``g + 1`` blocks of
    :data:`grading.config.SANDBOX_UID_SLOTS` above the slot's own (:func:`rules_uid`)."""
    return list(dict.fromkeys(tuple(names) for names in config.FORBIDDEN_IN_MODULE.values()))


def sandbox_uid_count():
    """How many sandbox uids there are: a block of slots for the modules without rules of their
    own, and one for each set of rules (:func:`rule_sets`)."""
    return (1 + len(rule_sets())) * config.SANDBOX_UID_SLOTS


def rules_uid(uid, extra):
    """The uid that runs a module with forbidden names of its own (``extra``, such as
    ``scipy.spatial`` in ``nn.py``) in the slot of sandbox ``uid``: that set of rules' uid of the
    slot (:func:`rule_sets`), which ACLs bar from those packages too (:func:`isolation`), and
    from no other module's (``cluster.py`` may use ``scipy.spatial``); ``uid`` itself for a
    module without rules of its own."""
    if uid is None or not extra:
        return uid
    return uid + (1 + rule_sets().index(tuple(extra))) * config.SANDBOX_UID_SLOTS


def module_rules_paths(extra):
    """The entries the forbidden names ``extra`` (one module's own rules) add to the packages
    forbidden everywhere."""
    everywhere = set(masked_paths())
    return [path for path in masked_paths(tuple(extra)) if path not in everywhere]


def bar_forbidden_packages():
    """Bar every sandbox uid from the packages forbidden everywhere, and each set of rules' uids
    (:func:`rules_uid`) from the packages that set forbids too; None when done, else why not."""
    barred = bar_sandbox_uids(masked_paths())
    # A uid of a set of rules loses what an earlier set barred it from (ACLs stay on the files: a
    # course whose modules' rules changed, on the same environment), never what its own set bars:
    # no moment leaves a package open to a uid its rules bar from it.
    sets = {extra: rules_uid(config.SANDBOX_UID_BASE, extra) for extra in rule_sets()}
    every = {uid for first in sets.values() for uid in range(first, first + config.SANDBOX_UID_SLOTS)}
    stale = {}
    for path in {path for extra in sets for path in module_rules_paths(extra)}:
        kept = {
            uid
            for extra, first in sets.items()
            if path in module_rules_paths(extra)
            for uid in range(first, first + config.SANDBOX_UID_SLOTS)
        }
        stale.setdefault(tuple(sorted(every - kept)), []).append(path)
    for uids, paths in sorted(stale.items()):
        if barred is None and uids:
            barred = _setfacl(["-x", ",".join(f"u:{uid}" for uid in uids)], sorted(paths))
    for extra in rule_sets():
        if barred is None:
            first = rules_uid(config.SANDBOX_UID_BASE, extra)
            barred = bar_sandbox_uids(module_rules_paths(extra), range(first, first + config.SANDBOX_UID_SLOTS))
    return barred


def bar_sandbox_uids(paths, also_barred_from=None):
    """Deny every sandbox uid (every uid of every slot, or the uids ``also_barred_from``)
    all access to ``paths`` with a POSIX ACL (``setfacl``).

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
    uids = range(config.SANDBOX_UID_BASE, config.SANDBOX_UID_BASE + sandbox_uid_count())
    if also_barred_from is not None:
        uids = also_barred_from
    return _setfacl(["-m", ",".join(f"u:{uid}:---" for uid in uids)], paths)


def _setfacl(change, paths):
    """``setfacl -P <change> -- paths``: None when done, else why not (one line)."""
    if not paths:
        return None
    completed = subprocess.run(
        ["setfacl", "-P", *change, "--", *[str(p) for p in paths]], capture_output=True, text=True
    )
    if completed.returncode != 0:
        why = (completed.stderr.strip().splitlines() or ["?"])[-1]
        return f"the sandbox uids could not be barred from the forbidden packages ({why})"
    return None


WRITABLE_ROOTS = ("/tmp", "/var/tmp", "/dev/shm", "/run/lock", "/var/lock", "/dev/mqueue")


WORLD_WRITABLE_DEPTH = 32  # levels of other users' world-writable folders searched for a uid's files


def files_of(uid, roots=WRITABLE_ROOTS):
    """(path, stat) of every entry that ``uid`` owns below ``roots``; links never followed.

    A dedicated uid can create entries only where others may write: in
    world-writable folders (recursed into, :data:`WORLD_WRITABLE_DEPTH` levels
    at most) and in its own folders (listed as one entry: removed whole, their
    size summed by :func:`grading.sandbox.usage.files_usage_of`).
    """
    stack = [(root, 0) for root in roots if root]
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
            if info.st_uid == uid:
                yield entry.path, info
            elif stat.S_ISDIR(info.st_mode) and info.st_mode & stat.S_IWOTH and depth < WORLD_WRITABLE_DEPTH:
                stack.append((entry.path, depth + 1))


def remove_files_of(uid, roots=WRITABLE_ROOTS):
    """Remove every file and folder that ``uid`` owns below ``roots`` (:func:`files_of`; its own
    folders whole). Called before and after each submission in the uid mode, whose processes
    are all dead by then, so that nothing one submission wrote is there for the next one to
    find. Links are removed, never followed.
    """
    for path, info in list(files_of(uid, roots)):
        if stat.S_ISDIR(info.st_mode):
            remove_tree(path)  # however deep the uid nested it (shutil.rmtree recursed)
        else:
            try:
                os.unlink(path)
            except OSError:
                pass


def _probe_script(paths):
    return (
        "import os, sys\n"
        f"sys.path.append({str(site_packages())!r})\n"
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
        for name, text in ((WORKER.name, "import sys\n"), (PROTOCOL.name, "")):  # the worker itself imports numpy
            (staged / name).write_text(text)
            (staged / name).chmod(0o644)
        probe = spawn(
            bubblewrap_command(staged, []),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=preexec(uid),
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
            [str(python_executable()[0]), "-I", "-S", "-c", _probe_script(protected)],
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=preexec(uid),
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
        if not Path(readable[0]).is_relative_to(REPO_ROOT):
            return f"uid {uid} can read {readable[0]}: make it unreadable to others (chmod 700)"
        return (
            f"uid {uid} can read {readable[0]}: make the course folder {REPO_ROOT} unreadable to others "
            f"(chmod 700) and keep the Python environment outside it"
        )
    return None


def worker_walls(uid):
    """Whether a worker running as ``uid`` can close its network (seccomp) and confine its files
    (Landlock): ``(None or why not, None or why not)``.

    Run as ``uid`` with the worker's own code (``--check-network``): the
    socket it then fails to open and the world-readable file outside its
    paths that it fails to read are measured, not assumed.
    """
    folder = tempfile.mkdtemp(prefix="grading-network-")  # the course's copy is out of the uid's reach
    canary = tempfile.mkdtemp(prefix="grading-canary-")
    for path in (folder, canary):
        os.chmod(path, 0o755)
    os.chmod(shutil.copy(WORKER, folder), 0o644)
    Path(canary, "readable-by-all").write_text("a file every user may read\n")
    os.chmod(Path(canary, "readable-by-all"), 0o644)
    try:
        completed = subprocess.run(
            [
                str(python_executable()[0]),
                "-I",
                "-S",
                f"{folder}/{WORKER.name}",
                "--check-network",
                str(site_packages()),
                str(Path(canary, "readable-by-all")),
            ],
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=preexec(uid),
            env={"PATH": "/usr/bin:/bin"},
            cwd="/",
        )
        answer = json.loads(completed.stdout.strip().splitlines()[-1])
    except (OSError, subprocess.SubprocessError) as exc:
        return f"the network could not be closed: the check failed ({exc})", "not checked"
    except (ValueError, IndexError):
        why = (completed.stderr.strip().splitlines() or ["no output"])[-1]
        return f"the network could not be closed: the check failed ({why})", "not checked"
    finally:
        kill_uid(uid)
        shutil.rmtree(folder, ignore_errors=True)
        shutil.rmtree(canary, ignore_errors=True)
    network = None if answer.get("closed") else f"the network could not be closed: {answer.get('why')}"
    return network, answer.get("files")


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
        course's :data:`PROTECTED` folders nor the paths named by :func:`protect`
        (the platform's files, the class's folder); else ``none``, with the reasons.
    """
    root = os.geteuid() == 0
    uid = reserve_uid(uid) if root else None
    become_subreaper()  # the probe's orphans come back here to be reaped
    if root:
        make_reachable(Path(sys.base_prefix) / "lib")
        make_reachable(site_packages())
    if config.SANDBOX_NAMESPACES:
        why_not = _bubblewrap_works(uid)
        if why_not is None:
            return Isolation(BUBBLEWRAP, uid)
    else:
        why_not = "namespaces switched off (PCL_SANDBOX_NAMESPACES=0)"
    if not root:
        return Isolation(NONE, None, f"{why_not}; the grader is not root, so no dedicated uid")
    # The second wall: a dedicated uid that can read neither the grader's files nor the forbidden packages.
    barred = bar_forbidden_packages()
    if barred is not None:
        return Isolation(NONE, None, f"{why_not}; {barred}")
    wall = permission_wall(uid, [*protected_paths(), *masked_paths()])
    for extra in rule_sets():
        if wall is None:
            wall = permission_wall(
                rules_uid(uid, extra), [*protected_paths(), *masked_paths(), *module_rules_paths(extra)]
            )
    if wall is not None:
        return Isolation(NONE, None, f"{why_not}; {wall}")
    network, files = worker_walls(uid)
    if network is not None:
        return Isolation(NONE, None, f"{why_not}; {network}")
    return Isolation(UID, uid, why_not, files_open=files or "")
