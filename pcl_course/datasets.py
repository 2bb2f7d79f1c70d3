"""Procedural datasets (complete): nothing is ever downloaded.

* :func:`make_shape` -- 13 shape categories sampled uniformly on their
  surface, with exact ground-truth unit normals.
* :func:`make_mini_modelnet` / :func:`load_modelnet` -- a small ModelNet40
  look-alike on disk, in the ``modelnet40_normal_resampled`` text format, so
  that code written for it runs unchanged on the real data set.
* :func:`make_street_scene` / :func:`simulate_lidar_scan` -- a street (ground,
  buildings, cars, poles, trees, pedestrians) scanned by a simulated 64-beam
  spinning lidar with Open3D's ray casting, range noise and labelled spurious
  returns.

Everything is deterministic given its ``rng`` / ``seed``.

Why the shapes are sampled analytically rather than with Open3D's
``sample_points_uniformly``: on a triangulated sphere or cylinder the facet
normals are only approximately the surface normals, and a ground truth must
be exact. Each primitive below is sampled with the probability density that
makes it uniform in surface area (rejection sampling where the area element
is not constant: torus, ellipsoid).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcl_course.validation import check_choice, check_integer, check_rng

__all__ = [
    "SHAPE_NAMES",
    "MODELNET40_NAMES",
    "make_shape",
    "normalize_unit_sphere",
    "make_mini_modelnet",
    "load_modelnet",
    "LidarScan",
    "LIDAR_CLASSES",
    "make_street_scene",
    "simulate_lidar_scan",
    "published_table",
    "CameraView",
    "KITTI_CAMERA",
    "render_street_view",
]

SHAPE_NAMES = (
    "sphere",
    "box",
    "cylinder",
    "cone",
    "torus",
    "plane",
    "ellipsoid",
    "chair",
    "table",
    "lamp",
    "airplane",
    "mug",
    "bottle",
)


# The 40 categories of ModelNet40 (Wu et al., 2015), in the data set's order. Each is a
# procedural object here: six are shared with SHAPE_NAMES (cup is the mug).
MODELNET40_NAMES = (
    "airplane", "bathtub", "bed", "bench", "bookshelf", "bottle", "bowl", "car", "chair", "cone",
    "cup", "curtain", "desk", "door", "dresser", "flower_pot", "glass_box", "guitar", "keyboard", "lamp",
    "laptop", "mantel", "monitor", "night_stand", "person", "piano", "plant", "radio", "range_hood", "sink",
    "sofa", "stairs", "stool", "table", "tent", "toilet", "tv_stand", "vase", "wardrobe", "xbox",
)  # fmt: skip
_ALL_SHAPES = tuple(dict.fromkeys(SHAPE_NAMES + MODELNET40_NAMES))


# --- primitives: uniform surface samples in a local frame -----------------


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _rejection(n, rng, propose):
    """Draw ``n`` accepted samples from ``propose(m) -> (points, normals, accept)``."""
    points, normals, count = [], [], 0
    while count < n:
        p, q, accept = propose(max(2 * (n - count), 16))
        points.append(p[accept])
        normals.append(q[accept])
        count += int(accept.sum())
    return np.concatenate(points)[:n], np.concatenate(normals)[:n]


def _sphere(n, rng, radius):
    normals = _unit(rng.standard_normal((n, 3)))
    return radius * normals, normals


def _sphere_area(radius):
    return 4.0 * np.pi * radius**2


def _ellipsoid(n, rng, axes):
    axes = np.asarray(axes, dtype=float)

    def propose(m):
        u = _unit(rng.standard_normal((m, 3)))
        # The map u -> axes * u stretches the area element by
        # prod(axes) * ||u / axes||: accept in proportion to it.
        stretch = np.linalg.norm(u / axes, axis=1)
        accept = rng.uniform(size=m) * (1.0 / axes.min()) < stretch
        return axes * u, _unit(u / axes), accept

    return _rejection(n, rng, propose)


def _ellipsoid_area(axes):
    a, b, c = axes
    p = 1.6075  # Knud Thomsen's approximation, relative error < 1.1 %
    return 4.0 * np.pi * ((a**p * b**p + a**p * c**p + b**p * c**p) / 3.0) ** (1.0 / p)


def _rectangle(n, rng, size):
    """The rectangle ``|x| <= sx/2, |y| <= sy/2`` at z = 0, normal +z."""
    xy = (rng.uniform(size=(n, 2)) - 0.5) * np.asarray(size, dtype=float)
    points = np.column_stack([xy, np.zeros(n)])
    return points, np.tile([0.0, 0.0, 1.0], (n, 1))


def _rectangle_area(size):
    return float(size[0] * size[1])


def _disk(n, rng, radius):
    """The disk of ``radius`` at z = 0, normal +z."""
    r = radius * np.sqrt(rng.uniform(size=n))
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    points = np.column_stack([r * np.cos(theta), r * np.sin(theta), np.zeros(n)])
    return points, np.tile([0.0, 0.0, 1.0], (n, 1))


def _disk_area(radius):
    return np.pi * radius**2


def _frustum(n, rng, r_bottom, r_top, height):
    """Lateral surface between z = 0 (radius ``r_bottom``) and z = ``height``.

    A cylinder when the radii are equal, a cone when ``r_top == 0``. The area
    density is proportional to the radius, so the radius is drawn by inverse
    transform of a density linear in it.
    """
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    if np.isclose(r_bottom, r_top):
        radius = np.full(n, float(r_bottom))
        z = rng.uniform(0.0, height, n)
    else:
        radius = np.sqrt(r_top**2 + rng.uniform(size=n) * (r_bottom**2 - r_top**2))
        z = height * (r_bottom - radius) / (r_bottom - r_top)
    points = np.column_stack([radius * np.cos(theta), radius * np.sin(theta), z])
    slope = (r_bottom - r_top) / height
    normals = _unit(np.column_stack([np.cos(theta), np.sin(theta), np.full(n, slope)]))
    return points, normals


def _frustum_area(r_bottom, r_top, height):
    return np.pi * (r_bottom + r_top) * np.hypot(r_bottom - r_top, height)


def _torus(n, rng, major, minor):
    """Torus around the z axis; the tube angle is drawn by rejection."""

    def propose(m):
        theta = rng.uniform(0.0, 2.0 * np.pi, m)
        phi = rng.uniform(0.0, 2.0 * np.pi, m)
        ring = major + minor * np.cos(phi)
        accept = rng.uniform(size=m) * (major + minor) < ring
        normals = np.column_stack([np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)])
        points = np.column_stack([ring * np.cos(theta), ring * np.sin(theta), minor * np.sin(phi)])
        return points, normals, accept

    return _rejection(n, rng, propose)


def _torus_area(major, minor):
    return 4.0 * np.pi**2 * major * minor


_PRIMITIVES = {
    "sphere": (_sphere, _sphere_area),
    "ellipsoid": (_ellipsoid, _ellipsoid_area),
    "rectangle": (_rectangle, _rectangle_area),
    "disk": (_disk, _disk_area),
    "frustum": (_frustum, _frustum_area),
    "torus": (_torus, _torus_area),
}


def _rotation(axis, angle):
    """Rotation matrix about ``axis`` (x, y or z) by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


