"""Plotting helpers for point clouds (complete).

Static figures use matplotlib's 3-D axes with equal scales on x, y and z, so
that a sphere looks like a sphere.
"""

import numpy as np

__all__ = [
    "new_3d_axes",
    "set_axes_equal",
    "plot_cloud",
    "plot_vectors",
    "cloud_trace",
    "vectors_trace",
    "interactive_figure",
    "show_interactive",
    "depth_panels",
    "worst_difference_window",
    "cloud_gallery",
    "principal_axes_gallery",
    "angular_error_gallery",
    "scan_top_view",
    "rayleigh_curve",
    "rotating_direction",
    "eigen_images",
    "reconstruction_figure",
    "labelled_codes",
    "lifting_figure",
    "component_scatter",
    "curves",
    "error_against_radius",
    "precision_recall_panels",
    "samples_top_view",
    "highlighted_samples",
    "sampler_gallery",
    "accuracy_against_samples",
    "outlier_filters",
    "filtered_images",
    "box_slices",
    "kdtree_leaf_cells",
    "bst_drawing",
    "kdtree_partitions",
    "octant_tests",
    "root_squares",
    "kmeans_trajectories",
    "ratio_distributions",
    "cluster_panels",
    "density_panels",
    "k_distance_curve",
    "clusters_top_view",
    "mixture_iterations",
    "clustering_grid",
    "small_graph",
    "spectral_panels",
    "mean_shift_paths",
    "bandwidth_sweep",
]


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
    ax.set_box_aspect((1, 1, 1), zoom=0.9)  # a margin for the z label, which a full-size box pushes out of the figure
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


# --- the book's figures ------------------------------------------------------
#
# One function per kind of figure, so that a page shows what it computes and
# one line that draws it. Each draws a matplotlib figure and shows it.


def cloud_gallery(panels, columns, figsize, size=1.0, axis_labels=False, axis_off=True):
    """3-D views of several clouds in a grid, filled row by row.

    Parameters
    ----------
    panels : list of (str, array_like of shape (N, 3))
        Titles and clouds.
    columns : int
    figsize : (float, float)
        Inches.
    size : float or sequence of float
        Marker area in points^2, one for all panels or one per panel.
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=figsize)
    rows = -(-len(panels) // columns)
    sizes = np.broadcast_to(np.asarray(size, dtype=float), (len(panels),))
    for i, ((title, points), marker_size) in enumerate(zip(panels, sizes)):
        ax = new_3d_axes(fig, rows, columns, i + 1, title=title)
        plot_cloud(ax, points, size=marker_size, axis_labels=axis_labels)
        if axis_off:
            ax.set_axis_off()
    plt.show()


def principal_axes_gallery(panels, columns, figsize, color="0.6", size=0.5, width=2.5, axis_off=False):
    """Clouds with their principal axes, two standard deviations long (red, green, blue).

    Parameters
    ----------
    panels : list of (str, ndarray of shape (N, 3), ndarray of shape (3,), ndarray of shape (3, 3))
        Title, points, eigenvalues (decreasing) and eigenvectors (columns).
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=figsize)
    rows = -(-len(panels) // columns)
    for i, (title, points, values, vectors) in enumerate(panels):
        ax = new_3d_axes(fig, rows, columns, i + 1, title=title)
        plot_cloud(ax, points, color=color, size=size, axis_labels=False)
        for k, axis_color in enumerate("rgb"):
            plot_vectors(ax, points.mean(axis=0), vectors[:, k], length=2 * np.sqrt(values[k]), color=axis_color,
                         lw=width)  # fmt: skip
        if axis_off:
            ax.set_axis_off()
    plt.show()


def angular_error_gallery(panels, figsize, size=3.0, arrows=None, axis_off=False, clip=30.0):
    """Clouds coloured by the angular error of their normals, with one colour bar.

    Parameters
    ----------
    panels : list of (str, ndarray of shape (N, 3), ndarray of shape (N,))
        Title, points and the error at each point (degrees).
    arrows : list of (ndarray of shape (M, 3), ndarray of shape (M, 3)), optional
        Per panel, origins and unit vectors drawn as short blue lines.
    clip : float
        Top of the colour scale (degrees); larger errors show as ``clip``.
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=figsize)
    for i, (title, points, error) in enumerate(panels):
        ax = new_3d_axes(fig, 1, len(panels), i + 1, title=title)
        artist = plot_cloud(ax, points, color=np.clip(error, 0, clip), size=size, cmap="magma",
                            axis_labels=not axis_off, vmin=0, vmax=clip)  # fmt: skip
        if arrows is not None:
            origins, vectors = arrows[i]
            plot_vectors(ax, origins, vectors, length=0.08, color="tab:blue", lw=0.6)
        if axis_off:
            ax.set_axis_off()
    fig.colorbar(artist, ax=fig.axes, shrink=0.7, label=f"angular error (degrees, clipped at {clip:g})")
    plt.show()


def scan_top_view(points, labels, is_outlier, class_names, colors=("0.6", "tab:blue", "tab:orange", "k",
                                                                     "tab:green", "tab:purple")):  # fmt: skip
    """Bird's-eye view of a lidar scan coloured by class, its spurious returns in red.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
        Metres.
    labels : ndarray of int, shape (N,)
        Indices into ``class_names``.
    is_outlier : ndarray of bool, shape (N,)
    """
    import matplotlib.pyplot as plt

    colors = np.asarray(colors)
    fig, ax = plt.subplots(1, 1, figsize=(8, 8))
    inliers = ~is_outlier
    ax.scatter(*points[inliers, :2].T, s=0.2, c=colors[labels[inliers]], linewidths=0)
    ax.scatter(*points[is_outlier, :2].T, s=3, c="red", linewidths=0, label="spurious returns")
    for label, color in zip(class_names, colors):
        ax.scatter([], [], c=color, s=20, label=label)
    ax.set(xlim=(-60, 60), ylim=(-60, 60), aspect="equal", xlabel="x (m)", ylabel="y (m)")
    ax.legend(loc="upper right", markerscale=1)
    plt.show()


def _angle_degrees(vector):
    """The angle of a 2-D direction in [0, 180) degrees (a direction and its opposite are one)."""
    return np.degrees(np.arctan2(vector[1], vector[0])) % 180


def rayleigh_curve(angles, quotient, eigenvalues, eigenvectors):
    """The Rayleigh quotient along the unit circle, with the eigenvalues and eigenvectors' angles.

    Parameters
    ----------
    angles : ndarray of shape (M,)
        Radians.
    quotient : ndarray of shape (M,)
    eigenvalues : ndarray of shape (2,)
    eigenvectors : ndarray of shape (2, 2)
        Columns.
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 1, figsize=(7, 3.5))
    ax.plot(np.degrees(angles), quotient, label=r"$R_A(\cos\theta, \sin\theta)$")
    for value, vector in zip(eigenvalues, eigenvectors.T):
        ax.axhline(value, ls="--", c="gray")
        ax.axvline(_angle_degrees(vector), ls=":", c="gray")
    ax.set(xlabel=r"$\theta$ (degrees)", ylabel="Rayleigh quotient")
    ax.legend()
    plt.show()


def rotating_direction(cloud, angles, variance, eigenvectors, shown_degrees=(0, 30, 60, 90, 120, 150)):
    """A 2-D cloud with some directions, and the variance along a direction against its angle.

    Parameters
    ----------
    cloud : ndarray of shape (N, 2)
    angles : ndarray of shape (M,)
        Radians.
    variance : ndarray of shape (M,)
        Variance of the coordinates along each angle's direction.
    eigenvectors : ndarray of shape (2, 2)
        The covariance's eigenvectors (columns), marked as dashed lines.
    """
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    left.scatter(*cloud.T, s=5, color="0.6")
    for a in np.deg2rad(shown_degrees):
        left.plot([0, 2.5 * np.cos(a)], [0, 2.5 * np.sin(a)], lw=1)
    left.set(aspect="equal", title="the cloud and some directions")
    right.plot(np.degrees(angles), variance)
    for vector in eigenvectors.T:
        right.axvline(_angle_degrees(vector), ls="--", color="k")
    right.set(xlabel="angle theta of z (degrees)", ylabel="variance of the coordinates z.x~")
    plt.show()


