"""The grader's constants, in one place.

Every limit the sandbox and the staging step enforce lives here; the other
modules of :mod:`grading` import them from this module.
"""

import os

# -- the worker process (grading/sandbox.py) ----------------------------------
MEMORY_LIMIT = 4 * 1024**3      # bytes of address space of one worker
CPU_LIMIT = 600                 # CPU seconds for a worker's whole life
PROCESS_LIMIT = 256             # processes of the sandbox user (fork bombs)
FILE_SIZE_LIMIT = 256 * 1024**2  # bytes of any one file the worker writes
TMP_SIZE = 256 * 1024**2        # bytes of the worker's private /tmp (tmpfs, bubblewrap only)
CALL_TIMEOUT = 30.0             # wall-clock seconds of one call (import included)
ANSWER_LIMIT = 1024**3          # bytes of one answer the grader accepts from a worker

# The dedicated, unprivileged uids that run submissions when the grader is
# root: one per parallel job slot of `batch`, never shared with another
# account. Override the base with PCL_SANDBOX_UID (e.g. on a machine where
# these uids are taken).
SANDBOX_UID_BASE = int(os.environ.get("PCL_SANDBOX_UID", "60500"))
SANDBOX_UID_SLOTS = 64
# PCL_SANDBOX_NAMESPACES=0 grades as if namespaces were forbidden (as in most
# Docker containers): the dedicated uid and file permissions are then the wall.
SANDBOX_NAMESPACES = os.environ.get("PCL_SANDBOX_NAMESPACES", "1") != "0"

# -- staging a submission (grading/staging.py) ---------------------------------
STAGE_MAX_FILES = 200                   # regular files in a submission's pcl_course/
STAGE_MAX_FILE_BYTES = 4 * 1024**2      # bytes of one file
STAGE_MAX_TOTAL_BYTES = 16 * 1024**2    # bytes of all files together
STAGE_MAX_DEPTH = 8                     # nested folders
# Compiled code cannot be read by the forbidden-API scan: only source ships.
STAGE_REFUSED_SUFFIXES = (".so", ".pyd", ".pyc", ".pyo", ".dylib", ".dll")
STAGE_SKIPPED_NAMES = ("__pycache__", ".ipynb_checkpoints", ".DS_Store")

# -- what submissions may not use (grading/forbidden.py) -----------------------
FORBIDDEN_PACKAGES = ("open3d", "sklearn", "pcl", "pclpy", "torch", "torch_cluster", "pytorch3d", "fpsample")
