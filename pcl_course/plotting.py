"""Plotting helpers for point clouds (complete).

Static figures use matplotlib's 3-D axes with equal scales on x, y and z, so
that a sphere looks like a sphere.
"""

import numpy as np

__all__ = ["new_3d_axes", "set_axes_equal", "plot_cloud", "plot_vectors", "depth_panels", "worst_difference_window"]


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
    artist = ax.scatter(points[:, 0], points[:, 1], points[:, 2], s=size, linewidths=0, depthshade=False, **kwargs)
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
    return ax.quiver(
        origins[:, 0],
        origins[:, 1],
        origins[:, 2],
        vectors[:, 0],
        vectors[:, 1],
        vectors[:, 2],
        color=color,
        arrow_length_ratio=0.15,
        **kwargs,
    )


# --- interactive figures (Plotly) -------------------------------------------
#
# The book loads one local copy of plotly.js on the pages that need it (see
# book/_ext/offline_assets.py), so figures are written without it.


def cloud_trace(points, color=None, size=1.5, name=None, colorscale="Viridis", showscale=False, **marker):
    """A Plotly 3-D scatter trace of a cloud, coloured by height by default."""
    import plotly.graph_objects as go

    points = np.asarray(points, dtype=float)
    color = points[:, 2] if color is None else color
    return go.Scatter3d(
        x=points[:, 0],
        y=points[:, 1],
        z=points[:, 2],
        mode="markers",
        name=name,
        marker=dict(size=size, color=color, colorscale=colorscale, showscale=showscale, **marker),
        hoverinfo="skip",
    )


def vectors_trace(origins, vectors, length=1.0, color="black", name=None, width=3):
    """Line segments from ``origins`` along ``vectors`` (normals, axes), as one trace."""
    import plotly.graph_objects as go

    origins = np.atleast_2d(np.asarray(origins, dtype=float))
    ends = origins + np.atleast_2d(vectors) * length
    segments = np.full((3 * len(origins), 3), np.nan)  # NaN rows break the line between segments
    segments[0::3], segments[1::3] = origins, ends
    return go.Scatter3d(
        x=segments[:, 0],
        y=segments[:, 1],
        z=segments[:, 2],
        mode="lines",
        name=name,
        line=dict(color=color, width=width),
        hoverinfo="skip",
    )


def interactive_figure(traces, title=None, height=520, camera_eye=(1.4, -1.4, 0.9)):
    """A Plotly figure of 3-D traces with equal axis scales."""
    import plotly.graph_objects as go

    figure = go.Figure(data=list(traces))
    figure.update_layout(
        title=title,
        height=height,
        margin=dict(l=0, r=0, t=40 if title else 10, b=30),
        scene=dict(aspectmode="data", camera=dict(eye=dict(zip("xyz", camera_eye)))),
        # Below the scene, left: the mode bar takes the top right corner.
        legend=dict(itemsizing="constant", orientation="h", x=0.0, xanchor="left", y=0.0, yanchor="top"),
    )
    return figure


def show_interactive(figure):
    """Display a Plotly figure in the book: an HTML fragment without plotly.js."""
    from IPython.display import HTML

    return HTML(
        figure.to_html(full_html=False, include_plotlyjs=False, config={"displaylogo": False, "responsive": True})
    )


def depth_panels(panels, vmax, label, cmap="turbo_r", columns=1, box=None, zero_is_missing=True):
    """Images and depth maps in a grid, with one colour bar for the maps.

    Parameters
    ----------
    panels : list of (str, ndarray)
        Titles and images: ``(H, W, 3)`` colour images are shown as they are,
        ``(H, W)`` maps with ``cmap`` from 0 to ``vmax``.
    vmax : float
        Top of the colour scale (the maps' unit, e.g. metres).
    label : str
        The colour bar's label.
    columns : int, default 1
    box : (slice, slice), optional
        Rows and columns of a rectangle to outline in white on every panel.
    zero_is_missing : bool, default True
        Show 0 as blank (no measurement), as for depth maps.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    rows = -(-len(panels) // columns)
    height, width = panels[0][1].shape[:2]
    fig, axes = plt.subplots(
        rows, columns, figsize=(12, rows * 12 / columns * height / width + 0.6), layout="constrained", squeeze=False
    )
    mapped = None
    for ax, (title, image) in zip(axes.flat, panels):
        if image.ndim == 3:
            ax.imshow(image)
        else:
            shown = np.where(image > 0, image, np.nan) if zero_is_missing else image
            mapped = ax.imshow(shown, cmap=cmap, vmin=0.0, vmax=vmax)
        if box is not None:
            ys, xs = box
            ax.add_patch(Rectangle((xs.start, ys.start), xs.stop - xs.start, ys.stop - ys.start, fill=False,
                                   edgecolor="white", lw=1.5))  # fmt: skip
        ax.set_title(title)
        ax.set_axis_off()
    for ax in list(axes.flat)[len(panels) :]:
        ax.set_axis_off()
    if mapped is not None:
        fig.colorbar(mapped, ax=axes, label=label, shrink=0.8)
    plt.show()


def worst_difference_window(error_a, error_b, valid, size):
    """The window of ``size`` (rows, columns) where ``error_a - error_b`` sums highest over ``valid`` pixels.

    Returns
    -------
    rows, columns : slice
    """
    from scipy.ndimage import uniform_filter

    gain = np.where(valid, error_a - error_b, 0.0)
    height, width = size
    mean = uniform_filter(gain, size=(height, width), mode="constant")
    row, column = np.unravel_index(np.argmax(mean), mean.shape)
    top = int(np.clip(row - height // 2, 0, gain.shape[0] - height))
    left = int(np.clip(column - width // 2, 0, gain.shape[1] - width))
    return slice(top, top + height), slice(left, left + width)