def eigen_images(mean, eigenvectors, share, image_shape, count=9):
    """The mean image and the first ``count`` principal directions as images (red adds, blue removes).

    Parameters
    ----------
    mean : ndarray of shape (P,)
    eigenvectors : ndarray of shape (P, K)
        Columns, in decreasing order of variance.
    share : ndarray of shape (K,)
        Share of the variance along each direction, shown in its title.
    image_shape : (int, int)
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, count + 1, figsize=(13, 1.8))
    axes[0].imshow(mean.reshape(image_shape), cmap="gray_r")
    axes[0].set_title("mean")
    for k, ax in enumerate(axes[1:]):
        v = eigenvectors[:, k].reshape(image_shape)
        ax.imshow(v, cmap="RdBu_r", vmin=-np.abs(v).max(), vmax=np.abs(v).max())
        ax.set_title(f"u{k + 1}: {share[k]:.1%}")
    for ax in axes:
        ax.set_axis_off()
    plt.show()


def reconstruction_figure(kept_share, rows, image_shape, vmax):
    """The variance kept against k (left), and rows of images decoded from k components (right).

    Parameters
    ----------
    kept_share : ndarray of shape (K,)
        Share of the variance kept by the first 1, 2, ..., K components.
    rows : dict of str to ndarray of shape (M, P)
        Row label to M flattened images.
    image_shape : (int, int)
    vmax : float
        Top of the grey scale.
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(13, 4))
    ax = fig.add_subplot(1, 3, 1)
    ax.plot(np.arange(1, len(kept_share) + 1), kept_share, marker=".")
    ax.set(xlabel="number of components k", ylabel="share of variance kept", ylim=(0, 1.02))
    ax.grid(alpha=0.3)
    columns = len(next(iter(rows.values())))
    grid = fig.add_gridspec(len(rows), columns, left=0.4, right=0.98)
    for row, (label, images) in enumerate(rows.items()):
        for column, image in enumerate(images):
            a = fig.add_subplot(grid[row, column])
            a.imshow(image.reshape(image_shape), cmap="gray_r", vmin=0, vmax=vmax)
            a.set_xticks([])
            a.set_yticks([])
            if column == 0:
                a.set_ylabel(label, rotation=0, labelpad=18)
    plt.show()


def labelled_codes(codes, labels):
    """Points at their first two coordinates, coloured by class, each class's label at its mean."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 1, figsize=(7, 6))
    scatter = ax.scatter(codes[:, 0], codes[:, 1], c=labels, cmap="tab10", s=8)
    for label in np.unique(labels):
        ax.annotate(str(label), codes[labels == label].mean(axis=0), fontsize=16, weight="bold", ha="center",
                    va="center", bbox=dict(boxstyle="circle", fc="white", alpha=0.8))  # fmt: skip
    ax.set(xlabel="first principal coordinate", ylabel="second principal coordinate")
    fig.colorbar(scatter, ax=ax, ticks=np.unique(labels), label="digit")
    plt.show()


def lifting_figure(points, labels, first_linear, lifted, lifted_coordinates, component):
    """The circles with their 1st linear PC, the lifted points, and two lifted principal coordinates.

    Parameters
    ----------
    points : ndarray of shape (N, 2)
    labels : ndarray of shape (N,)
    first_linear : ndarray of shape (N,)
        Coordinates on the first principal direction of ``points``.
    lifted : ndarray of shape (N, 3)
    lifted_coordinates : ndarray of shape (N, 3)
        Coordinates on the lifted principal directions.
    component : int
        The lifted component plotted against the first (0-based).
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(14, 4.2))
    ax = fig.add_subplot(1, 3, 1)
    ax.scatter(*points.T, c=labels, cmap="coolwarm", s=8)
    ax.scatter(first_linear, np.full(len(points), -1.4), c=labels, cmap="coolwarm", s=4, marker="|")
    ax.set(aspect="equal", title="input and its 1st PC (bottom)")
    ax = new_3d_axes(fig, 1, 3, 2, title=r"lifted by $\phi$", elev=15)
    ax.scatter(*lifted.T, c=labels, cmap="coolwarm", s=6)
    ax = fig.add_subplot(1, 3, 3)
    ax.scatter(lifted_coordinates[:, 0], lifted_coordinates[:, component], c=labels, cmap="coolwarm", s=8)
    ax.set(xlabel="1st lifted principal coordinate", ylabel=f"principal coordinate {component + 1}")
    fig.subplots_adjust(wspace=0.5)  # room for the 3-D axes' tick labels, which overhang their box
    plt.show()


def component_scatter(panels, labels):
    """Points at their first two components, one panel per method, coloured by class.

    Parameters
    ----------
    panels : dict of str to ndarray of shape (N, >= 2)
    labels : ndarray of shape (N,)
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(15, 3.8), layout="constrained", squeeze=False)
    for ax, (title, projections) in zip(axes[0], panels.items()):
        ax.scatter(*projections[:, :2].T, c=labels, cmap="coolwarm", s=8)
        ax.set(title=title, xlabel="1st component", ylabel="2nd component")
    plt.show()


def _ticks_at(ax, x, most=10):
    """Label a log x axis at the values measured (at most ``most``), not at powers of ten."""
    if len(x) <= most:
        ax.set_xticks(x, [f"{int(value):,}" if float(value).is_integer() else f"{value:g}" for value in x])
        ax.set_xticks([], minor=True)


def curves(x, values, xlabel, ylabel, xscale="log", yscale="log", ylim=None, vline=None, floor=None,
           figsize=(7, 4), styles=None, legend_outside=False):  # fmt: skip
    """Several curves over one x axis, with a legend.

    Parameters
    ----------
    x : array_like of shape (M,)
    values : dict of str to array_like of shape (M,)
        Legend label to the curve's values.
    vline : (float, str), optional
        A dotted vertical line and its legend label.
    floor : float, optional
        Values below it are drawn at it (a log scale has no 0).
    styles : sequence of str, optional
        Line styles for curves that come in groups (``["-", "--"]``: pairs):
        curve ``j`` is drawn with ``styles[j % len(styles)]`` in the group's
        colour, ``j // len(styles)``. Default: one colour per curve, solid.
    legend_outside : bool
        Put the legend to the right of the axes, where no curve runs under it
        (for many curves that fill the plot).
    """
    import matplotlib.pyplot as plt

    styles = ["-"] if styles is None else list(styles)
    fig, ax = plt.subplots(1, 1, figsize=figsize)
    for j, (label, ys) in enumerate(values.items()):
        ys = np.asarray(ys, dtype=float)
        colour = f"C{j // len(styles) if len(styles) > 1 else j}"
        ax.plot(x, ys if floor is None else np.maximum(ys, floor), marker="o", label=label,
                ls=styles[j % len(styles)], color=colour)  # fmt: skip
    if vline is not None:
        ax.axvline(vline[0], ls=":", c="gray", label=vline[1])
    ax.set(xlabel=xlabel, ylabel=ylabel, xscale=xscale, yscale=yscale)
    if xscale == "log":
        _ticks_at(ax, x)
    if ylim is not None:
        ax.set_ylim(*ylim)
    if legend_outside:
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
        fig.tight_layout()
    else:
        ax.legend()
    ax.grid(alpha=0.3, which="both")
    plt.show()


def error_against_radius(radii, errors, shapes, noises):
    """Mean angular error against the radius, one panel per shape, one curve per noise level.

    Parameters
    ----------
    radii : array_like of shape (M,)
    errors : dict of (str, float) to array_like of shape (M,)
        ``errors[shape, noise]``, degrees.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(shapes), figsize=(12, 4), sharey=True, squeeze=False)
    axes = axes[0]
    for ax, shape in zip(axes, shapes):
        for noise in noises:
            ax.plot(radii, errors[shape, noise], marker="o", label=f"noise {noise}")
        ax.set(title=shape, xlabel="radius", xscale="log", yscale="log")
        _ticks_at(ax, radii)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("mean angular error (degrees)")
    axes[-1].legend()
    plt.show()


def precision_recall_panels(panels):
    """Precision and recall against a parameter, one panel per filter.

    Parameters
    ----------
    panels : list of (str, array_like of shape (M,), list of (float, float))
        The parameter's label, its values and (precision, recall) at each.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(12, 3.8), sharey=True, squeeze=False)
    axes = axes[0]
    for ax, (label, xs, pr) in zip(axes, panels):
        ax.plot(xs, [p for p, _ in pr], marker="o", label="precision")
        ax.plot(xs, [r for _, r in pr], marker="s", label="recall")
        ax.set(xlabel=label, ylim=(0, 1.02))
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("share")
    axes[0].legend()
    plt.show()


def samples_top_view(points, samples, background_step=10):
    """Samples of a cloud seen from above (blue), over every ``background_step``-th point (grey).

    Parameters
    ----------
    points : ndarray of shape (N, >= 2)
    samples : dict of str to ndarray of shape (M, >= 2)
        Panel title to the sampled points.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(samples), figsize=(12, 4.5), layout="constrained", squeeze=False)
    axes = axes[0]
    for ax, (title, sample) in zip(axes, samples.items()):
        ax.scatter(*points[::background_step, :2].T, s=1, color="0.85")
        ax.scatter(*sample[:, :2].T, s=10, color="tab:blue")
        ax.set(aspect="equal", title=title, xticks=[], yticks=[])
    plt.show()


