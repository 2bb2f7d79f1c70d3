"""Exercises: voxel grids, farthest point sampling, normal space sampling.

Voxel indexing used by both voxel filters: origin at the per-axis minimum of
the xyz columns; ``h = floor((p - min) / voxel_size)`` per axis as int64;
the grid size ``G = floor((max - min) / voxel_size) + 1`` per axis; linear
index ``h_x + h_y * G_x + h_z * G_x * G_y``. (The course's contract writes
the grid sizes ``D_x, D_y, D_z``; here they are ``G``, since ``D`` is the
number of columns of ``points``.)
"""

# What every solution needs (NumPy; SciPy's k-d tree is allowed; the course's input checks).
import numpy as np  # noqa: F401

from pcl_course.validation import as_points, check_choice, check_integer, check_positive, check_rng  # noqa: F401

__all__ = ["voxel_grid_downsample", "approximate_voxel_downsample", "farthest_point_sampling", "normal_space_sampling"]


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    """Exact voxel grid filter.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns; extra columns travel with their row.
    voxel_size : float
        Edge length of a voxel, > 0.
    method : {"centroid", "random"}, default "centroid"
        ``centroid``: the mean of all columns of the voxel's rows.
        ``random``: one of the voxel's input rows, uniformly at random.
    rng : None, int or numpy.random.Generator
        Random source for ``method="random"``.

    Returns
    -------
    downsampled : ndarray of float64, shape (M, D)
        One row per occupied voxel, ordered by increasing linear voxel index
        (x fastest, then y, then z).

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``voxel_size``; an unknown ``method``.

    Notes
    -----
    Must stay correct when ``G_x * G_y * G_z`` does not fit in int64: never
    merge two distinct voxels.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.1, 0.1, 0.0], [0.3, 0.1, 0.0], [1.2, 0.0, 0.0]])
    >>> voxel_grid_downsample(points, voxel_size=1.0)  # two occupied voxels
    array([[0.2, 0.1, 0. ],
           [1.2, 0. , 0. ]])
    """
    raise NotImplementedError("voxel_grid_downsample: not implemented yet")


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    """Approximate voxel grid filter with a hash table of ``n_containers``.

    ``container = linear_index % n_containers``. Visit the points in input
    order. A container holds one voxel at a time: when a point of a different
    voxel arrives at an occupied container, first emit one row for what the
    container holds (centroid, or a uniformly random one of its rows for
    ``method="random"``), then start the container afresh with the new
    point. At the end, emit every non-empty container in increasing
    container order.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns; extra columns travel with their row.
    voxel_size : float
        Edge length of a voxel, > 0.
    n_containers : int
        Number of containers of the hash table, >= 1.
    method : {"centroid", "random"}, default "centroid"
        What a container emits: the mean of all columns of its rows, or one of
        its rows uniformly at random.
    rng : None, int or numpy.random.Generator
        Random source for ``method="random"``.

    Returns
    -------
    downsampled : ndarray of float64, shape (M', D)
        Rows in emission order.

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``voxel_size``; ``n_containers`` < 1; an
        unknown ``method``.
    """
    raise NotImplementedError("approximate_voxel_downsample: not implemented yet")


def farthest_point_sampling(points, n_samples, start_index=0):
    """Farthest point sampling.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
    n_samples : int
        From 0 to N.
    start_index : int, default 0
        The first selected index.

    Returns
    -------
    indices : ndarray of int64, shape (n_samples,)
        In selection order. Each next index is the point whose squared
        Euclidean (xyz) distance to its nearest already-selected point is
        largest; ties go to the lowest index. No index repeats.

    Raises
    ------
    ValueError
        Bad ``points``; ``n_samples`` not between 0 and N; ``start_index`` not
        between 0 and N - 1 (when ``n_samples`` > 0).

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0, 0], [1, 0, 0], [5, 0, 0], [2, 0, 0]])
    >>> farthest_point_sampling(points, 3)  # 0, then the farthest (5), then 2 (3 from 5, 2 from 0)
    array([0, 2, 3])
    """
    raise NotImplementedError("farthest_point_sampling: not implemented yet")


def normal_space_sampling(normals, n_samples, n_bins=4, rng=None):
    """Normal space sampling.

    Bucket each unit normal in a cube grid over ``[-1, 1]^3``: per axis
    ``b = clip(floor((n + 1) / 2 * n_bins), 0, n_bins - 1)``; bucket id
    ``b_x + b_y * n_bins + b_z * n_bins ** 2``. Then draw round-robin over
    the non-empty buckets in increasing bucket id, each draw taking a
    uniformly random not-yet-taken point of that bucket, skipping exhausted
    buckets, until ``n_samples`` indices are drawn.

    Parameters
    ----------
    normals : array_like, shape (N, 3)
        Unit normals, one per point.
    n_samples : int
        Number of indices to draw, from 0 to N.
    n_bins : int, default 4
        Buckets per axis of the cube grid, >= 1.
    rng : None, int or numpy.random.Generator
        Random source of the draws within a bucket.

    Returns
    -------
    indices : ndarray of int64, shape (n_samples,)
        In draw order, no repeats.

    Raises
    ------
    ValueError
        Bad ``normals``; ``n_samples`` not between 0 and N; ``n_bins`` < 1.
    """
    raise NotImplementedError("normal_space_sampling: not implemented yet")