_FLIP = _rotation("x", np.pi)  # turns +z into -z


@dataclass(frozen=True)
class _Part:
    kind: str
    params: tuple
    rotation: np.ndarray = None
    offset: tuple = (0.0, 0.0, 0.0)

    def area(self):
        return _PRIMITIVES[self.kind][1](*self.params)

    def sample(self, n, rng):
        points, normals = _PRIMITIVES[self.kind][0](n, rng, *self.params)
        if self.rotation is not None:
            points, normals = points @ self.rotation.T, normals @ self.rotation.T
        return points + np.asarray(self.offset, dtype=float), normals


def _box(size, center=(0.0, 0.0, 0.0)):
    """The six faces of an axis-aligned box, outward normals."""
    sx, sy, sz = size
    cx, cy, cz = center
    faces = []
    for sign in (1.0, -1.0):
        up = None if sign > 0 else _FLIP
        faces.append(_Part("rectangle", ((sx, sy),), up, (cx, cy, cz + sign * sz / 2)))
        faces.append(_Part("rectangle", ((sz, sy),), _rotation("y", sign * np.pi / 2), (cx + sign * sx / 2, cy, cz)))
        faces.append(_Part("rectangle", ((sx, sz),), _rotation("x", -sign * np.pi / 2), (cx, cy + sign * sy / 2, cz)))
    return faces


def _cylinder(radius, height, base=(0.0, 0.0, 0.0), bottom=True, top=True, rotation=None):
    """A z-aligned cylinder standing on ``base`` (then rotated about ``base``)."""
    parts = [_Part("frustum", (radius, radius, height))]
    if bottom:
        parts.append(_Part("disk", (radius,), _FLIP))
    if top:
        parts.append(_Part("disk", (radius,), None, (0.0, 0.0, height)))
    return _placed(parts, base, rotation)


def _placed(parts, offset, rotation=None):
    placed = []
    for part in parts:
        r = part.rotation if part.rotation is not None else np.eye(3)
        o = np.asarray(part.offset, dtype=float)
        if rotation is not None:
            r, o = rotation @ r, rotation @ o
        placed.append(_Part(part.kind, part.params, r, tuple(o + np.asarray(offset, dtype=float))))
    return placed


def _shape_parts(name, jitter):
    """The surface parts of a shape; ``jitter(x)`` varies a dimension."""
    j = jitter
    if name == "sphere":
        return [_Part("sphere", (j(1.0),))]
    if name == "ellipsoid":
        return [_Part("ellipsoid", ((j(1.0), j(0.6), j(0.35)),))]
    if name == "box":
        return _box((j(1.0), j(0.7), j(0.5)))
    if name == "plane":
        return [_Part("rectangle", ((j(2.0), j(1.5)),))]
    if name == "cylinder":
        h = j(1.5)
        return _cylinder(j(0.4), h, base=(0.0, 0.0, -h / 2))
    if name == "cone":
        return _cone(j, j(1.2))
    if name == "torus":
        return [_Part("torus", (j(0.8), j(0.25)))]
    if name == "chair":
        seat, leg_h, back_h, t = j(0.5), j(0.45), j(0.5), 0.05
        parts = _box((seat, seat, t), (0.0, 0.0, leg_h + t / 2))
        parts += _box((seat, t, back_h), (0.0, -(seat - t) / 2, leg_h + t + back_h / 2))
        for sx in (-1, 1):
            for sy in (-1, 1):
                parts += _box((t, t, leg_h), (sx * (seat - t) / 2, sy * (seat - t) / 2, leg_h / 2))
        return parts
    if name == "table":
        length, width, height, t, r = j(1.2), j(0.8), j(0.75), 0.05, 0.03
        parts = _box((length, width, t), (0.0, 0.0, height - t / 2))
        for sx in (-1, 1):
            for sy in (-1, 1):
                parts += _cylinder(
                    r, height - t, base=(sx * (length / 2 - 0.08), sy * (width / 2 - 0.08), 0.0), top=False
                )
        return parts
    if name == "lamp":
        pole = j(0.8)
        parts = _cylinder(j(0.15), 0.03)
        parts += _cylinder(0.015, pole, base=(0.0, 0.0, 0.03), bottom=False)
        shade_h = j(0.25)
        parts.append(_Part("frustum", (j(0.22), 0.08, shade_h), None, (0.0, 0.0, pole - 0.1)))
        return parts
    if name == "airplane":
        span, length = j(2.4), j(2.0)
        parts = [_Part("ellipsoid", ((length / 2, 0.12, 0.12),))]
        parts += _box((0.45, span, 0.03), (0.05, 0.0, 0.0))
        parts += _box((0.2, span * 0.35, 0.02), (-length / 2 + 0.15, 0.0, 0.0))
        parts += _box((0.25, 0.02, j(0.3)), (-length / 2 + 0.15, 0.0, 0.15))
        return parts
    if name == "mug":
        radius, height = j(0.4), j(0.9)
        parts = _cylinder(radius, height, top=False)
        handle = _Part("torus", (j(0.25), 0.05), _rotation("x", np.pi / 2), (radius, 0.0, height / 2))
        return parts + [handle]
    if name == "bottle":
        radius, body, shoulder, neck = j(0.3), j(1.0), j(0.3), j(0.3)
        parts = _cylinder(radius, body, top=False)
        parts.append(_Part("frustum", (radius, 0.08, shoulder), None, (0.0, 0.0, body)))
        parts += _cylinder(0.08, neck, base=(0.0, 0.0, body + shoulder), bottom=False)
        return parts
    return _modelnet_parts(name, j)