def highlighted_samples(points, samples, highlight, zlim, background_step=10):
    """3-D views of samples of a cloud, red where ``highlight`` holds and blue elsewhere.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
    samples : dict of str to ndarray of int
        Panel title to the indices of the sampled points.
    highlight : ndarray of bool, shape (N,)
    zlim : (float, float)
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12, 4.5))
    for i, (title, sample) in enumerate(samples.items()):
        ax = new_3d_axes(fig, 1, len(samples), i + 1, title=title, elev=35)
        plot_cloud(ax, points[::background_step], color="0.85", size=0.5)
        ax.scatter(*points[sample].T, c=np.where(highlight[sample], "tab:red", "tab:blue"), s=12,
                   depthshade=False)  # fmt: skip
        ax.set_zlim(*zlim)
    plt.show()


def sampler_gallery(samples, scan_extent=((-80, 80), (-30, 30)), height_range=(-2, 6)):
    """An object (3-D, top row) and a scan (from above, bottom row) reduced by each sampler.

    Parameters
    ----------
    samples : dict of str to (ndarray of shape (M, 3), ndarray of shape (L, 3))
        Sampler name to the sampled object and the sampled scan (metres).
    """
    import matplotlib.pyplot as plt

    # One row per sampler, the object beside the scan: legible at the page's width.
    fig = plt.figure(figsize=(11, 3.6 * len(samples)))
    grid = fig.add_gridspec(len(samples), 2, width_ratios=(1, 1.6))
    for i, (name, (object_sample, scan_sample)) in enumerate(samples.items()):
        ax = new_3d_axes(fig, grid[i, 0], title=f"{name}: {len(object_sample)} points")
        plot_cloud(ax, object_sample, size=6, axis_labels=False)
        ax = fig.add_subplot(grid[i, 1])
        ax.scatter(*scan_sample[:, :2].T, s=1.5, c=scan_sample[:, 2], cmap="viridis", vmin=height_range[0],
                   vmax=height_range[1])  # fmt: skip
        ax.set(xlim=scan_extent[0], ylim=scan_extent[1], aspect="equal", title=f"{name}: {len(scan_sample)} points",
               xlabel="x (m)", ylabel="y (m)")  # fmt: skip
    plt.show()


def circle_to_ellipse(matrix, n_marked=12):
    """The unit circle and its image under a symmetric 2x2 ``matrix``, with the eigenvectors.

    Parameters
    ----------
    matrix : ndarray of shape (2, 2)
        Symmetric.
    n_marked : int
        Points marked on the circle and joined to their images, to show
        where each goes.
    """
    import matplotlib.pyplot as plt

    theta = np.linspace(0, 2 * np.pi, 400)
    circle = np.stack([np.cos(theta), np.sin(theta)])
    image = matrix @ circle
    values, vectors = np.linalg.eigh(matrix)
    fig, ax = plt.subplots(figsize=(7, 6.5))
    ax.plot(*circle, color="0.6", label="unit circle $x$")
    ax.plot(*image, color="tab:blue", label="its image $Ax$")
    marked = np.linspace(0, 2 * np.pi, n_marked, endpoint=False)
    start = np.stack([np.cos(marked), np.sin(marked)])
    end = matrix @ start
    for a, b in zip(start.T, end.T):
        ax.annotate("", b, a, arrowprops={"arrowstyle": "->", "color": "0.75", "lw": 0.8})
    for value, vector, color in zip(values, vectors.T, ("tab:orange", "tab:red")):
        ax.plot(*np.stack([-value * vector, value * vector]).T, color=color, lw=2.5,
                label=f"$\\lambda = {value:.2f}$ along $u = ({vector[0]:.2f}, {vector[1]:.2f})$")  # fmt: skip
    ax.set(aspect="equal", xlabel="$x_1$", ylabel="$x_2$")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=9, ncol=2)
    plt.show()


def accuracy_against_samples(published, measured_sizes, measured, chance, published_title, measured_title,
                             matched=None):  # fmt: skip
    """The paper's accuracies (left) beside the measured ones (right), against points per cloud.

    Parameters
    ----------
    published : dict of str to (array_like, array_like)
        Legend label to (points per cloud, accuracy in %).
    measured_sizes : array_like of shape (M,)
    measured : dict of str to array_like of shape (S, M)
        Sampler to accuracy (%) over S repetitions (seeds): drawn as the
        mean, with the band from the lowest to the highest.
    chance : float
        Accuracy of guessing (%), drawn dashed.
    matched : dict of str to (array_like, array_like of shape (S, K)), optional
        Sampler (a key of ``measured``) to (points per cloud, accuracies over
        S seeds) of the control trained on that sampler's samples: squares
        in the sampler's colour with error bars (mean, lowest to highest).
    """
    import matplotlib.pyplot as plt

    fig, (paper, ours) = plt.subplots(1, 2, figsize=(11, 4.8), sharey=True, layout="constrained")
    # One colour per sampler across both panels, and never one colour for two samplers.
    names = list(dict.fromkeys([*published, *measured]))
    colours = {name: f"C{i}" for i, name in enumerate(names)}
    for label, (sizes, values) in published.items():
        paper.semilogx(sizes, values, marker="o", label=label, color=colours[label])
    paper.set(title=published_title, xlabel="points per test cloud", ylabel="accuracy (%)")
    for name, values in measured.items():
        values = np.atleast_2d(values)
        ours.semilogx(measured_sizes, values.mean(axis=0), marker="o", label=f"{name}, trained on full",
                      color=colours[name])  # fmt: skip
        ours.fill_between(measured_sizes, values.min(axis=0), values.max(axis=0), color=colours[name], alpha=0.2)
    for name, (sizes, values) in (matched or {}).items():
        values = np.atleast_2d(values)
        mean = values.mean(axis=0)
        spread = [mean - values.min(axis=0), values.max(axis=0) - mean]
        ours.errorbar(sizes, mean, yerr=spread, fmt="s", ms=8, capsize=4, color=colours.get(name), mec="black",
                      label=f"{name}, trained on {name} samples")  # fmt: skip
    ours.axhline(chance, color="0.5", ls="--", label="chance")
    ours.set(title=measured_title, xlabel="points per test cloud")
    for ax in (paper, ours):
        ax.invert_xaxis()
        ax.grid(alpha=0.3, which="both")
    paper.legend(loc="lower left")
    ours.legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=9)
    plt.show()


def outlier_filters(points, mean_distances, threshold, k, kept, slab, extent=6.0):
    """The mean-distance histogram with a threshold, and the points each filter removes.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
    mean_distances : ndarray of shape (N,)
        Mean distance of each point to its ``k`` nearest neighbours.
    threshold : float
        The statistical filter's cut, drawn on the histogram.
    kept : dict of str to ndarray of bool, shape (N,)
        Panel title to each filter's kept mask.
    slab : ndarray of bool, shape (N,)
        The points shown (a slice of the 3-D cloud), from above.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 1 + len(kept), figsize=(15, 4.4), layout="constrained", squeeze=False)
    axes = axes[0]
    axes[0].hist(mean_distances, bins=60, color="0.5")
    axes[0].axvline(threshold, color="tab:red", label="mu + 3 sigma")
    axes[0].set(xlabel=f"mean distance d_i to the {k} nearest", ylabel="points", yscale="log")
    axes[0].legend()
    for ax, (title, keep) in zip(axes[1:], kept.items()):
        ax.scatter(*points[slab & keep, :2].T, s=3, color="0.6", label="kept")
        ax.scatter(*points[slab & ~keep, :2].T, s=10, color="tab:red", label="removed")
        ax.set(aspect="equal", title=title, xlim=(-extent, extent), ylim=(-extent, extent))
        ax.legend(loc="upper right")
    plt.show()


