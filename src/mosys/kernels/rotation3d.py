"""Rotations and 3-vectors for the 3-D simulator (``kernels.bsr3d_simulate``) and its contacts
(``kernels.bsr3d_contact``): a unit quaternion's rotation matrix and a turn of it, a symmetric
3 × 3 inverse, ``R M Rᵀ``, a matrix applied to a vector, the cross product. Vectors travel as
three floats, matrices as (3, 3) arrays written into ``out``.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy")
def cross(ax, ay, az, bx, by, bz):
    """The cross product a × b (x, y, z) of a = (ax, ay, az) and b = (bx, by, bz)."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True, error_model="numpy")
def rotation_of(quaternion, out):
    """The rotation matrix (3, 3) of a unit quaternion (w, x, y, z), into out."""
    w = quaternion[0]
    x = quaternion[1]
    y = quaternion[2]
    z = quaternion[3]
    out[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    out[0, 1] = 2.0 * (x * y - w * z)
    out[0, 2] = 2.0 * (x * z + w * y)
    out[1, 0] = 2.0 * (x * y + w * z)
    out[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    out[1, 2] = 2.0 * (y * z - w * x)
    out[2, 0] = 2.0 * (x * z - w * y)
    out[2, 1] = 2.0 * (y * z + w * x)
    out[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, error_model="numpy")
def turn(quaternion, ax, ay, az):
    """Turn the unit quaternion (4,) in place by the world rotation vector (ax, ay, az), rad,
    and renormalise it (the drift correction)."""
    angle = math.sqrt(ax * ax + ay * ay + az * az)
    if angle != 0.0:  # a NaN turns it NaN (a singular inertia tensor), for the soundness test
        scale = math.sin(0.5 * angle) / angle
        dw = math.cos(0.5 * angle)
        dx = ax * scale
        dy = ay * scale
        dz = az * scale
        w = quaternion[0]
        x = quaternion[1]
        y = quaternion[2]
        z = quaternion[3]
        quaternion[0] = dw * w - dx * x - dy * y - dz * z
        quaternion[1] = dw * x + w * dx + dy * z - dz * y
        quaternion[2] = dw * y + w * dy + dz * x - dx * z
        quaternion[3] = dw * z + w * dz + dx * y - dy * x
    norm = math.sqrt(
        quaternion[0] ** 2 + quaternion[1] ** 2 + quaternion[2] ** 2 + quaternion[3] ** 2
    )
    for a in range(4):
        quaternion[a] /= norm


@njit(cache=True, error_model="numpy")
def invert_symmetric(matrix, out):
    """The inverse (3, 3) of a symmetric positive definite matrix, into out."""
    a = matrix[0, 0]
    b = matrix[0, 1]
    c = matrix[0, 2]
    d = matrix[1, 1]
    e = matrix[1, 2]
    f = matrix[2, 2]
    c00 = d * f - e * e
    c01 = c * e - b * f
    c02 = b * e - c * d
    det = a * c00 + b * c01 + c * c02
    out[0, 0] = c00 / det
    out[0, 1] = out[1, 0] = c01 / det
    out[0, 2] = out[2, 0] = c02 / det
    out[1, 1] = (a * f - c * c) / det
    out[1, 2] = out[2, 1] = (b * c - a * e) / det
    out[2, 2] = (a * d - b * b) / det


@njit(cache=True, error_model="numpy")
def conjugate(rotation, matrix, out):
    """out = rotation @ matrix @ rotation.T, all (3, 3): rotation @ (matrix @ rotation.T)."""
    for b in range(3):
        inner0 = matrix[0, 0] * rotation[b, 0]
        inner1 = matrix[1, 0] * rotation[b, 0]
        inner2 = matrix[2, 0] * rotation[b, 0]
        for d in range(1, 3):
            inner0 += matrix[0, d] * rotation[b, d]
            inner1 += matrix[1, d] * rotation[b, d]
            inner2 += matrix[2, d] * rotation[b, d]
        for a in range(3):
            out[a, b] = rotation[a, 0] * inner0 + rotation[a, 1] * inner1 + rotation[a, 2] * inner2


@njit(cache=True, error_model="numpy")
def apply(matrix, x, y, z):
    """matrix (3, 3) @ (x, y, z)."""
    return (
        matrix[0, 0] * x + matrix[0, 1] * y + matrix[0, 2] * z,
        matrix[1, 0] * x + matrix[1, 1] * y + matrix[1, 2] * z,
        matrix[2, 0] * x + matrix[2, 1] * y + matrix[2, 2] * z,
    )
