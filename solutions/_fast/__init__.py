"""Compiled kernels of the references (numba), one small module per technique.

==========  ============================================================
module      what
==========  ============================================================
``bounds``  per-axis bounds of a cloud (plain NumPy, shared by the rest)
``threads`` run a ``nogil`` kernel over index slices on every core
``order``   Z-order (Morton) sort of a cloud
``grid``    points sorted by grid cell; fixed-radius neighbour counts
``knn``     exact k nearest neighbours of every point, a leaf at a time
``eig3``    closed-form smallest eigenpair of a 3x3 symmetric matrix; patch normals
``voxel``   voxel keys, hash grouping, reservoir choice, the lecture's hash table
``fps``     exact farthest point sampling over buckets
``kdtree``  lecture 2's k-d tree: median build, kNN and radius searches
``octree``  lecture 2's octree: build, radius search, kNN with early termination
``rows``    the trees' shared pieces: distances, sorted CSR rows, rows un-permuted
``bst``     lecture 2's result set and binary search tree
``sorting`` in-place introsort of a range, alone or with a payload
``lloyd``   lecture 3's k-means: one pass per iteration (assignment, sums, inertia, changes)
``density`` lecture 3's DBSCAN: neighbours from candidate pairs, union-find of the cores
==========  ============================================================

No kernel calls ``np.sort`` or ``np.argsort``: ``sorting`` says why (numba's
cache can bind their helpers to another process's; a segmentation fault).

Why a package of their own, always imported under the same names
(``solutions._fast.knn``, ...): numba's on-disk cache (``cache=True``, which
saves the one to two seconds of compilation per function in every new
process) remembers the module a function was compiled under. The grader
loads the exercise modules under private names, so a kernel defined there
would find a cache written under another name. Renaming a module here costs
every process one recompilation, until the cache is rewritten.
"""