def _open_box(size, center=(0.0, 0.0, 0.0)):
    """An axis-aligned box without its top face (a tub, a basin)."""
    top = center[2] + size[2] / 2
    return [part for part in _box(size, center) if not (part.rotation is None and np.isclose(part.offset[2], top))]


def _legs(width, depth, height, thickness=0.04):
    """Four square legs under a ``width x depth`` top, from z = 0 to ``height``."""
    parts = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            at = (sx * (width - thickness) / 2, sy * (depth - thickness) / 2, height / 2)
            parts += _box((thickness, thickness, height), at)
    return parts


_ALONG_X, _ALONG_Y = _rotation("y", np.pi / 2), _rotation("x", -np.pi / 2)  # turn +z to +x, to +y


def _modelnet_parts(name, j):
    """The parts of one of the ModelNet40 categories the primitives above do not already cover."""
    if name == "bathtub":
        return _open_box((j(1.6), j(0.75), j(0.55)), (0.0, 0.0, 0.3))
    if name == "bed":
        length, width = j(2.0), j(1.4)
        parts = _box((length, width, 0.2), (0.0, 0.0, 0.2)) + _box((length, width, j(0.22)), (0.0, 0.0, 0.41))
        return parts + _box((0.08, width, j(0.9)), (-length / 2, 0.0, 0.45)) + _legs(length, width, 0.1)
    if name == "bench":
        length = j(1.5)
        parts = _box((length, j(0.4), 0.06), (0.0, 0.0, 0.45))
        return parts + [q for sx in (-1, 1) for q in _box((0.06, 0.38, 0.42), (sx * (length / 2 - 0.1), 0.0, 0.21))]
    if name == "bookshelf":
        width, depth, height = j(0.8), j(0.3), j(1.8)
        parts = [q for sx in (-1, 1) for q in _box((0.03, depth, height), (sx * width / 2, 0.0, height / 2))]
        parts += _box((width, 0.01, height), (0.0, -depth / 2, height / 2))
        for z in np.linspace(0.02, height - 0.02, 5):
            parts += _box((width, depth, 0.03), (0.0, 0.0, z))
        return parts
    if name == "bowl":
        return [_Part("frustum", (j(0.25), j(0.5), j(0.25))), _Part("disk", (j(0.25),), _FLIP)]
    if name == "car":
        length, width = j(2.0), j(0.9)
        parts = _box((length, width, 0.45), (0.0, 0.0, 0.45)) + _box((j(1.0), width - 0.1, 0.35), (-0.1, 0.0, 0.85))
        for sx in (-1, 1):
            for sy in (-1, 1):
                parts += _cylinder(0.2, 0.15, base=(sx * 0.65, sy * width / 2 - (0.15 if sy > 0 else 0), 0.2),
                                   rotation=_ALONG_Y)  # fmt: skip
        return parts
    if name == "cup":
        return _shape_parts("mug", j)
    if name == "curtain":
        width, height = j(1.6), j(2.0)
        parts = [_Part("rectangle", ((width / 4, height),), _rotation("z", a) @ _ALONG_Y, (x, 0.0, height / 2))
                 for x, a in zip(np.linspace(-0.375, 0.375, 4) * width, (0.35, -0.35, 0.35, -0.35))]  # fmt: skip
        return parts + _cylinder(0.02, width * 1.1, base=(-width * 0.55, 0.0, height + 0.03), rotation=_ALONG_X)
    if name == "desk":
        width, depth, height = j(1.4), j(0.7), j(0.75)
        parts = _box((width, depth, 0.04), (0.0, 0.0, height - 0.02))
        pedestal = (0.4, depth - 0.05, height - 0.04)
        return parts + [q for sx in (-1, 1) for q in _box(pedestal, (sx * (width / 2 - 0.2), 0.0, pedestal[2] / 2))]
    if name == "door":
        width, height = j(0.9), j(2.0)
        return _box((width, 0.05, height), (0.0, 0.0, height / 2)) + [
            _Part("sphere", (0.04,), None, (width / 2 - 0.1, 0.07, height / 2))
        ]
    if name == "dresser":
        width, depth, height = j(1.2), j(0.5), j(0.9)
        parts = _box((width, depth, height), (0.0, 0.0, 0.1 + height / 2)) + _legs(width, depth, 0.1)
        for z in np.linspace(0.25, height - 0.05, 3):
            parts += _box((width - 0.1, 0.02, 0.2), (0.0, depth / 2 + 0.01, z))
        return parts
    if name == "flower_pot":
        radius, height = j(0.3), j(0.35)
        parts = [_Part("frustum", (radius * 0.7, radius, height)), _Part("disk", (radius * 0.7,), _FLIP)]
        return parts + [_Part("ellipsoid", ((radius * 1.1, radius * 1.1, j(0.3)),), None, (0.0, 0.0, height + 0.2))]
    if name == "glass_box":
        side = j(0.6)
        return _box((side, side, j(0.6)), (0.0, 0.0, 0.3)) + _box((side * 0.9, side * 0.9, 0.02), (0.0, 0.0, 0.3))
    if name == "guitar":
        parts = [
            _Part("ellipsoid", ((j(0.4), j(0.3), 0.08),)),
            _Part("ellipsoid", ((0.3, 0.23, 0.08),), None, (0.45, 0, 0)),
        ]
        return parts + _box((j(0.9), 0.07, 0.04), (1.1, 0.0, 0.0)) + _box((0.18, 0.1, 0.03), (1.63, 0.0, 0.0))
    if name == "keyboard":
        width, depth = j(0.45), j(0.15)
        parts = _box((width, depth, 0.025), (0.0, 0.0, 0.0125))
        for x in np.linspace(-width / 2 + 0.03, width / 2 - 0.03, 12):
            for y in np.linspace(-depth / 2 + 0.025, depth / 2 - 0.025, 4):
                parts += _box((0.026, 0.026, 0.01), (x, y, 0.03))
        return parts
    if name == "laptop":
        width, depth = j(0.34), j(0.24)
        parts = _box((width, depth, 0.02), (0.0, 0.0, 0.01))
        screen = _box((width, 0.01, depth), (0.0, 0.0, depth / 2))
        return parts + _placed(screen, (0.0, -depth / 2, 0.02), _rotation("x", -0.25))
    if name == "mantel":
        width, height = j(1.6), j(1.2)
        parts = _box((width, 0.4, 0.08), (0.0, 0.0, height)) + _box((width, 0.45, 0.05), (0.0, 0.02, 0.025))
        pillar = (0.3, 0.35, height - 0.09)
        return parts + [q for sx in (-1, 1) for q in _box(pillar, (sx * (width / 2 - 0.15), 0.0, 0.05 + pillar[2] / 2))]
    if name == "monitor":
        width, height = j(0.6), j(0.36)
        parts = _box((width, 0.04, height), (0.0, 0.0, 0.3 + height / 2)) + _box((0.25, 0.18, 0.02), (0.0, 0.0, 0.01))
        return parts + _cylinder(0.03, 0.3, base=(0.0, 0.0, 0.02), bottom=False, top=False)
    if name == "night_stand":
        width = j(0.5)
        return _box((width, j(0.45), j(0.5)), (0.0, 0.0, 0.35)) + _legs(width, 0.45, 0.1)
    if name == "person":
        height = j(1.0)
        parts = [_Part("ellipsoid", ((0.18, 0.12, 0.3 * height),), None, (0.0, 0.0, 0.95 + 0.3 * height))]
        parts.append(_Part("sphere", (0.11,), None, (0.0, 0.0, 1.1 + 0.6 * height)))
        for sy in (-1, 1):
            parts += _cylinder(0.06, 0.95, base=(0.0, sy * 0.09, 0.0))
            parts += _cylinder(0.045, 0.6, base=(0.0, sy * 0.24, 0.75 + 0.3 * height))
        return parts
    if name == "piano":
        width, height = j(1.5), j(1.1)
        parts = _box((width, 0.6, height), (0.0, 0.0, 0.25 + height / 2)) + _box(
            (width - 0.1, 0.3, 0.06), (0.0, 0.45, 0.72)
        )
        return parts + [q for sx in (-1, 1) for q in _box((0.06, 0.06, 0.7), (sx * (width / 2 - 0.1), 0.55, 0.35))]
    if name == "plant":
        parts = [_Part("frustum", (0.15, j(0.2), 0.25)), _Part("disk", (0.15,), _FLIP)]
        parts += _cylinder(0.015, j(0.4), base=(0.0, 0.0, 0.25), bottom=False, top=False)
        return parts + [_Part("sphere", (j(0.3),), None, (0.0, 0.0, 0.9))]
    if name == "radio":
        width, height = j(0.4), j(0.25)
        parts = _box((width, 0.15, height), (0.0, 0.0, height / 2))
        parts.append(_Part("disk", (0.07,), _ALONG_Y, (-width / 4, 0.076, height / 2)))
        return parts + _cylinder(0.006, j(0.35), base=(width / 2 - 0.03, 0.0, height), rotation=_rotation("y", 0.4))
    if name == "range_hood":
        width = j(0.9)
        parts = [_Part("frustum", (width / 2, 0.18, j(0.3)), _rotation("z", np.pi / 4))]
        return parts + _box((0.3, 0.3, j(0.6)), (0.0, 0.0, 0.6)) + [_Part("disk", (width / 2,), _FLIP)]
    if name == "sink":
        parts = _open_box((j(0.6), j(0.45), 0.2), (0.0, 0.0, 0.8)) + _box((0.7, 0.55, 0.7), (0.0, 0.0, 0.35))
        return parts + _cylinder(0.02, 0.25, base=(0.0, -0.2, 0.9)) + _box((0.03, 0.15, 0.03), (0.0, -0.13, 1.14))
    if name == "sofa":
        length, depth = j(2.0), j(0.9)
        parts = _box((length, depth, 0.4), (0.0, 0.0, 0.2)) + _box(
            (length, 0.2, j(0.45)), (0.0, -depth / 2 + 0.1, 0.62)
        )
        return parts + [q for sx in (-1, 1) for q in _box((0.2, depth, 0.25), (sx * (length / 2 - 0.1), 0.0, 0.52))]
    if name == "stairs":
        width, rise, run = j(1.0), j(0.18), j(0.3)
        return [q for i in range(1, 6) for q in _box((width, run, rise * i), (0.0, run * i, rise * i / 2))]
    if name == "stool":
        radius, height = j(0.2), j(0.6)
        parts = _cylinder(radius, 0.05, base=(0.0, 0.0, height))
        for a in (0.0, 2 * np.pi / 3, 4 * np.pi / 3):
            parts += _cylinder(0.02, height, base=(0.7 * radius * np.cos(a), 0.7 * radius * np.sin(a), 0.0), top=False)
        return parts
    if name == "tent":
        length, half, height = j(2.0), j(0.8), j(1.1)
        slope, angle = np.hypot(half, height), np.arctan2(height, half)
        parts = [_Part("rectangle", ((length, slope),), _rotation("x", -sy * angle), (0.0, sy * half / 2, height / 2))
                 for sy in (-1, 1)]  # fmt: skip
        return parts + [_Part("rectangle", ((length, 2 * half),), _FLIP)]
    if name == "toilet":
        parts = [_Part("ellipsoid", ((j(0.2), j(0.25), 0.15),), None, (0.0, 0.05, 0.4))]
        parts += _cylinder(0.12, 0.3, top=False)
        return parts + _box((0.4, 0.18, j(0.35)), (0.0, -0.3, 0.6))
    if name == "tv_stand":
        width, depth = j(1.4), j(0.4)
        return _box((width, depth, j(0.45)), (0.0, 0.0, 0.33)) + _legs(width, depth, 0.1)
    if name == "vase":
        radius, body = j(0.3), j(0.4)
        parts = [_Part("frustum", (radius / 2, radius, body * 0.6)), _Part("disk", (radius / 2,), _FLIP)]
        parts.append(_Part("frustum", (radius, radius / 3, body), None, (0.0, 0.0, body * 0.6)))
        return parts + _cylinder(radius / 3, j(0.2), base=(0.0, 0.0, body * 1.6), bottom=False, top=False)
    if name == "wardrobe":
        width, depth, height = j(1.0), j(0.6), j(2.0)
        parts = _box((width, depth, height), (0.0, 0.0, 0.05 + height / 2)) + _legs(width, depth, 0.05)
        return parts + [
            q for sx in (-1, 1) for q in _box((0.02, 0.03, 0.3), (sx * 0.06, depth / 2 + 0.015, height / 2))
        ]
    if name == "xbox":
        width, depth, height = j(0.3), j(0.26), j(0.08)
        return _box((width, depth, height), (0.0, 0.0, height / 2)) + [
            _Part("disk", (0.04,), None, (width / 4, 0.0, height + 1e-3))
        ]
    raise AssertionError(name)


