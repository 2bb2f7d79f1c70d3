"""The grader's constants, in one place.

Every limit the sandbox and the staging step enforce lives here; the other
modules of :mod:`grading` import them from this module.
"""

import os

# -- what is graded -------------------------------------------------------------
# One assignment per lecture, each its own Gradescope assignment (its own
# archive and total): graded function -> exercise module, every name in
# ../shared/course-api.md (lecture 1) or in pcl_course/nn.py's and pcl_course/cluster.py's
# contracts (lectures 2 and 3).
ASSIGNMENTS = {
    "lecture1": {
        "pca": "pca",
        "kernel_matrix": "pca",
        "kernel_pca": "pca",
        "kernel_pca_transform": "pca",
        "fit_plane": "normals",
        "estimate_normals": "normals",
        "voxel_grid_downsample": "downsampling",
        "approximate_voxel_downsample": "downsampling",
        "farthest_point_sampling": "downsampling",
        "normal_space_sampling": "downsampling",
        "radius_outlier_removal": "filters",
        "statistical_outlier_removal": "filters",
        "bilateral_filter_image": "filters",
        "bilateral_filter_points": "filters",
        "joint_bilateral_upsample": "filters",
        "chamfer_distance": "metrics",
        "depth_metrics": "metrics",
    },
    "lecture2": {
        "knn_result_set": "nn",
        "bst_build": "nn",
        "bst_knn": "nn",
        "kdtree_build": "nn",
        "kdtree_knn": "nn",
        "kdtree_radius": "nn",
        "octree_build": "nn",
        "octree_radius": "nn",
        "octree_knn": "nn",
    },
    "lecture3": {
        "kmeans": "cluster",
        "kmeans_plusplus": "cluster",
        "gmm_em": "cluster",
        "dbscan": "cluster",
        "euclidean_clusters": "cluster",
        "knn_graph": "cluster",
        "spectral_embedding": "cluster",
        "spectral_clustering": "cluster",
    },
}
GRADED_FUNCTIONS = {function: module for graded in ASSIGNMENTS.values() for function, module in graded.items()}
EXERCISE_MODULES = tuple(dict.fromkeys(GRADED_FUNCTIONS.values()))  # pcl_course/<module>.py
ASSIGNMENT_MODULES = {name: tuple(dict.fromkeys(graded.values())) for name, graded in ASSIGNMENTS.items()}
# A graded function's place in its own assignment (1, 2, ...), and its assignment's: Gradescope
# numbers a test "<function's place>.<test's place>", so that each assignment's tests start at 1.1;
# a run over several assignments (the whole course, locally) prefixes the assignment's place.
FUNCTION_NUMBERS = {function: i + 1 for graded in ASSIGNMENTS.values() for i, function in enumerate(graded)}
ASSIGNMENT_NUMBERS = {function: i + 1 for i, graded in enumerate(ASSIGNMENTS.values()) for function in graded}
# The course's title and its lectures' short titles (their parts of the book,
# _toc.yml), one per assignment, in order. The book (_config.yml's title, the
# part captions), pcl_course/__init__.py's docstring (its exercise modules by
# lecture), pyproject.toml's description, the Makefile's first line and the
# release's README (grading/templates/README.md's title) must agree with them:
# tests/project/test_labels.py checks they do.
COURSE_TITLE = "3D Point Cloud Processing"
LECTURES = {
    "lecture1": "PCA, normals, downsampling and filters",
    "lecture2": "Nearest neighbours",
    "lecture3": "Clustering",
}
# Complete helper modules of pcl_course: they may use Open3D (data sets) and
# are not exercises. A submission's copy is trusted only if it is unchanged.
HELPER_MODULES = ("__init__", "validation", "neighbors", "datasets", "io", "plotting", "book")