def filtered_images(images, clean, row, columns):
    """Images (top) and one row of each against the clean image's row (bottom).

    Parameters
    ----------
    images : dict of str to ndarray of shape (H, W)
    clean : ndarray of shape (H, W)
    row : int
        The row drawn below, marked in red above.
    columns : (int, int)
        The range of columns drawn below.
    """
    import matplotlib.pyplot as plt

    # Three to a row, each image above its row's profile: legible at the page's width.
    per_row = 3
    n_rows = -(-len(images) // per_row)
    fig, axes = plt.subplots(2 * n_rows, per_row, figsize=(11, 5.2 * n_rows), squeeze=False, layout="constrained",
                             gridspec_kw={"height_ratios": [3, 2] * n_rows})  # fmt: skip
    for ax in axes.ravel():
        ax.set_axis_off()
    for i, (label, image) in enumerate(images.items()):
        top, profile = axes[2 * (i // per_row), i % per_row], axes[2 * (i // per_row) + 1, i % per_row]
        top.set_axis_on()
        top.imshow(image, cmap="gray", vmin=0, vmax=1.2)
        top.set_title(label, fontsize=11)
        top.axhline(row, color="tab:red", lw=0.8)
        top.set(xticks=[], yticks=[])
        profile.set_axis_on()
        profile.plot(clean[row], color="0.6", lw=3, label="clean")
        profile.plot(image[row], color="tab:red", lw=1, label="filtered")
        profile.set(xlim=columns, ylim=(0, 1.1), xlabel="column")
    axes[1, 0].legend()
    plt.show()


def box_slices(clouds, slab, outline):
    """A slice of each cloud in the xz plane, over the true box's outline (grey).

    Parameters
    ----------
    clouds : dict of str to ndarray of shape (N, 3)
    slab : ndarray of bool, shape (N,)
        The points shown.
    outline : (float, float)
        The box's size along x and z, centred on the origin.
    """
    import matplotlib.pyplot as plt

    width, height = outline
    fig, axes = plt.subplots(1, len(clouds), figsize=(14, 3.8), sharey=True, squeeze=False)
    axes = axes[0]
    for ax, (label, points) in zip(axes, clouds.items()):
        ax.add_patch(plt.Rectangle((-width / 2, -height / 2), width, height, fill=False, color="0.6", lw=2))
        ax.scatter(points[slab, 0], points[slab, 2], s=2, c="tab:blue")
        ax.set(title=label, aspect="equal", xlim=(-0.6 * width, 0.6 * width), ylim=(-0.7 * height, 0.7 * height),
               xlabel="x")  # fmt: skip
    axes[0].set_ylabel("z")
    plt.show()


def kdtree_leaf_cells(tree, lower, upper):
    """The cell (a box) of every leaf of a k-d tree, clipped to ``[lower, upper]``.

    Parameters
    ----------
    tree : dict
        A k-d tree as ``pcl_course.nn.kdtree_build`` returns it.
    lower, upper : array_like of shape (D,)
        The box the root's cell is clipped to (a cell is unbounded otherwise).

    Returns
    -------
    dict of int to (ndarray, ndarray)
        Leaf node id -> (lower corner, upper corner) of its cell.
    """
    cells, stack = {}, [(0, np.asarray(lower, dtype=float), np.asarray(upper, dtype=float))]
    while stack:
        node, low, high = stack.pop()
        if tree["axis"][node] < 0:
            cells[node] = (low, high)
            continue
        axis, split = tree["axis"][node], tree["split"][node]
        left_high, right_low = high.copy(), low.copy()
        left_high[axis], right_low[axis] = split, split
        stack += [(tree["left"][node], low, left_high), (tree["right"][node], right_low, high)]
    return cells


def _box_distance(query, low, high):
    return float(np.sqrt(np.sum((np.maximum(low - query, 0) + np.maximum(query - high, 0)) ** 2)))


def bst_drawing(keys, left, right, query, neighbours, offered=None, figsize=(9, 3.6)):
    """A binary search tree drawn with each node at (in-order rank, depth).

    The query's k nearest keys are marked, and every node whose key lies
    within the k-th distance of the query is outlined: a search must read
    those, whatever its order. The other nodes a search offered, if given,
    are grey; the nodes it never read stay white.

    Parameters
    ----------
    keys : array_like of shape (N,)
    left, right : array_like of int, shape (N,)
        As ``pcl_course.nn.bst_build`` returns them.
    query : float
    neighbours : array_like of int
        The k nearest nodes (ids).
    offered : array_like of int, optional
        The nodes a search offered to its result set.
    """
    import matplotlib.pyplot as plt

    keys = np.asarray(keys, dtype=float)
    n = len(keys)
    depth = np.zeros(n, dtype=int)
    for node in range(n):  # parents come before their children
        for child in (left[node], right[node]):
            if child >= 0:
                depth[child] = depth[node] + 1
    rank = np.empty(n, dtype=int)
    rank[np.lexsort((np.arange(n), keys))] = np.arange(n)
    w = np.max(np.abs(keys[np.asarray(neighbours)] - query))
    fig, ax = plt.subplots(figsize=figsize)
    for node in range(n):
        for child in (left[node], right[node]):
            if child >= 0:
                ax.plot([rank[node], rank[child]], [-depth[node], -depth[child]], c="0.7", lw=1, zorder=1)
    must = np.abs(keys - query) <= w
    read = np.zeros(n, dtype=bool)
    if offered is not None:
        read[np.asarray(offered, dtype=int)] = True
    face = np.where(read, "0.8", "white")
    ax.scatter(rank[~must], -depth[~must], s=120, c=face[~must], edgecolors="0.5", zorder=2)
    ax.scatter(rank[must], -depth[must], s=120, c=face[must], edgecolors="tab:orange", lw=2, zorder=2)
    # The legend's entries, one per class, drawn empty (the nodes above mix the classes): the
    # outline says where a key lies, the fill what the search did with it.
    ax.scatter([], [], s=120, facecolors="none", edgecolors="0.5", label="outline: farther than w")
    ax.scatter([], [], s=120, facecolors="none", edgecolors="tab:orange", lw=2, label="outline: within w")
    if offered is not None:
        ax.scatter([], [], s=120, c="0.8", edgecolors="none", label="grey: offered by the search")
        ax.scatter([], [], s=120, c="white", edgecolors="0.8", label="white: not read")
    ax.scatter(rank[neighbours], -depth[neighbours], s=60, c="tab:orange", zorder=3, label="the k nearest")
    for node in range(n):
        ax.annotate(f"{keys[node]:g}", (rank[node], -depth[node]), xytext=(0, 9), textcoords="offset points",
                    ha="center", fontsize=8)  # fmt: skip
    position = np.interp(query, np.sort(keys), np.arange(n))
    ax.axvline(position, ls=":", c="tab:blue", label=f"query {query:g}")
    ax.set(xlabel="in-order rank (sorted keys)", ylabel="depth", yticks=-np.arange(depth.max() + 1),
           yticklabels=np.arange(depth.max() + 1))  # fmt: skip
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    plt.show()


def kdtree_partitions(panels, query, k, figsize=(11, 5.2), columns=None):
    """2-D k-d tree partitions side by side, with one query's k-nearest ball.

    Leaves whose cell meets the ball (every exact search must read them) are
    shaded; the others are the leaves a good search prunes.

    Parameters
    ----------
    panels : dict of str to (points, tree)
        Title -> a 2-D cloud (N, 2) and a k-d tree of it.
    query : array_like of shape (2,)
    k : int
    columns : int, optional
        Panels per row (all in one row by default).
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    columns = len(panels) if columns is None else columns
    rows = -(-len(panels) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=figsize, squeeze=False)
    query = np.asarray(query, dtype=float)
    for ax, (title, (points, tree)) in zip(axes.ravel(), panels.items()):
        lower, upper = points.min(axis=0), points.max(axis=0)
        radius = np.sort(np.linalg.norm(points - query, axis=1))[k - 1]
        cells = kdtree_leaf_cells(tree, lower, upper)
        met = 0
        for low, high in cells.values():
            meets = _box_distance(query, low, high) <= radius
            met += meets
            ax.add_patch(Rectangle(low, *(high - low), fill=meets, fc="tab:orange", alpha=0.25 if meets else 1,
                                   ec="0.4", lw=0.6))  # fmt: skip
        ax.scatter(points[:, 0], points[:, 1], s=2, c="k")
        ax.add_patch(Circle(query, radius, fill=False, ec="tab:blue", lw=1.5))
        ax.plot(*query, marker="*", c="tab:blue", ms=10)
        ax.set(title=f"{title}: {met} of {len(cells)} leaves meet the ball", aspect="equal")
        ax.set_xlim(lower[0], upper[0])
        ax.set_ylim(lower[1], upper[1])
    plt.show()


def kdtree_levels(points, tree, query=None, figsize=(11, 3.4)):
    """A 2-D k-d tree's splits, one level more per panel; the last panel numbers the leaves.

    Parameters
    ----------
    points : array_like of shape (N, 2)
    tree : dict
        A k-d tree of ``points`` in the layout of ``pcl_course.nn.kdtree_build``.
    query : array_like of shape (2,), optional
        Drawn as a star in the last panel.
    """
    import matplotlib.pyplot as plt

    points = np.asarray(points, dtype=float)
    lower, upper = points.min(axis=0), points.max(axis=0)
    margin = 0.05 * (upper - lower).max()
    lower, upper = lower - margin, upper + margin
    segments = []  # (depth, axis, split, cell low, cell high) of every internal node
    stack = [(0, 0, lower, upper)]
    while stack:
        node, depth, low, high = stack.pop()
        axis = tree["axis"][node]
        if axis < 0:
            continue
        split = tree["split"][node]
        segments.append((depth, axis, split, low, high))
        left_high, right_low = high.copy(), low.copy()
        left_high[axis], right_low[axis] = split, split
        stack += [(tree["left"][node], depth + 1, low, left_high), (tree["right"][node], depth + 1, right_low, high)]
    levels = 1 + max((depth for depth, *_ in segments), default=-1)
    fig, axes = plt.subplots(1, levels + 1, figsize=figsize, squeeze=False)
    for panel, ax in enumerate(axes[0]):
        for depth, axis, split, low, high in segments:
            if depth < panel:
                ends = ([split, split], [low[1], high[1]]) if axis == 0 else ([low[0], high[0]], [split, split])
                ax.plot(*ends, c=f"C{depth}", lw=1.5)
        ax.scatter(points[:, 0], points[:, 1], s=12, c="k", zorder=3)
        ax.set(xlim=(lower[0], upper[0]), ylim=(lower[1], upper[1]), aspect="equal", xticks=[], yticks=[])
        ax.set_title("the points" if panel == 0 else f"depth {panel - 1} splits", fontsize=9)
    last = axes[0][-1]
    last.set_title("leaves (node ids)", fontsize=9)
    for node, (low, high) in kdtree_leaf_cells(tree, lower, upper).items():  # a leaf's id at its cell's centre
        last.annotate(str(node), (low + high) / 2, fontsize=8, ha="center", va="center", color="tab:red",
                      bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8))  # fmt: skip
    for index, (x, y) in enumerate(points):
        axes[0][0].annotate(str(index), (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7)
    if query is not None:
        last.plot(*np.asarray(query, dtype=float), marker="*", c="tab:blue", ms=11, zorder=4)
    plt.show()


FILL_ALPHA = 0.35  # the quadtree's squares, see-through over the points (the colour bar matches it)


def quadtree_cells(points, tree, figsize=(6.5, 5.2)):
    """The leaves of an octree of a flat (z = 0) cloud, seen from above as a quadtree, coloured by depth.

    Parameters
    ----------
    points : array_like of shape (N, 2)
    tree : dict
        ``pcl_course.nn.octree_build`` of the points with a zero z column.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    points = np.asarray(points, dtype=float)
    depth = _octree_depths(tree)
    leaves = np.flatnonzero(np.all(tree["children"] < 0, axis=1))
    colours = plt.get_cmap("viridis", depth.max() + 1)
    fig, ax = plt.subplots(figsize=figsize)
    for node in leaves:
        corner, side = tree["center"][node][:2] - tree["extent"][node], 2 * tree["extent"][node]
        ax.add_patch(Rectangle(corner, side, side, fc=colours(depth[node]), alpha=FILL_ALPHA, ec="0.3", lw=0.5))
    ax.scatter(points[:, 0], points[:, 1], s=1.5, c="k")
    root = tree["center"][0][:2] - tree["extent"][0], 2 * tree["extent"][0]
    ax.set(xlim=(root[0][0], root[0][0] + root[1]), ylim=(root[0][1], root[0][1] + root[1]), aspect="equal")
    mappable = plt.cm.ScalarMappable(cmap=colours, norm=plt.Normalize(-0.5, depth.max() + 0.5))
    fig.colorbar(mappable, ax=ax, label="depth of the leaf", ticks=range(depth.max() + 1), alpha=FILL_ALPHA)
    plt.show()


def _octree_depths(tree):
    """Depth of every node of an octree in preorder (a parent before its children)."""
    depth = np.zeros(len(tree["start"]), dtype=int)
    for node, children in enumerate(tree["children"]):
        depth[children[children >= 0]] = depth[node] + 1
    return depth


def octree_cubes_trace(tree, max_depth, color="gray", name=None, width=1):
    """The edges of an octree's leaf cubes, and of its nodes at ``max_depth``, as one Plotly trace.

    Parameters
    ----------
    tree : dict
        As ``pcl_course.nn.octree_build`` returns.
    max_depth : int
        Deeper nodes are not drawn: their ancestor at this depth is.
    """
    import plotly.graph_objects as go

    depth = _octree_depths(tree)
    is_leaf = np.all(tree["children"] < 0, axis=1)
    shown = np.flatnonzero((depth == max_depth) | (is_leaf & (depth < max_depth)))
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(corners[a] != corners[b]) == 1]
    segments = []
    for node in shown:
        cube = tree["center"][node] + tree["extent"][node] * corners
        for a, b in edges:
            segments += [cube[a], cube[b], [np.nan] * 3]  # NaN rows break the line between edges
    segments = np.array(segments)
    return go.Scatter3d(x=segments[:, 0], y=segments[:, 1], z=segments[:, 2], mode="lines", name=name,
                        line=dict(color=color, width=width), hoverinfo="skip")  # fmt: skip


def octant_tests(center, extent, balls, verdicts, figsize=(6.5, 5.2)):
    """One square cell (the 2-D picture of an octant) and query balls, each labelled with its verdicts.

    Parameters
    ----------
    center : array_like of shape (2,)
    extent : float
        Half the side of the square.
    balls : list of (array_like of shape (2,), float)
        Query centres and radii.
    verdicts : list of str
        One label per ball (which of overlaps / contains / inside hold).
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    center = np.asarray(center, dtype=float)
    fig, ax = plt.subplots(figsize=figsize)
    ax.add_patch(Rectangle(center - extent, 2 * extent, 2 * extent, fill=True, fc="0.92", ec="k", lw=1.5))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for (query, radius), verdict, color in zip(balls, verdicts, colors):
        ax.add_patch(Circle(query, radius, fill=False, ec=color, lw=2, label=verdict))
        ax.plot(*query, marker="o", c=color, ms=4)
    reach = 1.05 * max(np.max(np.abs(np.asarray(q) - center)) + r for q, r in balls)  # a margin: no line clipped
    ax.set(xlim=(center[0] - reach, center[0] + reach), ylim=(center[1] - reach, center[1] + reach), aspect="equal")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    plt.show()


def root_squares(points, panels, figsize=(10, 4.6)):
    """A 2-D cloud with candidate root squares; the points each square leaves out in red.

    Parameters
    ----------
    points : ndarray of shape (N, 2)
    panels : dict of str to (array_like of shape (2,), float)
        Title -> the square's centre and half side.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    fig, axes = plt.subplots(1, len(panels), figsize=figsize, squeeze=False)
    lower, upper = points.min(axis=0), points.max(axis=0)
    for center, extent in panels.values():
        lower = np.minimum(lower, np.asarray(center) - extent)
        upper = np.maximum(upper, np.asarray(center) + extent)
    pad = 0.15 * np.max(upper - lower)
    for ax, (title, (center, extent)) in zip(axes[0], panels.items()):
        center = np.asarray(center, dtype=float)
        outside = np.any(np.abs(points - center) > extent, axis=1)
        ax.scatter(*points[~outside].T, s=3, c="0.3")
        ax.scatter(*points[outside].T, s=12, c="tab:red", label=f"outside the root: {outside.sum()}")
        ax.add_patch(Rectangle(center - extent, 2 * extent, 2 * extent, fill=False, ec="tab:blue", lw=1.5))
        ax.plot(*center, marker="+", c="tab:blue", ms=12)
        ax.set(title=title, aspect="equal", xlim=(lower[0] - pad, upper[0] + pad),
               ylim=(lower[1] - pad, upper[1] + pad))  # fmt: skip
        ax.legend(loc="lower right")
    plt.show()


def kmeans_trajectories(points, labels, centers, inertia, figsize=(11, 4.4)):
    """Lloyd's iterations on a 2-D cloud: the centres' paths over the final clusters, and the inertia.

    Parameters
    ----------
    points : array_like of shape (N, 2)
    labels : array_like of shape (N,)
        The final labels, ``0 .. K - 1``; the points are coloured by them.
    centers : array_like of shape (T + 1, K, 2)
        The centres before the first iteration (``centers[0]``, the initial ones) and after each of
        the ``T`` iterations.
    inertia : array_like of shape (T,)
        The inertia recorded at each iteration's assignment.
    """
    import matplotlib.pyplot as plt

    points, labels, centers = np.asarray(points, dtype=float), np.asarray(labels), np.asarray(centers, dtype=float)
    fig, (left, right) = plt.subplots(1, 2, figsize=figsize, gridspec_kw={"width_ratios": [1.15, 1]})
    for k in range(centers.shape[1]):
        colour = f"C{k % 10}"
        left.scatter(*points[labels == k].T, s=5, c=colour, alpha=0.35, lw=0)
        left.plot(*centers[:, k].T, c="k", lw=1.2, marker="o", ms=3)
        left.plot(*centers[0, k], marker="X", ms=10, c=colour, mec="k", label="initial centres" if k == 0 else None)
        left.plot(*centers[-1, k], marker="*", ms=15, c=colour, mec="k", label="final centres" if k == 0 else None)
    left.set(aspect="equal", title="centres after each iteration", xlabel="x", ylabel="y")
    left.legend(loc="best", fontsize=8)
    iterations = np.arange(1, len(inertia) + 1)
    right.plot(iterations, inertia, marker="o")
    right.set(yscale="log", xlabel="iteration t", ylabel="inertia (sum of squared distances)",
              title="inertia at each assignment")  # fmt: skip
    right.grid(alpha=0.3, which="both")
    fig.tight_layout()
    plt.show()


def ratio_distributions(panels, xlabel, figsize=(11, 4)):
    """Empirical distribution functions of cost ratios (one panel per stage, one curve per method).

    Parameters
    ----------
    panels : dict of str to dict of str to array_like
        Panel title -> method label -> the ratios of its runs (at least 1).
    xlabel : str
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=figsize, squeeze=False, sharey=True)
    for ax, (title, curves_) in zip(axes[0], panels.items()):
        for j, (label, ratios) in enumerate(curves_.items()):
            ratios = np.sort(np.asarray(ratios, dtype=float))
            share = np.arange(1, len(ratios) + 1) / len(ratios)
            ax.step(np.concatenate([[ratios[0]], ratios]), np.concatenate([[0.0], share]), where="post",
                    c=f"C{j}", lw=1.8, label=f"{label} (median {np.median(ratios):.2f})")  # fmt: skip
        ax.set(xscale="log", xlabel=xlabel, title=title, ylim=(0, 1.02))
        low, high = ax.get_xlim()
        ticks = [v for v in (1, 1.5, 2, 3, 5, 10, 20, 30, 50, 100, 200) if low <= v <= high]
        ax.set_xticks(ticks, [f"{v:g}" for v in ticks])  # plain numbers at a few places, no crowded 2x10^0
        ax.set_xticks([], minor=True)
        ax.set_xlim(low, high)
        ax.grid(alpha=0.3, which="both")
        ax.legend(loc="lower right", fontsize=8)
    axes[0][0].set_ylabel("share of the runs with a ratio at most x")
    fig.tight_layout()
    plt.show()


def cluster_panels(panels, columns=None, figsize=(11, 3.4)):
    """2-D clouds coloured by cluster, one panel each, with the centres as black crosses.

    Parameters
    ----------
    panels : dict of str to (array_like of shape (N, 2), array_like of shape (N,), array_like of shape (K, 2) or None)
        Title -> the points, their labels and the centres (``None``: none drawn).
    columns : int, optional
        Panels per row; default, all in one row.
    """
    import matplotlib.pyplot as plt

    columns = len(panels) if columns is None else columns
    rows = -(-len(panels) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=figsize, squeeze=False)
    for ax, (title, (points, labels, centers)) in zip(axes.flat, panels.items()):
        points, labels = np.asarray(points, dtype=float), np.asarray(labels)
        ax.scatter(points[:, 0], points[:, 1], s=4, c=[f"C{k % 10}" for k in labels], lw=0)
        if centers is not None:
            ax.scatter(*np.asarray(centers, dtype=float).T, marker="X", s=90, c="k", ec="w", lw=1)
        ax.set(title=title, aspect="equal", xticks=[], yticks=[])
    for ax in axes.flat[len(panels) :]:
        ax.axis("off")
    fig.tight_layout()
    plt.show()


def _cluster_colours(labels):
    """One colour per cluster label, light grey for noise (-1): tab20's dark colours, then its light
    ones, cycling (so that clusters 0 and 1 do not get two shades of one colour), without its two
    greys (a grey cluster would read as noise)."""
    import matplotlib.pyplot as plt

    labels = np.asarray(labels)
    dark = [i for i in range(0, 20, 2) if i != 14]  # tab20's 14 and 15 are its greys
    palette = plt.cm.tab20(np.array(dark + [i + 1 for i in dark]))
    colours = palette[np.mod(labels, len(palette))]
    colours[labels < 0] = (0.75, 0.75, 0.75, 1.0)
    return colours


def density_panels(panels, columns=None, figsize=(11, 3.6), eps=None, numbered=False):
    """2-D clouds clustered by DBSCAN, one panel each: core points filled, border points hollow, noise grey crosses.

    Parameters
    ----------
    panels : dict of str to (array_like of shape (N, 2), array_like of shape (N,), array_like of shape (N,))
        Title -> the points, their labels (-1 for noise) and whether each is a core point.
    columns : int, optional
        Panels per row; default, all in one row.
    figsize : tuple of float, default (11, 3.6)
    eps : float, optional
        If given, a dashed circle of this radius around every core point (its neighbourhood).
    numbered : bool, default False
        Write each point's index above it (for small examples).
    """
    import matplotlib.pyplot as plt

    if not panels:
        raise ValueError("panels: nothing to draw")  # before a figure exists: no empty figure is shown
    columns = len(panels) if columns is None else columns
    rows = -(-len(panels) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=figsize, squeeze=False)
    for ax, (title, (points, labels, is_core)) in zip(axes.flat, panels.items()):
        points, labels = np.asarray(points, dtype=float), np.asarray(labels)
        is_core = np.asarray(is_core, dtype=bool)
        colours = _cluster_colours(labels)
        small = len(points) <= 50
        core_size, border_size = (90, 70) if small else (9, 9)
        noise, border = labels < 0, (labels >= 0) & ~is_core
        ax.scatter(*points[is_core].T, s=core_size, c=colours[is_core], lw=0, label="core")
        ax.scatter(*points[border].T, s=border_size, facecolors="none", edgecolors=colours[border],
                   lw=1.5 if small else 0.8, label="border")  # fmt: skip
        ax.scatter(*points[noise].T, s=border_size, c="0.45", marker="x", lw=1.2 if small else 0.6, label="noise")
        if eps is not None:
            for centre, colour in zip(points[is_core], colours[is_core]):
                ax.add_patch(plt.Circle(centre, eps, fill=False, ls="--", lw=0.8, ec=colour, alpha=0.7))
        if numbered:
            for i, (x, y) in enumerate(points):
                ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(0, 8), ha="center", fontsize=8)
        ax.set(title=title, aspect="equal")
        if not small:
            ax.set(xticks=[], yticks=[])
    axes.flat[len(panels) - 1].legend(loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    for ax in axes.flat[len(panels) :]:
        ax.axis("off")
    fig.tight_layout()
    plt.show()


def k_distance_curve(distances, min_samples, marks, figsize=(7, 3.8)):
    """The k-distance plot: every point's distance to its ``min_samples``-th neighbour, sorted.

    Parameters
    ----------
    distances : array_like of shape (N,)
        Each point's distance to its ``min_samples``-th nearest point, itself counted as the first.
    min_samples : int
        For the axis label.
    marks : dict of str to float
        Label -> a radius drawn as a horizontal line (a candidate ``eps``).
    figsize : tuple of float, default (7, 3.8)
    """
    import matplotlib.pyplot as plt

    distances = np.sort(np.asarray(distances, dtype=float))
    fig, ax = plt.subplots(figsize=figsize)
    ax.plot(np.arange(len(distances)), distances, c="k", lw=1.2)
    for k, (label, radius) in enumerate(marks.items()):
        share = np.mean(distances <= radius)
        ax.axhline(radius, c=f"C{k}", ls="--", lw=1, label=f"{label}: {share:.0%} of the points are core")
    ax.set(xlabel="points, sorted by their k-distance",
           ylabel=f"distance to the {min_samples}-th nearest point\n(itself counted)")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    plt.show()


def clusters_top_view(panels, figsize=(11, 8), xlim=(-40, 40), ylim=(-14, 14), size=1.0):
    """Bird's-eye views of labelled clouds, one panel each: a colour per label, noise (-1) grey.

    Parameters
    ----------
    panels : dict of str to (array_like of shape (N, 3), array_like of shape (N,))
        Title -> the points (metres) and their labels.
    figsize : tuple of float, default (11, 8)
    xlim, ylim : tuple of float
        The window shown, metres.
    size : float, default 1.0
        The markers' area, points squared.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(panels), 1, figsize=figsize, squeeze=False)
    for ax, (title, (points, labels)) in zip(axes.flat, panels.items()):
        points, labels = np.asarray(points, dtype=float), np.asarray(labels)
        order = np.argsort(labels >= 0, kind="stable")  # noise first, under the clusters
        ax.scatter(*points[order, :2].T, s=size, c=_cluster_colours(labels[order]), lw=0)
        ax.set(title=title, xlim=xlim, ylim=ylim, aspect="equal", xlabel="x (m)", ylabel="y (m)")
    fig.tight_layout()
    plt.show()


def _covariance_ellipse(ax, mean, covariance, scale, colour, **kwargs):
    """Draw the ellipse of the points at Mahalanobis distance ``scale`` from ``mean`` (2-D)."""
    from matplotlib.patches import Ellipse

    values, vectors = np.linalg.eigh(np.asarray(covariance, dtype=float))
    angle = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1]))  # the major axis: the last eigenvector
    width, height = 2 * scale * np.sqrt(np.maximum(values[::-1], 0.0))
    ax.add_patch(Ellipse(mean, width, height, angle=angle, fill=False, ec=colour, **kwargs))