def _cone(j, height):
    radius = j(0.5)
    base = -height / 2
    return [
        _Part("frustum", (radius, 0.0, height), None, (0.0, 0.0, base)),
        _Part("disk", (radius,), _FLIP, (0.0, 0.0, base)),
    ]


def make_shape(name, n_points=2048, noise=0.0, rng=None, variation=0.0):
    """Sample a procedural shape uniformly on its surface, with exact normals.

    Parameters
    ----------
    name : str
        One of :data:`SHAPE_NAMES`: the primitives ``sphere``, ``box``,
        ``cylinder``, ``cone``, ``torus``, ``plane``, ``ellipsoid`` and the
        composite objects ``chair``, ``table``, ``lamp``, ``airplane``,
        ``mug``, ``bottle`` (unions of primitive surfaces; as in many CAD
        models, some parts overlap and their hidden faces are sampled too),
        or one of the 40 categories of :data:`MODELNET40_NAMES` (``bathtub``
        ... ``xbox``), built the same way.
    n_points : int, default 2048
    noise : float, default 0.0
        Standard deviation of isotropic Gaussian noise added to the points
        (shape units, about 1 = the object's size). Normals stay exact.
    rng : None, int or numpy.random.Generator
    variation : float, default 0.0
        Relative random variation of the shape's dimensions (0.2 = up to
        +-20 %), for several distinct instances of a category.

    Returns
    -------
    points : ndarray of float64, shape (n_points, 3)
    normals : ndarray of float64, shape (n_points, 3)
        Outward unit normals of the noise-free surface at each sample.
    """
    check_choice(name, "name", _ALL_SHAPES)
    n_points = check_integer(n_points, "n_points", low=0)
    if not np.isfinite(noise) or noise < 0:
        raise ValueError(f"noise must be a non-negative number, got {noise!r}")
    if not 0 <= variation < 1:
        raise ValueError(f"variation must be in [0, 1), got {variation!r}")
    rng = check_rng(rng)

    def jitter(x):
        return x * rng.uniform(1.0 - variation, 1.0 + variation) if variation else x

    parts = _shape_parts(name, jitter)
    areas = np.array([part.area() for part in parts])
    counts = rng.multinomial(n_points, areas / areas.sum())
    samples = [part.sample(c, rng) for part, c in zip(parts, counts) if c]
    points = np.concatenate([s[0] for s in samples]) if samples else np.empty((0, 3))
    normals = np.concatenate([s[1] for s in samples]) if samples else np.empty((0, 3))
    order = rng.permutation(n_points)  # no part-by-part ordering to exploit
    points, normals = points[order], _unit(normals[order]) if n_points else normals
    if noise:
        points = points + rng.normal(scale=noise, size=points.shape)
    return points, normals