# -- time limits ------------------------------------------------------------------
# Wall-clock seconds of one graded test: a backstop above the calls' own CPU limits
# (CALL_TIMEOUT), for the grader's side of a test (trusted code in-process).
# The grader's own linear algebra (the tests' expected values, the catalogue's replays) runs on one
# BLAS thread: its matrices are small, and BLAS threads spinning on a busy machine cost more than
# they give (a gmm_em mutant's grading took 52 s with OpenBLAS's default threads and 9 s with one,
# another grading running beside it). The sandbox's workers run one thread already (their environment).
# OpenMP too: scikit-learn's k-means and neighbour searches in the tests' expected values use it.
GRADER_ENVIRONMENT = {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
TEST_TIMEOUT = 240.0
CALL_TIMEOUT = 30.0  # CPU seconds of one sandboxed call (its module's import included), all its threads
# A call is also stopped after CALL_WALL_FACTOR times as many wall-clock seconds: a
# backstop for a call that waits (sleeps, blocks) rather than computes. CPU time
# does not grow with the machine's load, so neither does a mark.
CALL_WALL_FACTOR = 4.0
MAX_FEEDBACK_LINES = 12  # of one failed test's feedback
# Values (array entries) of one call's arguments kept for the diagnosis
# (grading/diagnosis.py); larger calls are recorded without their arguments.
DIAGNOSIS_MAX_VALUES = 2_000_000
# Bytes of the copies (arguments and answers) kept for the diagnosis over a whole grading
# (grading/recording.py, Recorder): calls past it are recorded without them. The
# reference's whole grading (both lectures) keeps 21 MB (measured, see the README).
DIAGNOSIS_BUDGET = 64 * 1024**2
# Bytes of answers a grading receives between two collections of Python's reference cycles:
# a failed test's traceback holds its frames, and the answers in them, until the cycle
# collector runs, which counts objects, not bytes (a run of large answers, each failing,
# took the grading process from 0.86 to 1.4 GiB by the collector's timing alone).
COLLECT_EVERY_BYTES = 64 * 1024**2
# Wall-clock seconds of one submission's whole grading: tests not started by
# then score 0 with a line that says so, and a test under way when it runs out
# stops there (a hard deadline), within Gradescope's default limit of 10 minutes.
SUBMISSION_BUDGET = 480.0

# -- the worker process (grading/sandbox/) ----------------------------------
MEMORY_LIMIT = 4 * 1024**3  # bytes of address space of one worker
CPU_LIMIT = 600  # CPU seconds for a worker's whole life
PROCESS_LIMIT = 256  # processes of the sandbox user (fork bombs)
FILE_SIZE_LIMIT = 256 * 1024**2  # bytes of any one file the worker writes
# Descriptors a worker process may hold: each socket pair or pipe holds kernel buffers no reading
# counts (20,000 allowed 10,000 pairs of them: h77); numpy, numba and the worker need a few dozen.
OPEN_FILES_LIMIT = 1024
TMP_SIZE = 256 * 1024**2  # bytes of the worker's private /tmp (tmpfs, bubblewrap only)
SHM_SIZE = 64 * 1024**2  # bytes of its private /dev/shm (tmpfs, bubblewrap only): the only other writable place
# Limits of one call as a whole, over every process it started (alive, zombie or orphaned),
# read while it runs (grading/sandbox/client.py, CallUsage); the CPU limit is CALL_TIMEOUT.
CALL_MEMORY_LIMIT = MEMORY_LIMIT  # bytes of memory of all its processes together (their Pss)
# Bytes of the files a dedicated sandbox uid may own in the places it can write (its home,
# /tmp, /dev/shm, ...): the uid mode's counterpart of bubblewrap's TMP_SIZE + SHM_SIZE.
DISK_LIMIT = TMP_SIZE + SHM_SIZE
# Entries (files, folders, links) it may own there, and how deep its own folders may nest: no
# test needs more than a few (a numba cache), and the walk that sums them stops past these,
# so that a tree of empty files or of folders nested past PATH_MAX costs the grader little.
FILES_LIMIT = 10_000
FOLDER_DEPTH_LIMIT = 64
# What the grader reads from a worker, every size checked before anything is allocated
# (grading/sandbox/): the grader's own memory stays bounded whatever a worker sends.
ANSWER_LIMIT = 16 * 1024**2  # bytes of all the arrays of one answer (the reference's largest: 95 kB)
HEADER_LIMIT = 1024**2  # bytes of one answer's JSON header
MAX_ARRAYS = 4096  # arrays (and modified arguments) in one answer
MAX_TEXT = 2000  # characters kept of any one text a submission produced (a message, a name, a place)
MAX_OUTPUT = 4000  # characters of one test's feedback (grading/results.py)
MAX_REPORT = 64 * 1024  # characters of a failed test's traceback that pytest keeps until the session ends
MAX_OUTPUT_LINES = MAX_FEEDBACK_LINES + 2  # lines of it: the message's, a diagnosis and the last call
STDERR_TAIL_BYTES = 64 * 1024  # of the worker's stderr, read from its end after a crash

# The dedicated, unprivileged uids that run submissions when the grader is
# root: one per parallel job slot of `batch`, never shared with another
# account; and, without namespaces, one more per slot for each set of rules of
# the modules' own (FORBIDDEN_IN_MODULE; a block of SANDBOX_UID_SLOTS uids
# each, above the slots'), which ACLs bar from that set's packages too:
# (1 + sets) * SANDBOX_UID_SLOTS uids in all (grading/sandbox/walls.py).
# Override the base with PCL_SANDBOX_UID (e.g. on a machine where these uids
# are taken).
SANDBOX_UID_BASE = int(os.environ.get("PCL_SANDBOX_UID", "60500"))
SANDBOX_UID_SLOTS = 64
# PCL_SANDBOX_NAMESPACES=0 grades as if namespaces were forbidden (as in most
# Docker containers): the dedicated uid and file permissions are then the wall.
SANDBOX_NAMESPACES = os.environ.get("PCL_SANDBOX_NAMESPACES", "1") != "0"

# -- staging a submission (grading/staging.py) ---------------------------------
STAGE_MAX_FILES = 200  # regular files in a submission's pcl_course/
STAGE_MAX_FILE_BYTES = 4 * 1024**2  # bytes of one file
STAGE_MAX_TOTAL_BYTES = 16 * 1024**2  # bytes of all files together
STAGE_MAX_DEPTH = 8  # nested folders
# Compiled code cannot be read by the forbidden-API scan: only source ships.
STAGE_REFUSED_SUFFIXES = (".so", ".pyd", ".pyc", ".pyo", ".dylib", ".dll")
STAGE_SKIPPED_NAMES = ("__pycache__", ".ipynb_checkpoints", ".DS_Store")

# -- what submissions may not use (grading/forbidden.py) -----------------------
FORBIDDEN_PACKAGES = ("open3d", "sklearn", "pcl", "pclpy", "torch", "torch_cluster", "pytorch3d", "fpsample")
# Forbidden in one exercise module only, by dotted prefix ("pcl_course.x": the
# package's own module x, however it is imported). The nearest-neighbour
# lecture is about writing the search: no library's, nor the course's own
# helper (lecture 1 may use both).
FORBIDDEN_IN_MODULE = {
    "nn": (
        "scipy.spatial",
        "pykdtree",
        "pynanoflann",
        "faiss",
        "hnswlib",
        "annoy",
        "nanoflann",
        "numba_kdtree",
        "kdtree",
        "pcl_course.neighbors",
    ),
    # The clustering lecture is about writing the algorithms (scikit-learn's and Open3D's are
    # forbidden everywhere already).
    "cluster": ("scipy.cluster", "hdbscan", "fast_hdbscan", "dbscan", "pyclustering", "kmeans1d", "faiss"),
}
# Why, in the words the grader's forbidden-API line uses: one per module of FORBIDDEN_IN_MODULE.
MODULE_RULES_WHY = {
    "nn": "this lecture is about writing the search: no library's neighbour search, nor pcl_course.neighbors",
    "cluster": "this lecture is about writing the clustering algorithms: no library's k-means or clustering",
}

# -- the instructors' reports (grading/instructors/) -------------------------------
# Gradescope's submission_metadata.yml is read with these caps, an alias counted as
# the values it repeats (a 576-byte "billion laughs" of merge keys took the old reader
# past 1 GiB): a file past them identifies nobody, a record past them nobody of its
# submission (graded under its folder's name, with one line that says why).
METADATA_MAX_BYTES = 8 * 1024**2  # bytes of the file (a submission's record: about 200 bytes)
METADATA_MAX_NODES = 100_000  # values, keys and collections, aliases expanded (PyYAML: about 2 s, 45 MiB)
METADATA_MAX_DEPTH = 16  # nested values (Gradescope's: 5, a submitter's email)
METADATA_MAX_FIELD = 320  # characters of one submitter's name, SID or email (an email: 254)