def mixture_iterations(points, panels, lower_bounds=None, final_bound=None, marks=(), columns=2, figsize=(11, 6.4)):
    """A 2-D Gaussian mixture at a few iterations of EM, beside how far each recorded bound is from the last.

    Each panel shows the points, coloured by the component of largest responsibility, and every
    component's ellipses at one and two standard deviations (the points at Mahalanobis distance 1
    and 2 from its mean), with its mean as a cross. If ``lower_bounds`` is given, the last column
    plots, on a log scale, how far the bound recorded after t iterations lies below ``final_bound``.

    Parameters
    ----------
    points : array_like of shape (N, 2) or None
        The points of every panel; ``None`` if each panel brings its own.
    panels : dict of str to tuple
        Title -> (means (K, 2), covariances (K, 2, 2) or ``None``: no ellipses, responsibilities
        (N, K) or ``None``: the points are drawn grey), optionally followed by the panel's own
        points (N, 2).
    lower_bounds : array_like of shape (T,), optional
        The average log-likelihood recorded at each iteration's E-step: ``lower_bounds[t]`` is that
        of the parameters after ``t`` iterations, ``t = 0 .. T - 1``. Default: no curve.
    final_bound : float, optional
        The average log-likelihood of the returned parameters, above every recorded bound; needed
        with ``lower_bounds``.
    marks : sequence of int, default ()
        Numbers of iterations done (``0 .. T - 1``) to mark on the curve, e.g. those the panels show.
    columns : int, default 2
        Panels per row; the curve, if any, takes one more column, over all the rows.
    figsize : tuple of float, default (11, 6.4)
    """
    import matplotlib.pyplot as plt

    if not panels:
        raise ValueError("panels: nothing to draw")  # before a figure exists: no empty figure is shown
    rows = -(-len(panels) // columns)
    fig = plt.figure(figsize=figsize)
    curved = lower_bounds is not None
    grid = fig.add_gridspec(rows, columns + curved, width_ratios=[1] * columns + [1.25] * curved)
    for j, (title, (means, covariances, responsibilities, *own)) in enumerate(panels.items()):
        ax = fig.add_subplot(grid[j // columns, j % columns])
        cloud = np.asarray(own[0] if own else points, dtype=float)
        low, high = cloud.min(axis=0), cloud.max(axis=0)
        margin = 0.05 * (high - low)
        means = np.asarray(means, dtype=float)
        if responsibilities is None:
            colours = "0.6"
        else:
            colours = [f"C{k % 10}" for k in np.argmax(np.asarray(responsibilities), axis=1)]
        ax.scatter(cloud[:, 0], cloud[:, 1], s=3, c=colours, alpha=0.4, lw=0)
        for k, mean in enumerate(means):
            if covariances is not None:
                for scale, style in ((1, "-"), (2, "--")):
                    _covariance_ellipse(ax, mean, np.asarray(covariances, dtype=float)[k], scale, "k", lw=1.2, ls=style)
            ax.plot(*mean, marker="X", ms=9, c=f"C{k % 10}", mec="k")
        ax.set(title=title, aspect="equal", xlim=(low[0] - margin[0], high[0] + margin[0]),
               ylim=(low[1] - margin[1], high[1] + margin[1]))  # fmt: skip
        ax.tick_params(labelsize=8)
    if curved:
        gaps = float(final_bound) - np.asarray(lower_bounds, dtype=float)
        curve = fig.add_subplot(grid[:, columns])
        done = np.arange(len(gaps))
        curve.plot(done, gaps, marker="o", ms=3, c="k", lw=1.2)
        shown = [t for t in marks if 0 <= t < len(gaps)]
        if shown:
            curve.plot(shown, gaps[np.array(shown)], ls="none", marker="o", ms=9, mfc="none", mec="C3",
                       label="the parameters drawn")  # fmt: skip
            curve.legend(loc="upper right", fontsize=8)
        curve.set(yscale="log", xlabel="iterations done",
                  ylabel="log-likelihood of the returned parameters\nminus the bound recorded",
                  title="recorded bounds below the\nreturned parameters' log-likelihood")  # fmt: skip
        curve.xaxis.set_major_locator(plt.MaxNLocator(integer=True))
        curve.grid(alpha=0.3, which="both")
    fig.tight_layout()
    plt.show()


def clustering_grid(clouds, results, figsize=(14, 14.5)):
    """2-D clouds clustered by several methods: one row per cloud, one column per method.

    Each panel colours the points by their label (``C0`` to ``C9``, cycling; noise, -1, black) and
    says, under it, the adjusted Rand index and the wall time of its run.

    Parameters
    ----------
    clouds : dict of str to array_like of shape (N, 2)
        Row title -> the points of that row.
    results : dict of (str, str) to (array_like of shape (N,), float, float)
        (row title, column title) -> the labels, the wall time in seconds and the adjusted Rand
        index. The columns are in the order in which they first appear; every row needs every column.
    figsize : tuple of float, default (14, 14.5)
    """
    import matplotlib.pyplot as plt

    if not clouds or not results:
        raise ValueError("clouds, results: nothing to draw")  # before a figure exists: no empty figure is shown
    columns = list(dict.fromkeys(column for _, column in results))
    panels = [[results[row, column] for column in columns] for row in clouds]  # all there, before a figure
    fig, axes = plt.subplots(len(clouds), len(columns), figsize=figsize, squeeze=False)
    for axes_row, points, shown in zip(axes, clouds.values(), panels):
        points = np.asarray(points, dtype=float)
        for ax, (labels, seconds, score) in zip(axes_row, shown):
            colours = ["k" if label < 0 else f"C{label % 10}" for label in np.asarray(labels)]
            ax.scatter(points[:, 0], points[:, 1], s=3, c=colours, lw=0)
            milliseconds = f"{seconds * 1e3:.1f}" if seconds < 0.01 else f"{seconds * 1e3:.0f}"
            ax.set(xticks=[], yticks=[], aspect="equal", adjustable="datalim")
            ax.set_xlabel(f"ARI {score:.2f}, {milliseconds} ms", fontsize=9)
    for ax, row in zip(axes[:, 0], clouds):
        ax.set_ylabel(row, fontsize=10)
    for ax, column in zip(axes[0], columns):
        ax.set_title(column, fontsize=10)
    fig.tight_layout()
    plt.show()


def _graph_segments(points, indptr, indices):
    """Each link {i, j} of a CSR graph once (i < j), as a (M, 2, 2) array of segments."""
    indptr, indices = np.asarray(indptr), np.asarray(indices)
    rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    once = rows < indices
    return np.stack([points[rows[once], :2], points[indices[once], :2]], axis=1)


def small_graph(points, indptr, indices, weights, vectors, names, figsize=(11, 3.6)):
    """A small weighted graph, its links as wide as their weights, and some eigenvectors as bars.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        Where the vertices are drawn.
    indptr, indices, weights : array_like
        The graph in CSR form (both directions of every link stored).
    vectors : array_like of shape (N, M)
        Eigenvectors, one per column; the vertices are coloured by the sign of the last one.
    names : sequence of str
        A legend entry for each column of ``vectors``.
    figsize : tuple of float, default (11, 3.6)
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    points, weights, vectors = (np.asarray(a, dtype=float) for a in (points, weights, vectors))
    indptr, indices = np.asarray(indptr), np.asarray(indices)
    rows = np.repeat(np.arange(len(points)), np.diff(indptr))
    once = rows < indices
    fig, (left, right) = plt.subplots(1, 2, figsize=figsize, gridspec_kw={"width_ratios": [1, 1.3]})
    left.add_collection(LineCollection(_graph_segments(points, indptr, indices), colors="0.5",
                                       linewidths=0.5 + 3.0 * weights[once] / weights.max()))  # fmt: skip
    for i, j, w in zip(rows[once], indices[once], weights[once]):
        left.annotate(f"{w:g}", (points[i] + points[j]) / 2, xytext=(0, 5), textcoords="offset points",
                      ha="center", fontsize=8, color="0.3")  # fmt: skip
    sign = vectors[:, -1] >= 0
    left.scatter(*points.T, s=260, c=np.where(sign, "C0", "C1"), ec="k", zorder=3)
    for i, p in enumerate(points):
        left.annotate(str(i), p, ha="center", va="center", color="w", fontsize=9, zorder=4)
    left.set(aspect="equal", xticks=[], yticks=[], title="the graph (colour: the sign of the last vector)")
    left.margins(0.15)
    width = 0.8 / vectors.shape[1]
    for m, name in enumerate(names):
        right.bar(np.arange(len(points)) + (m - (vectors.shape[1] - 1) / 2) * width, vectors[:, m], width,
                  label=name, color=f"C{m + 2}")  # fmt: skip
    right.axhline(0, c="k", lw=0.8)
    low, high = min(vectors.min(), 0.0), max(vectors.max(), 0.0)
    right.set(
        xticks=np.arange(len(points)),
        xlabel="vertex",
        ylabel="entry",
        title="eigenvectors of L",
        ylim=(low - 0.1 * (high - low), high + 0.45 * (high - low)),
    )  # room for the legend above the bars
    right.legend(fontsize=8, loc="upper center", ncol=2)
    fig.tight_layout()
    plt.show()


def spectral_panels(points, indptr, indices, eigenvalues, rows, labels, figsize=(11, 8.2)):
    """Spectral clustering of a 2-D cloud in four panels: graph, spectrum, embedding, labels.

    Parameters
    ----------
    points : array_like of shape (N, 2)
    indptr, indices : array_like
        The similarity graph in CSR form.
    eigenvalues : array_like of shape (M,)
        The smallest eigenvalues of the graph's Laplacian, increasing.
    rows : array_like of shape (N, 2)
        The rows of the embedding on the unit circle (Y), drawn with a small jitter along the circle
        so that coincident rows stay visible.
    labels : array_like of shape (N,)
        The clusters.
    figsize : tuple of float, default (11, 8.2)
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    points, rows, eigenvalues = (np.asarray(a, dtype=float) for a in (points, rows, eigenvalues))
    colours = [f"C{k % 10}" for k in np.asarray(labels)]
    fig, axes = plt.subplots(2, 2, figsize=figsize)
    graph, spectrum, embedding, clusters = axes.flat
    graph.add_collection(LineCollection(_graph_segments(points, indptr, indices), colors="0.4", linewidths=0.4))
    graph.scatter(*points.T, s=3, c="k", lw=0)
    graph.set(aspect="equal", xticks=[], yticks=[], title=f"the kNN graph: {len(indices) // 2:,} links")
    spectrum.plot(np.arange(1, len(eigenvalues) + 1), eigenvalues, "o-", c="k", ms=4)
    spectrum.set(xlabel="m", ylabel="eigenvalue m of $L_{sym}$", title="the smallest eigenvalues")
    spectrum.set_xticks(np.arange(1, len(eigenvalues) + 1))
    spectrum.grid(alpha=0.3)
    angle = np.arctan2(rows[:, 1], rows[:, 0]) + np.random.default_rng(0).normal(0, 0.04, len(rows))
    embedding.plot(np.cos(np.linspace(0, 2 * np.pi, 200)), np.sin(np.linspace(0, 2 * np.pi, 200)), c="0.8")
    embedding.scatter(np.cos(angle), np.sin(angle), s=6, c=colours, lw=0)
    embedding.set(aspect="equal", xlim=(-1.3, 1.3), ylim=(-1.3, 1.3), xlabel="$y_{i0}$", ylabel="$y_{i1}$",
                  title="the rows of Y (jittered along the circle)")  # fmt: skip
    clusters.scatter(*points.T, s=4, c=colours, lw=0)
    clusters.set(aspect="equal", xticks=[], yticks=[], title="the labels")
    fig.tight_layout()
    plt.show()


def mean_shift_paths(points, grid, density, paths, modes, bandwidth, figsize=(7.5, 5.6)):
    """Mean-shift trajectories over the contours of a 2-D density estimate.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        The data, drawn as small grey dots.
    grid : tuple of (array_like of shape (G,), array_like of shape (H,))
        The x and y coordinates at which ``density`` is given.
    density : array_like of shape (H, G)
        The density estimate on the grid (row ``j`` at ``grid[1][j]``).
    paths : list of array_like of shape (T, 2)
        Each seed's positions, its start first; drawn as a line with a dot per position.
    modes : array_like of shape (M, 2)
        Drawn as black crosses.
    bandwidth : float
        A circle of this radius around the start of the first path: the first window.
    figsize : tuple of float, default (7.5, 5.6)
    """
    import matplotlib.pyplot as plt

    points = np.asarray(points, dtype=float)
    fig, ax = plt.subplots(figsize=figsize)
    filled = ax.contourf(*grid, np.asarray(density, dtype=float), levels=12, cmap="Greys", alpha=0.55)
    fig.colorbar(filled, ax=ax, label="Epanechnikov density estimate", shrink=0.8)
    ax.scatter(*points.T, s=3, c="0.35", lw=0)
    for k, path in enumerate(paths):
        path = np.asarray(path, dtype=float)
        ax.plot(*path.T, "-o", c=f"C{k % 10}", ms=3, lw=1.4)
        ax.scatter(*path[0], s=50, facecolors="none", edgecolors=f"C{k % 10}", lw=1.5)
    if paths:
        ax.add_patch(plt.Circle(np.asarray(paths[0], dtype=float)[0], bandwidth, fill=False, ls="--", lw=1, ec="C0"))
    ax.scatter(*np.asarray(modes, dtype=float).T, marker="X", s=110, c="k", ec="w", lw=1, zorder=5)
    ax.set(aspect="equal", xlabel="x", ylabel="y")
    fig.tight_layout()
    plt.show()


def bandwidth_sweep(bandwidths, counts, panels, figsize=(11, 7.2)):
    """How many clusters mean shift finds against the bandwidth, and the clusters at a few bandwidths.

    Parameters
    ----------
    bandwidths, counts : array_like of shape (B,)
        The bandwidths tried and the number of clusters found at each (log-log axes).
    panels : dict of float to (array_like of shape (N, 2), array_like of shape (N,), array_like of shape (K, 2))
        Bandwidth -> the points, their labels and the modes, drawn in a row under the curve (and
        marked on it).
    figsize : tuple of float, default (11, 7.2)
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=figsize)
    grid = fig.add_gridspec(2, len(panels), height_ratios=[1, 1.25])
    top = fig.add_subplot(grid[0, :])
    top.plot(bandwidths, counts, "-o", c="k", ms=3, lw=1.2)
    for k, h in enumerate(panels):
        top.axvline(h, c=f"C{k}", ls="--", lw=1)
    top.set(xscale="log", yscale="log", xlabel="bandwidth h", ylabel="clusters found")
    top.grid(alpha=0.3, which="both")
    for k, (h, (points, labels, modes)) in enumerate(panels.items()):
        ax = fig.add_subplot(grid[1, k])
        points = np.asarray(points, dtype=float)
        ax.scatter(*points.T, s=4, c=_cluster_colours(labels), lw=0)
        ax.scatter(*np.asarray(modes, dtype=float).T, marker="X", s=60, c="k", ec="w", lw=0.8)
        ax.set_title(f"h = {h:g}: {len(modes)} cluster{'s' if len(modes) != 1 else ''}", color=f"C{k}")
        ax.set(aspect="equal", xticks=[], yticks=[])
    fig.tight_layout()
    plt.show()