def normalize_unit_sphere(points):
    """Centre on the centroid and scale into the unit sphere (ModelNet convention).

    Returns
    -------
    normalized : ndarray, shape (N, 3)
    centroid : ndarray, shape (3,)
    scale : float
        ``normalized = (points - centroid) / scale``.
    """
    points = np.asarray(points, dtype=float)
    centroid = points.mean(axis=0)
    scale = float(np.max(np.linalg.norm(points - centroid, axis=1)))
    return (points - centroid) / scale, centroid, scale


# --- mini ModelNet ---------------------------------------------------------


def make_mini_modelnet(root, n_per_class=4, n_test_per_class=1, n_points=2048, seed=0, classes=SHAPE_NAMES):
    """Write a small ModelNet40 look-alike to ``root``.

    The layout and file format are those of ``modelnet40_normal_resampled``:
    ``root/<class>/<class>_0001.txt`` with ``x,y,z,nx,ny,nz`` lines (objects
    centred and scaled into the unit sphere), plus
    ``modelnet40_shape_names.txt``, ``modelnet40_train.txt`` and
    ``modelnet40_test.txt``. Each object is a distinct instance (dimensions
    varied by up to 20 %).

    Returns
    -------
    root : pathlib.Path
    """
    root = Path(root)
    n_per_class = check_integer(n_per_class, "n_per_class", low=1)
    n_test_per_class = check_integer(n_test_per_class, "n_test_per_class", low=0, high=n_per_class - 1)
    rng = check_rng(seed, "seed")
    from pcl_course.io import write_modelnet_txt

    train, test = [], []
    for name in classes:
        for i in range(1, n_per_class + 1):
            object_id = f"{name}_{i:04d}"
            points, normals = make_shape(name, n_points, rng=rng, variation=0.2)
            points, _, _ = normalize_unit_sphere(points)
            write_modelnet_txt(root / name / f"{object_id}.txt", points, normals)
            (test if i > n_per_class - n_test_per_class else train).append(object_id)
    (root / "modelnet40_shape_names.txt").write_text("\n".join(classes) + "\n")
    (root / "modelnet40_train.txt").write_text("\n".join(train) + "\n")
    (root / "modelnet40_test.txt").write_text("\n".join(test) + "\n")
    return root


