"""Normals of neighbourhoods: the closed-form smallest eigenpair of a symmetric 3x3 matrix (numba)."""

import numpy as np
from numba import njit

__all__ = ["normals_from_neighbourhoods", "patch_normal", "smallest_eigenpair"]


@njit(cache=True, inline="always")
def _eigenvector(a00, a01, a02, a11, a12, a22, value):
    """Unit null vector of ``A - value I``: the longest cross product of two of its rows."""
    r0x, r0y, r0z = a00 - value, a01, a02
    r1x, r1y, r1z = a01, a11 - value, a12
    r2x, r2y, r2z = a02, a12, a22 - value
    c01 = (r0y * r1z - r0z * r1y, r0z * r1x - r0x * r1z, r0x * r1y - r0y * r1x)
    c02 = (r0y * r2z - r0z * r2y, r0z * r2x - r0x * r2z, r0x * r2y - r0y * r2x)
    c12 = (r1y * r2z - r1z * r2y, r1z * r2x - r1x * r2z, r1x * r2y - r1y * r2x)
    d01 = c01[0] ** 2 + c01[1] ** 2 + c01[2] ** 2
    d02 = c02[0] ** 2 + c02[1] ** 2 + c02[2] ** 2
    d12 = c12[0] ** 2 + c12[1] ** 2 + c12[2] ** 2
    best, d = c01, d01
    if d02 > d:
        best, d = c02, d02
    if d12 > d:
        best, d = c12, d12
    if d == 0.0:  # A - value I is zero: every vector is an eigenvector
        return 1.0, 0.0, 0.0
    inv = 1.0 / np.sqrt(d)
    return best[0] * inv, best[1] * inv, best[2] * inv


@njit(cache=True, inline="always")
def _perpendicular(a, b):
    """Unit vector perpendicular to ``(a, b)`` (up to sign), without overflow; ``(1, 0)`` for zero."""
    if abs(a) >= abs(b):
        if a == 0.0:
            return 1.0, 0.0
        t = b / a
        s = 1.0 / np.sqrt(1.0 + t * t)
        return t * s, -s
    t = a / b
    s = 1.0 / np.sqrt(1.0 + t * t)
    return s, -t * s


@njit(cache=True, inline="always")
def _second_eigenvector(a00, a01, a02, a11, a12, a22, w, value):
    """Eigenvector of ``value`` orthogonal to the unit eigenvector ``w``: a 2x2 problem in w's complement."""
    if abs(w[0]) > abs(w[1]):
        inv = 1.0 / np.sqrt(w[0] * w[0] + w[2] * w[2])
        u = (-w[2] * inv, 0.0, w[0] * inv)
    else:
        inv = 1.0 / np.sqrt(w[1] * w[1] + w[2] * w[2])
        u = (0.0, w[2] * inv, -w[1] * inv)
    v = (w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0])
    au = (
        a00 * u[0] + a01 * u[1] + a02 * u[2],
        a01 * u[0] + a11 * u[1] + a12 * u[2],
        a02 * u[0] + a12 * u[1] + a22 * u[2],
    )
    av = (
        a00 * v[0] + a01 * v[1] + a02 * v[2],
        a01 * v[0] + a11 * v[1] + a12 * v[2],
        a02 * v[0] + a12 * v[1] + a22 * v[2],
    )
    m00 = u[0] * au[0] + u[1] * au[1] + u[2] * au[2] - value
    m01 = u[0] * av[0] + u[1] * av[1] + u[2] * av[2]
    m11 = v[0] * av[0] + v[1] * av[1] + v[2] * av[2] - value
    # Null vector (c_u, c_v) of [[m00, m01], [m01, m11]]: perpendicular to its larger row.
    if abs(m00) >= abs(m11):
        cu, cv = _perpendicular(m00, m01)
    else:
        cu, cv = _perpendicular(m01, m11)
    return (cu * u[0] + cv * v[0], cu * u[1] + cv * v[1], cu * u[2] + cv * v[2])


