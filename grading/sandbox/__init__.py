"""Run a staged submission's functions in a separate, isolated worker process.

The grading process (which runs the tests and decides the score) never
imports the submission: :class:`Worker` sends each call to a worker process
that runs at the strongest isolation the machine allows (:func:`isolation`:
``bubblewrap``, a dedicated ``uid``, or ``none``, a local check only), under
resource limits, and reads back plain data only. One job per module:

* :mod:`~grading.sandbox.walls` -- the isolation levels and their walls:
  uid reservation, the permission and network walls, file clean-up;
* :mod:`~grading.sandbox.processes` -- the worker's processes: limits,
  accounting (threads, CPU time), killing what a uid left running;
* :mod:`~grading.sandbox.bubblewrap` -- the ``bwrap`` command: binds, masks
  of the forbidden packages, environment;
* :mod:`~grading.sandbox.protocol` -- the wire format, both halves, stated
  once in its docstring; ``worker.py`` (the script the worker runs) beside it;
* :mod:`~grading.sandbox.client` -- :class:`Worker`, the grader's side of a
  call: deadlines by CPU time, stray threads, the answer decoded.

The names below are this package's public interface; the rest is private
to its modules.
"""

from grading.sandbox.arguments import set_generator_state
from grading.sandbox.bubblewrap import WORKER, WORKER_FILES, masked_paths, site_packages
from grading.sandbox.client import STRAY_MESSAGE, Worker
from grading.sandbox.processes import kill_uid, living_processes, process_limit, tasks_of_user
from grading.sandbox.walls import (
    BUBBLEWRAP,
    NONE,
    PROTECTED,
    UID,
    WRITABLE_ROOTS,
    Isolation,
    bar_sandbox_uids,
    isolation,
    make_reachable,
    permission_wall,
    protect,
    protected_paths,
    remove_files_of,
    reserve_uid,
    worker_walls,
)

__all__ = [
    "BUBBLEWRAP",
    "NONE",
    "PROTECTED",
    "STRAY_MESSAGE",
    "UID",
    "WORKER",
    "WORKER_FILES",
    "WRITABLE_ROOTS",
    "Isolation",
    "Worker",
    "bar_sandbox_uids",
    "isolation",
    "kill_uid",
    "living_processes",
    "make_reachable",
    "masked_paths",
    "permission_wall",
    "process_limit",
    "protect",
    "protected_paths",
    "remove_files_of",
    "reserve_uid",
    "set_generator_state",
    "site_packages",
    "tasks_of_user",
    "worker_walls",
]