def load_modelnet(root, split="train", max_objects=None):
    """Load objects of a ModelNet ``*_normal_resampled`` folder (mini or real).

    Parameters
    ----------
    root : path
        A folder written by :func:`make_mini_modelnet`, or the real
        ``modelnet40_normal_resampled``.
    split : {"train", "test"}
    max_objects : int, optional
        Stop after this many objects (the real data set has 12,311).

    Returns
    -------
    objects : list of dict
        Each with ``id``, ``label`` (class name), ``points`` and ``normals``
        (float64 arrays of shape (N, 3)).
    """
    from pcl_course.io import read_modelnet_txt

    check_choice(split, "split", ("train", "test"))
    root = Path(root)
    lists = sorted(root.glob(f"modelnet*_{split}.txt"))
    if not lists:
        raise FileNotFoundError(f"no modelnet*_{split}.txt in {root}")
    objects = []
    for object_id in lists[0].read_text().split():
        if max_objects is not None and len(objects) >= max_objects:
            break
        label = object_id.rsplit("_", 1)[0]
        points, normals = read_modelnet_txt(root / label / f"{object_id}.txt")
        objects.append({"id": object_id, "label": label, "points": points, "normals": normals})
    return objects


# --- a street scene and a simulated spinning lidar ------------------------

LIDAR_CLASSES = ("ground", "building", "car", "pole", "vegetation", "pedestrian")
"""Class names of :attr:`LidarScan.labels` (spurious returns have label -1)."""

# Diffuse reflectivity per class, for the simulated intensity.
_REFLECTIVITY = {"ground": 0.25, "building": 0.45, "car": 0.7, "pole": 0.55, "vegetation": 0.35, "pedestrian": 0.3}

SENSOR_HEIGHT = 1.73  # metres above the ground, as on the KITTI car


@dataclass(frozen=True)
class LidarScan:
    """A simulated lidar scan, in the sensor frame (x forward, z up, metres).

    Attributes
    ----------
    points : ndarray of float64, shape (N, 3)
    intensity : ndarray of float64, shape (N,)
        In [0, 1]: reflectivity times the cosine of the incidence angle,
        attenuated with range.
    labels : ndarray of int64, shape (N,)
        Index into :data:`LIDAR_CLASSES`; -1 for a spurious return.
    objects : ndarray of int64, shape (N,)
        The object each return hit, numbered in the order of
        :func:`make_street_scene`'s meshes (0: the ground; a tree's trunk and
        crown are one object); -1 for a spurious return.
    normals : ndarray of float64, shape (N, 3)
        Ground-truth surface normals (facing the sensor); NaN for spurious returns.
    ring : ndarray of int64, shape (N,)
        Beam index, 0 = the highest beam.
    is_outlier : ndarray of bool, shape (N,)
        True for the spurious returns (dust, rain, multi-path).
    """

    points: np.ndarray
    intensity: np.ndarray
    labels: np.ndarray
    objects: np.ndarray
    normals: np.ndarray
    ring: np.ndarray
    is_outlier: np.ndarray

    @property
    def origin(self):
        """The sensor position, ``(3,)``: the origin of the sensor frame."""
        return np.zeros(3)


