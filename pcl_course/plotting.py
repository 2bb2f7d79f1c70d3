"""Plotting helpers for point clouds (complete).

Static figures use matplotlib's 3-D axes with equal scales on x, y and z, so
that a sphere looks like a sphere.
"""

import numpy as np

__all__ = ["new_3d_axes", "set_axes_equal", "plot_cloud", "plot_vectors"]


def new_3d_axes(fig, *position, title=None, elev=25, azim=-60):
    """Add a 3-D axes to ``fig`` at ``position`` (as ``fig.add_subplot``)."""
    ax = fig.add_subplot(*(position or (111,)), projection="3d")
    ax.view_init(elev=elev, azim=azim)
    if title:
        ax.set_title(title)
    return ax


def set_axes_equal(ax, points=None):
    """Give a 3-D axes equal scales on all three axes (around ``points``)."""
    if points is None:
        limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
    else:
        points = np.asarray(points)[:, :3]
        limits = np.stack([points.min(axis=0), points.max(axis=0)], axis=1)
    centre = limits.mean(axis=1)
    half = 0.5 * np.max(limits[:, 1] - limits[:, 0]) or 1.0
    ax.set_xlim3d(centre[0] - half, centre[0] + half)
    ax.set_ylim3d(centre[1] - half, centre[1] + half)
    ax.set_zlim3d(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    return ax


def plot_cloud(ax, points, color=None, size=2.0, cmap="viridis", axis_labels=True, **kwargs):
    """Scatter a point cloud on a 3-D axes, coloured by height by default.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    points : array_like, shape (N, 3) or (N, D)
    color : array_like of shape (N,), a colour, or None
        Values mapped through ``cmap`` (None: the z coordinate).
    size : float
        Marker area in points^2.
    """
    points = np.asarray(points, dtype=float)
    color = points[:, 2] if color is None else color
    if isinstance(color, str):  # one colour for all: no colour map
        kwargs["color"] = color
    else:
        kwargs.update(c=color, cmap=cmap)
    artist = ax.scatter(points[:, 0], points[:, 1], points[:, 2], s=size,
                        linewidths=0, depthshade=False, **kwargs)
    set_axes_equal(ax, points)
    if axis_labels:
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("z")
    return artist


def plot_vectors(ax, origins, vectors, length=1.0, color="k", **kwargs):
    """Draw arrows (normals, principal axes) from ``origins`` along ``vectors``."""
    origins = np.atleast_2d(origins)
    vectors = np.atleast_2d(vectors) * length
    return ax.quiver(origins[:, 0], origins[:, 1], origins[:, 2],
                     vectors[:, 0], vectors[:, 1], vectors[:, 2],
                     color=color, arrow_length_ratio=0.15, **kwargs)