@njit(cache=True, nogil=True)
def smallest_eigenpair(a00, a01, a02, a11, a12, a22):
    """Smallest eigenvalue of a symmetric 3x3 matrix and a unit eigenvector of it, in closed form.

    Eberly's noniterative solver ("A Robust Eigensolver for 3x3 Symmetric
    Matrices", Geometric Tools, 2014), the one Open3D uses: scale by the
    largest entry, eigenvalues from the trigonometric solution of the
    characteristic cubic, then the eigenvector of the *better separated*
    extreme eigenvalue from cross products, the middle one from a 2x2 problem
    in its orthogonal complement, and the remaining one as their cross
    product. Solving for the separated eigenvalue first keeps flat patches
    (two large, one tiny eigenvalue) and lines (one large, two tiny) accurate;
    the returned eigenvalue is the Rayleigh quotient of the eigenvector.

    Returns
    -------
    value : float
    nx, ny, nz : float
    """
    scale = max(abs(a00), abs(a01), abs(a02), abs(a11), abs(a12), abs(a22))
    if scale == 0.0:
        return 0.0, 1.0, 0.0, 0.0
    a00, a01, a02, a11, a12, a22 = a00 / scale, a01 / scale, a02 / scale, a11 / scale, a12 / scale, a22 / scale
    q = (a00 + a11 + a22) / 3.0
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    p = np.sqrt((b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * (a01 * a01 + a02 * a02 + a12 * a12)) / 6.0)
    if p == 0.0:  # a multiple of the identity
        return q * scale, 1.0, 0.0, 0.0
    c00 = b11 * b22 - a12 * a12
    c01 = a01 * b22 - a12 * a02
    c02 = a01 * a12 - b11 * a02
    half_det = (b00 * c00 - a01 * c01 + a02 * c02) / (2.0 * p * p * p)
    half_det = min(max(half_det, -1.0), 1.0)
    angle = np.arccos(half_det) / 3.0
    beta2 = 2.0 * np.cos(angle)
    beta0 = 2.0 * np.cos(angle + 2.0 * np.pi / 3.0)
    beta1 = -(beta0 + beta2)
    value0, value1, value2 = q + p * beta0, q + p * beta1, q + p * beta2
    if half_det >= 0.0:  # the largest eigenvalue is the separated one
        w2 = _eigenvector(a00, a01, a02, a11, a12, a22, value2)
        w1 = _second_eigenvector(a00, a01, a02, a11, a12, a22, w2, value1)
        n = (w1[1] * w2[2] - w1[2] * w2[1], w1[2] * w2[0] - w1[0] * w2[2], w1[0] * w2[1] - w1[1] * w2[0])
    else:
        n = _eigenvector(a00, a01, a02, a11, a12, a22, value0)
    # The trigonometric root loses half the digits at a double root (a line:
    # two eigenvalues zero); the Rayleigh quotient of the accurate vector
    # does not.
    rayleigh = (
        a00 * n[0] * n[0]
        + a11 * n[1] * n[1]
        + a22 * n[2] * n[2]
        + 2.0 * (a01 * n[0] * n[1] + a02 * n[0] * n[2] + a12 * n[1] * n[2])
    )
    return rayleigh * scale, n[0], n[1], n[2]


@njit(cache=True, nogil=True)
def patch_normal(points, members, start, stop):
    """Normal and curvature of the neighbourhood ``points[members[start:stop]]`` (at least 3 points).

    Two-pass covariance (centred on the neighbourhood's own mean before
    multiplying), so that coordinates far from the origin do not cancel
    catastrophically; then the closed-form smallest eigenpair.

    Returns
    -------
    nx, ny, nz, curvature : float
    """
    count = stop - start
    mx = my = mz = 0.0
    for j in range(start, stop):
        p = members[j]
        mx += points[p, 0]
        my += points[p, 1]
        mz += points[p, 2]
    mx, my, mz = mx / count, my / count, mz / count
    sxx = sxy = sxz = syy = syz = szz = 0.0
    for j in range(start, stop):
        p = members[j]
        dx, dy, dz = points[p, 0] - mx, points[p, 1] - my, points[p, 2] - mz
        sxx += dx * dx
        sxy += dx * dy
        sxz += dx * dz
        syy += dy * dy
        syz += dy * dz
        szz += dz * dz
    value, nx, ny, nz = smallest_eigenpair(sxx, sxy, sxz, syy, syz, szz)
    trace = sxx + syy + szz
    return nx, ny, nz, (max(value, 0.0) / trace if trace > 0.0 else 0.0)


@njit(cache=True)
def normals_from_neighbourhoods(points, members, offsets):
    """Normal and curvature of every neighbourhood ``members[offsets[i]:offsets[i+1]]``; NaN below 3 points."""
    n = offsets.shape[0] - 1
    normals = np.full((n, 3), np.nan)
    curvature = np.full(n, np.nan)
    for i in range(n):
        if offsets[i + 1] - offsets[i] >= 3:
            normals[i, 0], normals[i, 1], normals[i, 2], curvature[i] = patch_normal(
                points, members, offsets[i], offsets[i + 1]
            )
    return normals, curvature