def make_street_scene(seed=0, half_length=100.0):
    """Triangle meshes of a street along the x axis, in the sensor frame.

    Ground at ``z = -SENSOR_HEIGHT``; building facades on both sides, parked
    and driving cars, poles, trees and pedestrians.

    Returns
    -------
    meshes : list of (open3d.geometry.TriangleMesh, str)
        Each mesh with its class name (one of :data:`LIDAR_CLASSES`).
    """
    import open3d as o3d

    rng = check_rng(seed, "seed")
    ground_z = -SENSOR_HEIGHT
    meshes = []

    def box(size, center, label):
        mesh = o3d.geometry.TriangleMesh.create_box(*size)
        mesh.translate(np.asarray(center, dtype=float) - np.asarray(size, dtype=float) / 2)
        meshes.append((mesh, label))

    def cylinder(radius, height, base, label):
        mesh = o3d.geometry.TriangleMesh.create_cylinder(radius, height, resolution=24)
        mesh.translate(np.asarray(base, dtype=float) + [0.0, 0.0, height / 2])
        meshes.append((mesh, label))

    extent = 1.2 * half_length
    ground = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(
            [
                [-extent, -extent, ground_z],
                [extent, -extent, ground_z],
                [extent, extent, ground_z],
                [-extent, extent, ground_z],
            ]
        ),
        o3d.utility.Vector3iVector([[0, 1, 2], [0, 2, 3]]),
    )
    meshes.append((ground, "ground"))

    for side in (-1.0, 1.0):
        x = -half_length
        while x < half_length:  # facades with gaps between buildings
            length = rng.uniform(12.0, 35.0)
            height = rng.uniform(6.0, 22.0)
            depth = 10.0
            setback = rng.uniform(9.0, 12.0)
            box(
                (length, depth, height),
                (x + length / 2, side * (setback + depth / 2), ground_z + height / 2),
                "building",
            )
            x += length + rng.uniform(1.0, 8.0)
        x = -half_length + rng.uniform(0.0, 6.0)
        while x < half_length:  # parked cars
            if rng.uniform() < 0.7:
                box((rng.uniform(3.8, 4.8), 1.8, rng.uniform(1.4, 1.7)), (x, side * 5.2, ground_z + 0.75), "car")
            x += rng.uniform(5.5, 9.0)
        for x in np.arange(-half_length + 10.0, half_length, 22.0) + rng.uniform(-2, 2):
            cylinder(0.12, 7.0, (x, side * 7.0, ground_z), "pole")
        for x in np.arange(-half_length + 21.0, half_length, 22.0) + rng.uniform(-2, 2):
            cylinder(0.2, 2.5, (x, side * 7.5, ground_z), "vegetation")
            crown = o3d.geometry.TriangleMesh.create_sphere(rng.uniform(1.5, 2.5), resolution=12)
            crown.translate([x, side * 7.5, ground_z + 4.0])
            meshes.append((crown, "vegetation"))
        for _ in range(4):
            cylinder(
                0.25,
                rng.uniform(1.6, 1.9),
                (rng.uniform(-40, 40), side * rng.uniform(6.2, 8.0), ground_z),
                "pedestrian",
            )
    for x in rng.uniform(-60.0, 60.0, 5):  # cars driving in the lanes
        if abs(x) > 6.0:
            box((4.5, 1.8, 1.5), (x, rng.choice([-1.8, 1.8]), ground_z + 0.75), "car")
    return meshes


def simulate_lidar_scan(
    seed=0, n_beams=64, n_azimuth=1800, max_range=100.0, range_noise=0.02, outlier_fraction=0.005, fov=(2.0, -24.8)
):
    """Scan the street with a simulated 64-beam spinning lidar.

    The beams are spread evenly over the vertical field of view ``fov``
    (degrees; a Velodyne HDL-64E covers +2 to -24.8), each sampled at
    ``n_azimuth`` azimuths over 360 degrees. Rays are cast with Open3D's
    ``RaycastingScene``; returns beyond ``max_range`` are dropped.

    Parameters
    ----------
    seed : int
        Seeds the scene layout, the noise and the spurious returns.
    range_noise : float
        Standard deviation of the Gaussian range noise, metres.
    outlier_fraction : float
        Spurious returns added, as a fraction of the real ones: each at a
        uniformly random range in front of a real return, along its ray.

    Returns
    -------
    LidarScan
    """
    import open3d as o3d

    rng = check_rng(seed, "seed")
    scene = o3d.t.geometry.RaycastingScene()
    label_of_geometry, object_of_geometry, n_objects, n_vegetation = {}, {}, 0, 0
    for mesh, label in make_street_scene(rng):
        geometry_id = scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
        label_of_geometry[geometry_id] = LIDAR_CLASSES.index(label)
        # The vegetation meshes come in pairs, a trunk then its crown: one tree, one object.
        crown = label == "vegetation" and n_vegetation % 2 == 1
        n_vegetation += label == "vegetation"
        object_of_geometry[geometry_id] = n_objects - 1 if crown else n_objects
        n_objects += not crown

    elevation = np.deg2rad(np.linspace(fov[0], fov[1], n_beams))
    azimuth = np.linspace(-np.pi, np.pi, n_azimuth, endpoint=False)
    el, az = np.meshgrid(elevation, azimuth, indexing="ij")
    directions = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1).reshape(-1, 3)
    ring = np.repeat(np.arange(n_beams), n_azimuth)
    rays = np.hstack([np.zeros_like(directions), directions]).astype(np.float32)
    hits = scene.cast_rays(o3d.core.Tensor(rays))
    t_hit = hits["t_hit"].numpy().astype(np.float64)
    hit = np.isfinite(t_hit) & (t_hit <= max_range)

    directions, ring, t_hit = directions[hit], ring[hit], t_hit[hit]
    geometry = hits["geometry_ids"].numpy()[hit]
    labels = np.array([label_of_geometry[g] for g in geometry], dtype=np.int64)
    objects = np.array([object_of_geometry[g] for g in geometry], dtype=np.int64)
    normals = hits["primitive_normals"].numpy()[hit].astype(np.float64)
    normals = _unit(normals)
    facing = np.sum(normals * directions, axis=1) > 0
    normals[facing] *= -1.0  # make every normal face the sensor
    cos_incidence = -np.sum(normals * directions, axis=1)

    reflectivity = np.array([_REFLECTIVITY[c] for c in LIDAR_CLASSES])[labels]
    intensity = reflectivity * cos_incidence * np.exp(-t_hit / (2.0 * max_range))
    intensity = np.clip(intensity + rng.normal(scale=0.02, size=intensity.shape), 0.0, 1.0)
    ranges = t_hit + rng.normal(scale=range_noise, size=t_hit.shape)
    points = directions * ranges[:, None]

    n_out = int(round(outlier_fraction * len(points)))
    source = rng.choice(len(points), size=n_out, replace=False)
    out_ranges = t_hit[source] * rng.uniform(0.1, 0.9, n_out)  # clearly in front of the surface
    outliers = directions[source] * out_ranges[:, None]
    n = len(points)
    return LidarScan(
        points=np.vstack([points, outliers]),
        intensity=np.concatenate([intensity, rng.uniform(0.0, 0.2, n_out)]),
        labels=np.concatenate([labels, np.full(n_out, -1, dtype=np.int64)]),
        objects=np.concatenate([objects, np.full(n_out, -1, dtype=np.int64)]),
        normals=np.vstack([normals, np.full((n_out, 3), np.nan)]),
        ring=np.concatenate([ring, ring[source]]),
        is_outlier=np.concatenate([np.zeros(n, dtype=bool), np.ones(n_out, dtype=bool)]),
    )


# --- a camera view of the street (depth completion) ---------------------------------


# KITTI's camera 2, approximately: image size (pixels), focal length and principal point (pixels).
KITTI_CAMERA = {"width": 1242, "height": 375, "focal": 721.5, "cx": 609.6, "cy": 172.9}

_ALBEDO = {
    "ground": (0.35, 0.35, 0.38),
    "building": (0.75, 0.6, 0.45),
    "car": (0.7, 0.1, 0.1),
    "pole": (0.3, 0.3, 0.3),
    "vegetation": (0.2, 0.55, 0.2),
    "pedestrian": (0.2, 0.3, 0.8),
}


@dataclass(frozen=True)
class CameraView:
    """What a pinhole camera at the lidar sees of the street.

    Attributes
    ----------
    rgb : ndarray of float64, shape (height, width, 3)
        A shaded colour image in [0, 1], with darker windows on the facades and a little noise.
    depth : ndarray of float64, shape (height, width)
        Ground-truth z-depth in metres (along the optical axis, as KITTI's), 0 where there is no
        surface within ``max_depth``.
    camera : dict
        ``width``, ``height``, ``focal``, ``cx``, ``cy`` (pixels).
    """

    rgb: np.ndarray
    depth: np.ndarray
    camera: dict


def render_street_view(seed=0, max_depth=80.0, camera=None):
    """Render :func:`make_street_scene` from the lidar's position, looking down the street (+x).

    Open3D's ray casting gives every pixel the distance to the first surface,
    its normal and its object; the depth map and a Lambert-shaded colour
    image follow from those.

    Parameters
    ----------
    seed : int, default 0
        The street (:func:`make_street_scene`) and the image noise.
    max_depth : float, default 80.0
        Metres; farther surfaces get depth 0, as in KITTI's ground truth.
    camera : dict, optional
        ``width``, ``height``, ``focal``, ``cx``, ``cy``; :data:`KITTI_CAMERA` by default.

    Returns
    -------
    CameraView
    """
    import open3d as o3d

    camera = dict(KITTI_CAMERA if camera is None else camera)
    width, height, focal, cx, cy = (camera[key] for key in ("width", "height", "focal", "cx", "cy"))
    scene = o3d.t.geometry.RaycastingScene()
    label_of = {}
    for mesh, label in make_street_scene(seed=seed):
        label_of[scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))] = label

    u, v = np.meshgrid(np.arange(width), np.arange(height))
    # Camera axes: x right, y down, z forward; the lidar frame has x forward, y left, z up.
    world = np.stack([np.ones(u.shape), -(u - cx) / focal, -(v - cy) / focal], axis=-1)
    directions = world / np.linalg.norm(world, axis=-1, keepdims=True)
    rays = np.concatenate([np.zeros_like(directions), directions], axis=-1).reshape(-1, 6).astype(np.float32)
    hits = scene.cast_rays(o3d.core.Tensor(rays))
    distance = hits["t_hit"].numpy().reshape(height, width).astype(float)
    depth = distance * directions[..., 0]
    depth[~np.isfinite(depth) | (depth > max_depth)] = 0.0

    geometry = hits["geometry_ids"].numpy().reshape(height, width)
    normals = hits["primitive_normals"].numpy().reshape(height, width, 3)
    points = directions * np.where(np.isfinite(distance), distance, 0.0)[..., None]
    light = np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8])
    rgb = np.empty((height, width, 3))
    rgb[:] = (0.6, 0.75, 0.95)  # sky
    for geometry_id, label in label_of.items():
        where = geometry == geometry_id
        colour = np.array(_ALBEDO[label]) * (0.35 + 0.65 * np.abs(normals[where] @ light))[:, None]
        if label == "building":  # a grid of darker windows
            p = points[where]
            colour[(np.mod(p[:, 0] + p[:, 1], 3.0) < 1.2) & (np.mod(p[:, 2], 3.0) > 1.2)] *= 0.45
        rgb[where] = colour
    rgb = np.clip(rgb + np.random.default_rng(seed).normal(scale=0.02, size=rgb.shape), 0.0, 1.0)
    return CameraView(rgb=rgb, depth=depth, camera=camera)


# --- published results the book cites ---------------------------------------------


# Two kinds of table, kept apart so that each can be checked for what it is:
# published/ holds byte copies of the lecture's published figures (the course's shared data),
# compiled/ holds tables this course compiled itself, each citing its public source and commit.
_TABLE_DIRS = tuple(Path(__file__).parent / "data" / kind for kind in ("published", "compiled"))


def _table_paths():
    return {path.stem: path for directory in _TABLE_DIRS for path in sorted(directory.glob("*.csv"))}


def published_table(name):
    """A table of published results shipped with the course, as columns.

    Parameters
    ----------
    name : str
        The file's name without ``.csv``, in ``pcl_course/data/published/``
        (copies of figures published with the lecture's papers) or
        ``pcl_course/data/compiled/`` (tables this course compiled from public
        sources). For example ``"snet_modelnet40_classification"`` (Dovrat et
        al., "Learning to Sample", CVPR 2019: PointNet's accuracy on ModelNet40
        when each test cloud is reduced by random sampling, FPS or S-NET).

    Returns
    -------
    columns : dict of str to ndarray of float64
        One array per column, in the file's order.
    source : str
        The file's leading ``#`` comment lines: what the numbers are, and where they were published.
    """
    paths = _table_paths()
    if name not in paths:
        raise ValueError(f"name must be one of {sorted(paths)}, got {name!r}")
    path = paths[name]
    lines = path.read_text().splitlines()
    source = " ".join(line.lstrip("# ").strip() for line in lines if line.startswith("#"))
    rows = [line.split(",") for line in lines if line and not line.startswith("#")]
    header, values = rows[0], np.array(rows[1:], dtype=float)
    return {column: values[:, j] for j, column in enumerate(header)}, source
