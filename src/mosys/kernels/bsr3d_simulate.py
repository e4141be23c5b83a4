"""The BSR simulator of the 1995 paper carried to 3-D (§4 on §2.1.1), one step at a time.

Frames: world x forward (a figure faces +x at t = 0), y up, z completing a right-handed frame;
the floor is the plane y = ``floor``. Every rod has a frame whose x axis runs along the rod,
proximal to distal. The root rod's frame is the body frame; a child rod's frame is
``R_child = R_parent @ rest @ Rz(θ) @ Ry(ψ)``, where ``rest = Rz(offset) @ Ry(splay)`` is the
joint's fixed orientation and (θ, ψ) its two angles (the 1995 paper's Figure 6): θ turns the rod
about its rest frame's z axis, in the plane of a 2-D figure; ψ then turns it about its own y axis,
out of that plane. ``Rz(a) = [[c, -s, 0], [s, c, 0], [0, 0, 1]]``, ``Ry(b) = [[c, 0, s], [0, 1,
0], [-s, 0, c]]``. With every ψ and splay 0 a figure stays in its x-y plane and moves as the 2-D
simulator moves it.

The figure is otherwise a rigid body, as in 2-D: a deformation leaves its centre of mass, linear
momentum and angular momentum ``L`` (about the centre of mass, world frame) unchanged, and the
body frame turns at ``I⁻¹ (L - h)``, where ``I`` is the deformed figure's inertia tensor and ``h``
the angular momentum of the deformation itself (the 2-D step's correction, split the same way:
the deformation's own spin, averaged over the step, then the rigid spin ``I⁻¹ L`` at the half
step). The orientation is a unit quaternion (body to world), renormalised every step. Gravity
and ground contact act on the rigid figure: impulses at every rod endpoint that would end the
step on the floor (up to ``MAX_CONTACTS``, the lowest first), with the paper's friction carried
to 3-D: a lone contact does not slide; several take horizontal impulses in the ratio of their
normal impulses, sized so that their normal-impulse-weighted horizontal velocity is zero (a
fixed point over the weights: each iteration a symmetric positive definite solve, its normal
block inverted once; Anderson mixing of the weights, where the plain iteration would take two to
five times as many, except for two contacts with no z in their offsets from the centre of mass
or their velocities, which iterate plainly as the 2-D rule does). Contacts whose normal impulse
would pull are dropped one at a time, then each is tried alone, stopped dead; where no set of
the friction rule pushes, the normal impulses alone (no friction for that step) stop the
sinking ones. An endpoint that still ends the step below the floor lifts
the figure out of it, and an endpoint alone on the floor is stopped and held where it stood, as
in 2-D.

State vector (S = 13 + 2J): ``c`` (3, m), ``v`` (3, m/s), the orientation quaternion ``q`` (w,
x, y, z), ``L`` (3, kg m²/s, world), ``θ`` (J, rad), ``θ'`` (J, rad/s).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from mosys.kernels.bsr_simulate import CONTACT_TOLERANCE, deform_joints, lowest_on_floor

CX, CY, CZ, VX, VY, VZ = 0, 1, 2, 3, 4, 5
QW = 6  # quaternion w, x, y, z
LX = 10  # angular momentum x, y, z
JOINTS = 13  # θ starts here, θ' follows it
MAX_CONTACTS = 4  # the lowest endpoints solved together (a body needs three on a plane)
COMPLIANCE = 1e-6  # of a contact's own response: splits loads the rigid body leaves undecided
FIXED_POINT_ITERATIONS = 50  # of the shared-friction shares
# a twist whose horizontal impulse at some contact exceeds its normal impulse this many times is
# not used (the shares of a contact that barely touches cannot stop a spin): slide only then
TWIST_RATIO = 1.0
# m: the margin by which an endpoint must clear the contact tolerance, however fast it falls, to
# be passed over without computing its motion (rounding there is far smaller)
PASS_OVER_MARGIN = 1e-9


class FigureArrays3D(NamedTuple):
    """A 3-D figure as the kernels take it: N rods in an order where every parent precedes its
    children, J = 2 (N - 1) joint angles (θ then ψ of each non-root rod's joint, in rod order),
    E distinct endpoints, and the world it moves in. A fixed angle has joint_min == joint_max; a
    one-angle ``hinge`` in a 3-D figure is a joint whose ψ is fixed at 0."""

    parent: np.ndarray  # (N,) int64: each rod's parent, -1: the root
    hinge: np.ndarray  # (N,) m: where the rod hangs on its parent, from the parent's proximal end
    rest: np.ndarray  # (N, 3, 3): fixed rotation Rz(offset) @ Ry(splay) (root: in the body frame)
    length: np.ndarray  # (N,) m
    mass: np.ndarray  # (N,) kg
    com: np.ndarray  # (N,): the rod's centre of mass, a fraction from proximal to distal
    inertia: np.ndarray  # (N,) kg m² about a transverse axis through the rod's centre of mass
    joint: np.ndarray  # (N,) int64: index of the rod's θ in the angle vector (ψ follows), -1: root
    endpoints: np.ndarray  # (E, 2) int64: rod and end (0 proximal, 1 distal) of each endpoint
    joint_min: np.ndarray  # (J,) rad
    joint_max: np.ndarray  # (J,) rad
    gravity: float  # m/s², positive
    floor: float  # m: the floor's height (nan: no floor)
    reach: float  # m: the sum of the rods' lengths


@njit(cache=True)
def new_scratch(n_rods):
    """The (N, 7, 3) scratch of ``body_frame``, its angle memory empty (NaN: never seen)."""
    return np.full((n_rods, 7, 3), np.nan)


@njit(cache=True, error_model="numpy")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True, inline="always", error_model="numpy")
def joint_trig(parent, joint, theta, scratch):
    """Keep each rod's joint angles' cosines and sines in the last two rows of ``scratch`` (N,
    7, 3; ``new_scratch``): row 5 (θ, cos θ, sin θ), row 6 (ψ, cos ψ, sin ψ), recomputed only for
    angles that moved since the last call (fixed ones never do). theta (J,) rad."""
    for k in range(parent.shape[0]):
        if parent[k] < 0:
            continue
        j = joint[k]
        if theta[j] != scratch[k, 5, 0]:
            scratch[k, 5, 0] = theta[j]
            scratch[k, 5, 1] = math.cos(theta[j])
            scratch[k, 5, 2] = math.sin(theta[j])
        if theta[j + 1] != scratch[k, 6, 0]:
            scratch[k, 6, 0] = theta[j + 1]
            scratch[k, 6, 1] = math.cos(theta[j + 1])
            scratch[k, 6, 2] = math.sin(theta[j + 1])


@njit(cache=True, inline="always", error_model="numpy")
def body_frame(
    parent,
    hinge,
    rest,
    length,
    mass,
    com,
    inertia,
    joint,
    endpoints,
    theta,
    theta_rate,
    rod_ends,
    end_offset,
    end_velocity,
    frames,
    scratch,
    tensor,
    spin,
):
    """The deformed figure in its body frame, about its centre of mass.

    Fills frames (N, 3, 3): each rod's frame in the body frame (columns: its axes, the first
    along the rod); rod_ends (N, 2, 3): each rod's proximal and distal end relative to the
    centre of mass, m; end_offset, end_velocity (E, 3): each distinct endpoint's position relative
    to the centre of mass (m) and its velocity from the deformation alone (m/s); tensor (3, 3):
    the inertia tensor about the centre of mass, kg m²; spin (3,): the deformation's angular
    momentum about the centre of mass, kg m²/s. scratch: (N, 7, 3) work space from
    ``new_scratch`` (its last two rows keep each rod's angles' cosines and sines between calls).
    Returns the total mass, kg. theta, theta_rate (J,): rad, rad/s.
    """
    n = parent.shape[0]
    joint_trig(parent, joint, theta, scratch)
    omega = scratch[:, 0]
    proximal = scratch[:, 1]
    proximal_velocity = scratch[:, 2]
    centre = scratch[:, 3]
    centre_velocity = scratch[:, 4]
    trig_theta = scratch[:, 5]
    trig_psi = scratch[:, 6]
    total_mass = 0.0
    mass_x = mass_y = mass_z = 0.0
    momentum_x = momentum_y = momentum_z = 0.0
    for k in range(n):
        p = parent[k]
        if p < 0:
            for a in range(3):
                for b in range(3):
                    frames[k, a, b] = rest[k, a, b]
                omega[k, a] = 0.0
                proximal[k, a] = 0.0
                proximal_velocity[k, a] = 0.0
        else:
            j = joint[k]
            ct = trig_theta[k, 1]
            st = trig_theta[k, 2]
            cp = trig_psi[k, 1]
            sp = trig_psi[k, 2]
            wx = omega[p, 0]
            wy = omega[p, 1]
            wz = omega[p, 2]
            hx = hinge[k] * frames[p, 0, 0]
            hy = hinge[k] * frames[p, 1, 0]
            hz = hinge[k] * frames[p, 2, 0]
            vx, vy, vz = _cross(wx, wy, wz, hx, hy, hz)
            proximal[k, 0] = proximal[p, 0] + hx
            proximal[k, 1] = proximal[p, 1] + hy
            proximal[k, 2] = proximal[p, 2] + hz
            proximal_velocity[k, 0] = proximal_velocity[p, 0] + vx
            proximal_velocity[k, 1] = proximal_velocity[p, 1] + vy
            proximal_velocity[k, 2] = proximal_velocity[p, 2] + vz
            for a in range(3):
                # row a of A = frames[p] @ rest[k], then of A @ Rz(θ) @ Ry(ψ)
                a0 = frames[p, a, 0] * rest[k, 0, 0]
                a1 = frames[p, a, 0] * rest[k, 0, 1]
                a2 = frames[p, a, 0] * rest[k, 0, 2]
                for c in range(1, 3):
                    a0 += frames[p, a, c] * rest[k, c, 0]
                    a1 += frames[p, a, c] * rest[k, c, 1]
                    a2 += frames[p, a, c] * rest[k, c, 2]
                b0 = ct * a0 + st * a1
                b1 = ct * a1 - st * a0
                frames[k, a, 0] = cp * b0 - sp * a2
                frames[k, a, 1] = b1
                frames[k, a, 2] = sp * b0 + cp * a2
                omega[k, a] = omega[p, a] + a2 * theta_rate[j] + b1 * theta_rate[j + 1]
        arm = com[k] * length[k]
        ux = frames[k, 0, 0]
        uy = frames[k, 1, 0]
        uz = frames[k, 2, 0]
        vx, vy, vz = _cross(omega[k, 0], omega[k, 1], omega[k, 2], arm * ux, arm * uy, arm * uz)
        gx = proximal[k, 0] + arm * ux
        gy = proximal[k, 1] + arm * uy
        gz = proximal[k, 2] + arm * uz
        centre[k, 0] = gx
        centre[k, 1] = gy
        centre[k, 2] = gz
        centre_velocity[k, 0] = proximal_velocity[k, 0] + vx
        centre_velocity[k, 1] = proximal_velocity[k, 1] + vy
        centre_velocity[k, 2] = proximal_velocity[k, 2] + vz
        total_mass += mass[k]
        mass_x += mass[k] * gx
        mass_y += mass[k] * gy
        mass_z += mass[k] * gz
        momentum_x += mass[k] * centre_velocity[k, 0]
        momentum_y += mass[k] * centre_velocity[k, 1]
        momentum_z += mass[k] * centre_velocity[k, 2]
    cx = mass_x / total_mass
    cy = mass_y / total_mass
    cz = mass_z / total_mass
    cvx = momentum_x / total_mass
    cvy = momentum_y / total_mass
    cvz = momentum_z / total_mass
    tensor[:, :] = 0.0
    spin[:] = 0.0
    for k in range(n):
        m = mass[k]
        rx = centre[k, 0] - cx
        ry = centre[k, 1] - cy
        rz = centre[k, 2] - cz
        ux = frames[k, 0, 0]
        uy = frames[k, 1, 0]
        uz = frames[k, 2, 0]
        i_rod = inertia[k]
        squared = m * (rx * rx + ry * ry + rz * rz) + i_rod
        tensor[0, 0] += squared - m * rx * rx - i_rod * ux * ux
        tensor[1, 1] += squared - m * ry * ry - i_rod * uy * uy
        tensor[2, 2] += squared - m * rz * rz - i_rod * uz * uz
        tensor[0, 1] -= m * rx * ry + i_rod * ux * uy
        tensor[0, 2] -= m * rx * rz + i_rod * ux * uz
        tensor[1, 2] -= m * ry * rz + i_rod * uy * uz
        hx, hy, hz = _cross(
            rx,
            ry,
            rz,
            centre_velocity[k, 0] - cvx,
            centre_velocity[k, 1] - cvy,
            centre_velocity[k, 2] - cvz,
        )
        wx = omega[k, 0]
        wy = omega[k, 1]
        wz = omega[k, 2]
        along = ux * wx + uy * wy + uz * wz
        spin[0] += m * hx + i_rod * (wx - along * ux)
        spin[1] += m * hy + i_rod * (wy - along * uy)
        spin[2] += m * hz + i_rod * (wz - along * uz)
        rod_ends[k, 0, 0] = proximal[k, 0] - cx
        rod_ends[k, 0, 1] = proximal[k, 1] - cy
        rod_ends[k, 0, 2] = proximal[k, 2] - cz
        for a in range(3):
            rod_ends[k, 1, a] = rod_ends[k, 0, a] + length[k] * frames[k, a, 0]
    tensor[1, 0] = tensor[0, 1]
    tensor[2, 0] = tensor[0, 2]
    tensor[2, 1] = tensor[1, 2]
    for e in range(endpoints.shape[0]):
        k = endpoints[e, 0]
        end = endpoints[e, 1]
        reach = length[k] * end
        vx, vy, vz = _cross(
            omega[k, 0],
            omega[k, 1],
            omega[k, 2],
            reach * frames[k, 0, 0],
            reach * frames[k, 1, 0],
            reach * frames[k, 2, 0],
        )
        end_offset[e, 0] = rod_ends[k, end, 0]
        end_offset[e, 1] = rod_ends[k, end, 1]
        end_offset[e, 2] = rod_ends[k, end, 2]
        end_velocity[e, 0] = proximal_velocity[k, 0] + vx - cvx
        end_velocity[e, 1] = proximal_velocity[k, 1] + vy - cvy
        end_velocity[e, 2] = proximal_velocity[k, 2] + vz - cvz
    return total_mass


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


@njit(cache=True, inline="always", error_model="numpy")
def rigid_rate(state, rotation, world_inverse, spin):
    """The body's angular velocity (x, y, z), rad/s, world: I⁻¹ (L - h), L the state's (S,)
    angular momentum and h the deformation's own (spin (3,), body frame, turned to the world by
    rotation (3, 3)); world_inverse (3, 3): the inverse inertia tensor in the world."""
    hx, hy, hz = apply(rotation, spin[0], spin[1], spin[2])
    return apply(world_inverse, state[LX] - hx, state[LX + 1] - hy, state[LX + 2] - hz)


@njit(cache=True, inline="always", error_model="numpy")
def endpoint_position(state, rotation, end_offset, e):
    """World (x, y, z) of endpoint e, m, from its offset from the centre of mass in the body
    frame (end_offset (E, 3)) and the body's orientation (rotation (3, 3))."""
    x, y, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
    return state[CX] + x, state[CY] + y, state[CZ] + z


@njit(cache=True, inline="always", error_model="numpy")
def endpoint_motion(state, rotation, body_rate, end_offset, end_velocity, e):
    """Endpoint e's offset (rx, ry, rz) from the centre of mass in the world, m, and its
    velocity (ux, uy, uz), m/s: the body's motion (velocity of the centre of mass, rotation at
    body_rate (3,) rad/s, world) plus the deformation's own (end_velocity (E, 3), body frame)."""
    rx, ry, rz = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
    dx, dy, dz = apply(rotation, end_velocity[e, 0], end_velocity[e, 1], end_velocity[e, 2])
    wx, wy, wz = _cross(body_rate[0], body_rate[1], body_rate[2], rx, ry, rz)
    return rx, ry, rz, state[VX] + wx + dx, state[VY] + wy + dy, state[VZ] + wz + dz


@njit(cache=True, inline="always", error_model="numpy")
def place_in_world(state, rotation, body_ends, out):
    """Every rod's ends in the world, m: body_ends (N, 2, 3) relative to the centre of mass in
    the body frame, turned by the body's orientation rotation (3, 3) and moved to the state's
    centre of mass; written to out (N, 2, 3), which may be body_ends itself (as the 2-D
    ``bsr_simulate.place_in_world``)."""
    for k in range(body_ends.shape[0]):
        for end in range(2):
            x, y, z = apply(
                rotation, body_ends[k, end, 0], body_ends[k, end, 1], body_ends[k, end, 2]
            )
            out[k, end, 0] = state[CX] + x
            out[k, end, 1] = state[CY] + y
            out[k, end, 2] = state[CZ] + z


@njit(cache=True, inline="always", error_model="numpy")
def largest_fall(state, body_rate, end_velocity, reach, dt):
    """How far any endpoint can fall in a step of dt s at most, m (>= 0): an endpoint's vertical
    velocity is the centre of mass's (the state's (S,)) plus the body's spin (body_rate (3,)
    rad/s, world) across its offset from the centre of mass, which is at most the figure's reach
    (m: the sum of its rods' lengths), plus its deformation velocity (end_velocity (E, 3) m/s,
    any frame: only the fastest's length counts)."""
    fastest = 0.0
    for e in range(end_velocity.shape[0]):
        fastest = max(
            fastest, end_velocity[e, 0] ** 2 + end_velocity[e, 1] ** 2 + end_velocity[e, 2] ** 2
        )
    turning = math.sqrt(body_rate[0] ** 2 + body_rate[1] ** 2 + body_rate[2] ** 2)
    return max(0.0, -state[VY] + turning * reach + math.sqrt(fastest)) * dt


@njit(cache=True, inline="always", error_model="numpy")
def spin_per_impulse(r, j, world_inverse, spins):
    """spins[j] (3, 3): column b the body's change of spin (rad/s, world) per unit impulse along
    axis b at a point with offset r[j] (3,) from the centre of mass, for a rigid body of inverse
    inertia world_inverse (3, 3): I⁻¹ [r_j]x (the part of ``response`` that does not depend on
    the point that moves, made once for every point it is paired with)."""
    for b in range(3):
        ex = 1.0 if b == 0 else 0.0
        ey = 1.0 if b == 1 else 0.0
        ez = 1.0 if b == 2 else 0.0
        tx, ty, tz = _cross(r[j, 0], r[j, 1], r[j, 2], ex, ey, ez)
        spins[j, 0, b], spins[j, 1, b], spins[j, 2, b] = apply(world_inverse, tx, ty, tz)


@njit(cache=True, inline="always", error_model="numpy")
def response(r, i, j, inverse_mass, spins, responses):
    """responses[i, j] (3, 3): the velocity change at a point with offset r[i] (3,) from the
    centre of mass per unit impulse at a point with offset r[j], for a rigid body of inverse
    mass inverse_mass whose spin per impulse at r[j] is spins[j] (``spin_per_impulse``):
    E/M - [r_i]x I⁻¹ [r_j]x."""
    for b in range(3):
        ex = 1.0 if b == 0 else 0.0
        ey = 1.0 if b == 1 else 0.0
        ez = 1.0 if b == 2 else 0.0
        sx, sy, sz = spins[j, 0, b], spins[j, 1, b], spins[j, 2, b]
        vx, vy, vz = _cross(sx, sy, sz, r[i, 0], r[i, 1], r[i, 2])
        responses[i, j, 0, b] = vx + inverse_mass * ex
        responses[i, j, 1, b] = vy + inverse_mass * ey
        responses[i, j, 2, b] = vz + inverse_mass * ez


@njit(cache=True, inline="always", error_model="numpy")
def _mix_shares(weight, active, count, mixing, stored):
    """Anderson mixing of the shared-friction shares: weight (count,) holds the plain update g
    of the active points' shares; mixing[0, :stored] and mixing[1, :stored] the last changes of
    g and of its residual f = g - w, mixing[:2, MAX_CONTACTS - 1] the last g and f. The shares
    become g - ΔG γ with γ the least-squares fit of f by ΔF (for a nearly affine map in n - 1
    free shares, as this one is, that converges in about n iterations where the plain update
    shrinks the residual only 5 to 10 times an iteration). Kept plain when the fit is
    degenerate or a share would not stay positive. mixing[2]: work space."""
    if stored == 0:
        return
    last = MAX_CONTACTS - 1
    for a in range(stored):
        for b in range(a + 1):
            total = 0.0
            for i in range(count):
                if active[i]:
                    total += mixing[1, a, i] * mixing[1, b, i]
            mixing[2, a, b] = total
        total = 0.0
        for i in range(count):
            if active[i]:
                total += mixing[1, a, i] * mixing[1, last, i]
        mixing[2, a, last] = total
    largest = 0.0
    for a in range(stored):
        largest = max(largest, mixing[2, a, a])
    # Cholesky of the normal equations in place, then γ in mixing[2, :stored, last]
    for a in range(stored):
        for b in range(a):
            total = mixing[2, a, b]
            for c in range(b):
                total -= mixing[2, a, c] * mixing[2, b, c]
            mixing[2, a, b] = total / mixing[2, b, b]
        total = mixing[2, a, a]
        for c in range(a):
            total -= mixing[2, a, c] * mixing[2, a, c]
        if not total > 1e-12 * largest:
            return
        mixing[2, a, a] = math.sqrt(total)
        total = mixing[2, a, last]
        for c in range(a):
            total -= mixing[2, a, c] * mixing[2, c, last]
        mixing[2, a, last] = total / mixing[2, a, a]
    for a in range(stored - 1, -1, -1):
        total = mixing[2, a, last]
        for c in range(a + 1, stored):
            total -= mixing[2, c, a] * mixing[2, c, last]
        mixing[2, a, last] = total / mixing[2, a, a]
    for i in range(count):
        if active[i]:
            mixed = weight[i]
            for a in range(stored):
                mixed -= mixing[0, a, i] * mixing[2, a, last]
            if not mixed > 0.0:
                return
    total = 0.0
    for i in range(count):
        if active[i]:
            for a in range(stored):
                weight[i] -= mixing[0, a, i] * mixing[2, a, last]
            total += weight[i]
    for i in range(count):
        weight[i] /= total


@njit(cache=True, inline="always", error_model="numpy")
def cholesky_in_place(system, n, scale):
    """The Cholesky factor L of the symmetric positive definite system[:n, :n] (its lower
    triangle read), into that lower triangle; False where a pivot is at most 1e-12 of ``scale``
    (the largest entry): singular, the factor unfinished."""
    for k in range(n):
        for c in range(k):
            total = system[k, c]
            for p in range(c):
                total -= system[k, p] * system[c, p]
            system[k, c] = total / system[c, c]
        total = system[k, k]
        for p in range(k):
            total -= system[k, p] * system[k, p]
        if not total > 1e-12 * scale:
            return False
        system[k, k] = math.sqrt(total)
    return True


@njit(cache=True, inline="always", error_model="numpy")
def normal_responses(active, count, responses, compliance, system):
    """A: the active contacts' (``active`` (count,), nonzero for one) normal (y) velocity
    responses to one another's normal impulses (from ``responses`` (M, M, 3, 3)), with
    ``compliance`` (s/kg) added to its diagonal, into system[:n, :n] in the contacts' order;
    returns its largest entry (the scale its pivots are judged by)."""
    scale = 0.0
    row = 0
    for i in range(count):
        if not active[i]:
            continue
        column = 0
        for j in range(count):
            if active[j]:
                value = responses[i, j, 1, 1] + (compliance if i == j else 0.0)
                system[row, column] = value
                scale = max(scale, abs(value))
                column += 1
        row += 1
    return scale


@njit(cache=True, error_model="numpy")
def _normal_block(u, r, active, count, responses, system, compliance, pairs):
    """The set-up of ``_shared_friction`` at the active contacts: A⁻¹ into system[:n, :n], N0 =
    A⁻¹ (-u_y) into system[:n, M + 3] and the pairs' terms into ``pairs`` (M = MAX_CONTACTS;
    the layout and the names are ``_shared_friction``'s; ``compliance`` added to A's diagonal).
    Returns the largest entry of A, the scale its pivots are judged by, or -1.0 where A is
    singular."""
    n = 0
    for i in range(count):
        if active[i]:
            n += 1
    rhs = MAX_CONTACTS + 3  # the right-hand sides' and solutions' column
    for i in range(count):
        if not active[i]:
            continue
        for j in range(count):
            if active[j]:
                # B's and D's terms of the pair: the normal (y) response at i and the slide
                # (x, z) and twist response at i (the twist's velocity r_z v_x - r_x v_z) to a
                # slide x, a slide z and a twist at j (a twist's impulse (r_z, 0, -r_x))
                k = responses[i, j]
                twist_x = r[j, 2] * k[0, 0] - r[j, 0] * k[0, 2]
                twist_z = r[j, 2] * k[2, 0] - r[j, 0] * k[2, 2]
                pairs[i, j, 0] = k[1, 0]
                pairs[i, j, 1] = k[1, 2]
                pairs[i, j, 2] = r[j, 2] * k[1, 0] - r[j, 0] * k[1, 2]
                pairs[i, j, 3] = k[0, 0]
                pairs[i, j, 4] = k[2, 0]
                pairs[i, j, 5] = k[2, 2]
                pairs[i, j, 6] = r[i, 2] * k[0, 0] - r[i, 0] * k[2, 0]
                pairs[i, j, 7] = r[i, 2] * k[0, 2] - r[i, 0] * k[2, 2]
                pairs[i, j, 8] = r[i, 2] * twist_x - r[i, 0] * twist_z
    # A; then L in place of A, then A⁻¹ (both triangles) in place of L, and N0 = A⁻¹ (-u_y)
    scale_a = normal_responses(active, count, responses, compliance, system)
    if not cholesky_in_place(system, n, scale_a):
        return -1.0
    for k in range(n):  # L⁻¹, row by row (a row's entries of L are used left to right)
        diagonal = 1.0 / system[k, k]
        for c in range(k):
            total = 0.0
            for p in range(c, k):
                total -= system[k, p] * system[p, c]
            system[k, c] = total * diagonal
        system[k, k] = diagonal
    for i in range(n):  # A⁻¹ = L⁻ᵀ L⁻¹, rows in order (row i of L⁻¹ is not used after it)
        for j in range(i + 1):
            total = 0.0
            for p in range(i, n):
                total += system[p, i] * system[p, j]
            system[i, j] = total
            system[j, i] = total
    row = 0
    for i in range(count):
        if active[i]:
            total = 0.0
            column = 0
            for j in range(count):
                if active[j]:
                    total -= system[row, column] * u[j, 1]
                    column += 1
            system[row, rhs] = total
            row += 1
    return scale_a


@njit(cache=True, error_model="numpy")
def _shared_friction(
    u, r, active, count, impulse, system, mixing, weight, share, twisting, pairs, scale_a
):
    """Impulses at the active contacts (at least two), the paper's friction carried to 3-D: no
    active point sinks; each point's horizontal impulse is its share (its normal impulse over
    their sum) of a common one, a slide (T_x, T_z) plus a twist Γ about the vertical (at offset
    r from the centre of mass: (T_x + Γ r_z, T_z - Γ r_x)); and the normal-weighted horizontal
    velocity and twist (r_z u_x - r_x u_z) of the points vanish after it, so that together they
    neither slide nor spin on the floor (in a vertical plane the twist is 0 and this is the 2-D
    rule). A fixed point over the shares, iterated to 1e-12. The compliance (s/kg, 0: none)
    that ``_normal_block`` adds to each contact's own normal response splits the load of
    contacts that a rigid body leaves undecided (more than three on a plane, several in a
    line). ``twisting``: False leaves the twist out (Γ = 0: slide only, the 2-D rule as it
    is). u, r (count, 3). Returns
    the index of the contact whose normal impulse pulls most (-1: none pulls; -2: the system is
    singular; -3: the shares of a twisting solve did not settle; slide only keeps its last
    iterate, as the 2-D rule does). ``share`` (count,): the shares the points had the step
    before (0: not in contact then), where the iteration starts if every active point had one,
    the shares then mixed (``_mix_shares``), unless there are two with no z in their offsets r or
    velocities u (a figure moving in its x-y plane): those start at even shares and iterate
    plainly, as the 2-D rule does (where the iteration starts can decide whether a normal
    impulse pulls, and a figure in that plane moves as the 2-D simulator moves it).

    How it is solved: the system in the n normal impulses and the m = 3 (2 without the twist)
    tangential unknowns is symmetric positive semi-definite, [[A, B], [Bᵀ, D]] (the body's
    response restricted to those impulses, plus the compliance on A's diagonal). A does not
    depend on the shares, so it is inverted once (by its Cholesky factor; a pivot at most 1e-12
    of its largest entry is singular), and so is N0 = A⁻¹ (-u_y); B is linear in the shares
    and D bilinear, so the terms they sum (``pairs`` (M, M, 9): for each pair of points, the
    normal response at the first to the slides and twist at the second, and the slide and
    twist response at the first to them) are made once too. Each share iteration sums
    them, forms the Schur complement S = D - Bᵀ Y, Y = A⁻¹ B (m × m), and solves S x = b - Bᵀ N0
    by S's adjugate, one division (singular where a pivot of S's Cholesky factor, the ratio of
    two leading minors, is at most 1e-12 of the system's largest entry); the normal impulses are
    N0 - Y x: no chain of divisions and square roots an iteration. system (M + 4, M + 4) holds,
    M = MAX_CONTACTS: A⁻¹ in rows :n, columns :n; B in rows :n, columns M:M + m; Yᵀ in rows M:M
    + m, columns :n, and S beside it; the right-hand sides and solutions (N0, then b and x) in
    column M + 3; the normal impulses in row M + 3, columns :n. A⁻¹, N0 and the pairs' terms
    depend neither on the shares nor on ``twisting``: ``_normal_block`` makes them (scale_a: the
    largest entry of A, which it returns), and a retry without the twist reads the same."""
    n = 0
    known = 0.0
    planar = True  # no z in any active point's offset or velocity: the 2-D rule's case
    for i in range(count):
        if active[i]:
            n += 1
            known = known + share[i] if share[i] > 0.0 and known >= 0.0 else -1.0
            planar = planar and r[i, 2] == 0.0 and u[i, 2] == 0.0
    accelerated = n >= 3 or not planar  # two in the plane iterate plainly, as the 2-D rule does
    for i in range(count):
        if not active[i]:
            weight[i] = 0.0
        elif known > 0.0 and accelerated:  # two in the plane start even, as the 2-D rule does
            weight[i] = share[i] / known
        else:
            weight[i] = 1.0 / n
    m = 3 if twisting else 2
    t = MAX_CONTACTS  # the tangential block's first row and column
    rhs = MAX_CONTACTS + 3  # the right-hand sides' and solutions' column
    normal = MAX_CONTACTS + 3  # the row that keeps the normal impulses
    converged = False
    last = MAX_CONTACTS - 1  # mixing's row of the last update and residual
    for iteration in range(FIXED_POINT_ITERATIONS):
        # B, D (lower triangle) and the tangential right-hand side b at the present shares
        b_x = b_z = b_twist = 0.0
        d_xx = d_zx = d_zz = d_tx = d_tz = d_tt = 0.0
        scale = scale_a
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = 0.0
            for j in range(count):
                if not active[j]:
                    continue
                wj = weight[j]
                s0 += wj * pairs[i, j, 0]
                s1 += wj * pairs[i, j, 1]
                s2 += wj * pairs[i, j, 2]
                s3 += wj * pairs[i, j, 3]
                s4 += wj * pairs[i, j, 4]
                s5 += wj * pairs[i, j, 5]
                s6 += wj * pairs[i, j, 6]
                s7 += wj * pairs[i, j, 7]
                s8 += wj * pairs[i, j, 8]
            wi = weight[i]
            system[row, t] = s0
            system[row, t + 1] = s1
            scale = max(scale, abs(s0), abs(s1))
            d_xx += wi * s3
            d_zx += wi * s4
            d_zz += wi * s5
            b_x -= wi * u[i, 0]
            b_z -= wi * u[i, 2]
            if twisting:
                system[row, t + 2] = s2
                scale = max(scale, abs(s2))
                d_tx += wi * s6
                d_tz += wi * s7
                d_tt += wi * s8
                b_twist -= wi * (r[i, 2] * u[i, 0] - r[i, 0] * u[i, 2])
            row += 1
        system[t, t] = d_xx
        system[t + 1, t] = d_zx
        system[t + 1, t + 1] = d_zz
        system[t, rhs] = b_x
        system[t + 1, rhs] = b_z
        scale = max(scale, abs(d_xx), abs(d_zx), abs(d_zz))
        if twisting:
            system[t + 2, t] = d_tx
            system[t + 2, t + 1] = d_tz
            system[t + 2, t + 2] = d_tt
            system[t + 2, rhs] = b_twist
            scale = max(scale, abs(d_tx), abs(d_tz), abs(d_tt))
        # Y = A⁻¹ B (its transpose in rows M:M + m, columns :n); S = D - Bᵀ Y and b - Bᵀ N0
        for q in range(m):
            for k in range(n):
                total = 0.0
                for p in range(n):
                    total += system[k, p] * system[p, t + q]
                system[t + q, k] = total
        for p in range(m):
            for k in range(n):
                b_kp = system[k, t + p]
                system[t + p, rhs] -= b_kp * system[k, rhs]
                for q in range(p + 1):
                    system[t + p, t + q] -= b_kp * system[t + q, k]
        # S x = b - Bᵀ N0 by S's adjugate; a pivot of S's Cholesky factor (the ratio of its
        # leading minors) at most 1e-12 of the system's largest entry is singular
        s00 = system[t, t]
        s10 = system[t + 1, t]
        s11 = system[t + 1, t + 1]
        minor = s00 * s11 - s10 * s10
        if not (s00 > 1e-12 * scale and minor > 1e-12 * scale * s00):
            return -2
        r0 = system[t, rhs]
        r1 = system[t + 1, rhs]
        if twisting:
            s20 = system[t + 2, t]
            s21 = system[t + 2, t + 1]
            s22 = system[t + 2, t + 2]
            c00 = s11 * s22 - s21 * s21
            c10 = s20 * s21 - s10 * s22
            c20 = s10 * s21 - s11 * s20
            determinant = s00 * c00 + s10 * c10 + s20 * c20
            if not determinant > 1e-12 * scale * minor:
                return -2
            inverse = 1.0 / determinant
            r2 = system[t + 2, rhs]
            system[t, rhs] = (c00 * r0 + c10 * r1 + c20 * r2) * inverse
            system[t + 1, rhs] = (
                c10 * r0 + (s00 * s22 - s20 * s20) * r1 + (s10 * s20 - s00 * s21) * r2
            ) * inverse
            system[t + 2, rhs] = (c20 * r0 + (s10 * s20 - s00 * s21) * r1 + minor * r2) * inverse
        else:
            inverse = 1.0 / minor
            system[t, rhs] = (s11 * r0 - s10 * r1) * inverse
            system[t + 1, rhs] = (s00 * r1 - s10 * r0) * inverse
        # the normal impulses N0 - Y x
        for k in range(n):
            total = system[k, rhs]
            for q in range(m):
                total -= system[t + q, k] * system[t + q, rhs]
            system[normal, k] = total
        total = 0.0
        worst = -1
        worst_value = 0.0
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            value = system[normal, row]
            if value <= worst_value:
                worst_value = value
                worst = i
            total += value
            row += 1
        if worst >= 0:
            return worst
        # the plain update g (each point's share of the normal impulses) and its residual
        # g - w, remembered as changes since the last iteration
        depth = n - 1
        slot = (iteration - 1) % depth
        change = 0.0
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            updated = system[normal, row] / total
            residual = updated - weight[i]
            change = max(change, abs(residual))
            if iteration > 0:
                mixing[0, slot, i] = updated - mixing[0, last, i]
                mixing[1, slot, i] = residual - mixing[1, last, i]
            mixing[0, last, i] = updated
            mixing[1, last, i] = residual
            weight[i] = updated
            row += 1
        if change <= 1e-12:
            converged = True
            break
        if accelerated:
            _mix_shares(weight, active, count, mixing, min(iteration, depth))
    if twisting and not converged:
        return -3
    slide_x = system[t, rhs]
    slide_z = system[t + 1, rhs]
    twist = system[t + 2, rhs] if twisting else 0.0
    row = 0
    for i in range(count):
        if active[i]:
            impulse[i, 0] = weight[i] * (slide_x + twist * r[i, 2])
            impulse[i, 1] = system[normal, row]
            impulse[i, 2] = weight[i] * (slide_z - twist * r[i, 0])
            row += 1
    return -1


@njit(cache=True, inline="always", error_model="numpy")
def stop_dead(u, responses, i):
    """The impulse (x, y, z) that stops contact i (velocity u[i] (3,)) dead, from its own
    response responses[i, i] (3, 3) (symmetric positive definite: solved by its Cholesky
    factor); its y is <= 0 if that would pull the point down."""
    l00 = math.sqrt(responses[i, i, 0, 0])
    l10 = responses[i, i, 1, 0] / l00
    l20 = responses[i, i, 2, 0] / l00
    l11 = math.sqrt(responses[i, i, 1, 1] - l10 * l10)
    l21 = (responses[i, i, 2, 1] - l20 * l10) / l11
    l22 = math.sqrt(responses[i, i, 2, 2] - l20 * l20 - l21 * l21)
    y0 = -u[i, 0] / l00
    y1 = (-u[i, 1] - l10 * y0) / l11
    y2 = (-u[i, 2] - l20 * y0 - l21 * y1) / l22
    z = y2 / l22
    y = (y1 - l21 * z) / l11
    x = (y0 - l10 * y - l20 * z) / l00
    return x, y, z


@njit(cache=True, inline="always", error_model="numpy")
def stop_horizontally(u, responses, i):
    """The horizontal impulse (x, 0, z) that stops contact i's horizontal velocity (u[i] (3,))
    alone, from the x-z block of its own response responses[i, i] (3, 3): the lone contact's
    stop where stopping dead would pull (the point then does not sink)."""
    k = responses[i, i]
    det = k[0, 0] * k[2, 2] - k[0, 2] * k[2, 0]
    px = (-u[i, 0] * k[2, 2] + u[i, 2] * k[0, 2]) / det
    pz = (-u[i, 2] * k[0, 0] + u[i, 0] * k[2, 0]) / det
    return px, 0.0, pz


@njit(cache=True, inline="always", error_model="numpy")
def _others_hold(u, count, responses, impulse, members):
    """True if no touching point outside ``members`` ((count,) 1.0 for a member) sinks after
    the impulses (count, 3)."""
    for i in range(count):
        if members[i]:
            continue
        uy = u[i, 1]
        for j in range(count):
            for b in range(3):
                uy += responses[i, j, 1, b] * impulse[j, b]
        if uy < -1e-9:
            return False
    return True


@njit(cache=True, inline="always", error_model="numpy")
def _twist_too_strong(impulse, active, count):
    """True if some active contact's horizontal impulse exceeds TWIST_RATIO times its normal."""
    for i in range(count):
        if active[i]:
            horizontal = math.sqrt(impulse[i, 0] ** 2 + impulse[i, 2] ** 2)
            if horizontal > TWIST_RATIO * impulse[i, 1]:
                return True
    return False


@njit(cache=True, error_model="numpy")
def frictionless_impulses(u, count, responses, impulse, system, compliance, members):
    """Normal impulses alone (count,) N s into impulse[:, 1] (its x and z 0), the floor's last
    resort when no impulse set of the friction rule pushes: the contacts that push stop
    sinking, and none of the others sinks after them (non-penetration with no friction; for a
    positive definite normal block exactly one such set). The sets are tried largest first;
    ``compliance`` (s/kg) is added to each contact's own normal response in sets of three or
    more (as ``contact_impulses`` does: a rigid body leaves their split undecided). u (count, 3),
    responses (M, M, 3, 3); system (M + 4, M + 4), members (M,): work space. Returns whether
    a set was found (else the impulses are 0)."""
    impulse[:count, :] = 0.0
    for size in range(count, 0, -1):
        for subset in range(1, 1 << count):
            n = 0
            for i in range(count):
                bit = (subset >> i) & 1
                members[i] = bit
                n += bit
            if n != size:
                continue
            added = compliance if n >= 3 else 0.0
            # A_S's Cholesky factor in system[:n, :n], the solution in column M
            scale = normal_responses(members, count, responses, added, system)
            row = 0
            for i in range(count):
                if members[i]:
                    system[row, MAX_CONTACTS] = -u[i, 1]
                    row += 1
            if not cholesky_in_place(system, n, scale):
                continue
            for k in range(n):  # L y = b, then Lᵀ x = y
                total = system[k, MAX_CONTACTS]
                for q in range(k):
                    total -= system[k, q] * system[q, MAX_CONTACTS]
                system[k, MAX_CONTACTS] = total / system[k, k]
            pushing = True
            for k in range(n - 1, -1, -1):
                total = system[k, MAX_CONTACTS]
                for q in range(k + 1, n):
                    total -= system[q, k] * system[q, MAX_CONTACTS]
                system[k, MAX_CONTACTS] = total / system[k, k]
                pushing = pushing and system[k, MAX_CONTACTS] > 0.0
            if not pushing:
                continue
            row = 0
            for i in range(count):
                if members[i]:
                    impulse[i, 1] = system[row, MAX_CONTACTS]
                    row += 1
            if _others_hold(u, count, responses, impulse, members):
                return True
            impulse[:count, 1] = 0.0
    return False


@njit(cache=True, inline="always", error_model="numpy")
def contact_impulses(
    u,
    r,
    count,
    inverse_mass,
    world_inverse,
    impulse,
    responses,
    system,
    mixing,
    shares,
    chosen,
    end_share,
    pairs,
    spins,
):
    """The ground's impulses (count, 3) N s on ``count`` touching endpoints: u (count, 3) their
    velocities m/s, r (count, 3) their offsets from the centre of mass m. First the sinking ones
    together, with shared friction, dropping the one whose normal impulse would pull most and
    trying again while two or more are left; then each sinking one alone, the fastest first,
    stopped dead. The first set whose normal impulses push and after which no other touching
    point sinks is kept. A lone point that stopping dead would pull is stopped horizontally
    alone (``stop_horizontally``; it then rises). Two or more of which no set pushes take
    normal impulses alone (``frictionless_impulses``), as the 2-D rule does for two. Returns
    whether the impulses follow the friction rule (False: the frictionless ones).
    responses (M, M, 3, 3), system (M + 4, M + 4), mixing (3, M, M), shares (3, M), pairs (M, M,
    9), spins (M, 3, 3): work space.
    chosen (count,): the points' endpoint numbers; end_share (E,): each endpoint's share of the
    horizontal impulse the step before, updated (the shared-friction iteration starts from
    it)."""
    impulse[:count, :] = 0.0
    active = shares[0]
    weight = shares[1]
    share = shares[2]
    for i in range(count):
        share[i] = end_share[chosen[i]]
    end_share[:] = 0.0
    n = 0
    for i in range(count):
        active[i] = 1.0 if u[i, 1] < 0.0 else 0.0
        n += int(active[i])
    if n == 0:
        return True
    for j in range(count):
        spin_per_impulse(r, j, world_inverse, spins)
    for i in range(count):
        for j in range(count):
            response(r, i, j, inverse_mass, spins, responses)
    # three or more points: a rigid body often leaves their split undecided
    compliance = 0.0 if n < 3 else COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
    # np.int64 and np.bool_: types, not literals (each literal a signature of its own: the
    # shared friction compiled four times over, 40 s of a cold start)
    points = (u, r, active, np.int64(count), impulse, system, mixing, weight, share)
    while n >= 2:
        scale_a = _normal_block(u, r, active, np.int64(count), responses, system, compliance, pairs)
        worst = -2
        if scale_a >= 0.0:
            worst = _shared_friction(*points, np.bool_(True), pairs, scale_a)
        if worst == -1 and _twist_too_strong(impulse, active, count) or worst == -3:
            # slide only: the paper's rule as it is (on the same normal block)
            worst = _shared_friction(*points, np.bool_(False), pairs, scale_a)
        if worst == -2 and compliance == 0.0:
            # the rigid body leaves the split undecided: a little compliance decides it
            compliance = COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
            continue
        if worst == -1 and _others_hold(u, count, responses, impulse, active):
            for i in range(count):
                end_share[chosen[i]] = weight[i]
            return True
        if worst < 0:
            # still singular, unsettled, or another point would sink: drop the one sinking
            # slowest
            for i in range(count):
                if active[i] and (worst < 0 or u[i, 1] > u[worst, 1]):
                    worst = i
        active[worst] = 0.0
        n -= 1
        impulse[:count, :] = 0.0
    tried = shares[1]
    tried[:count] = 0.0
    for _ in range(count):
        first = -1
        for i in range(count):
            if u[i, 1] < 0.0 and not tried[i] and (first < 0 or u[i, 1] < u[first, 1]):
                first = i
        if first < 0:
            break
        tried[first] = 1.0
        px, py, pz = stop_dead(u, responses, first)
        if py <= 0.0:
            if count == 1:
                # stopping dead would pull: the horizontal stop alone, after which it rises
                # (the lone-contact rule, as in 2-D)
                impulse[0, 0], _, impulse[0, 2] = stop_horizontally(u, responses, 0)
                return True
            continue
        impulse[first, 0] = px
        impulse[first, 1] = py
        impulse[first, 2] = pz
        active[:count] = 0.0
        active[first] = 1.0
        if _others_hold(u, count, responses, impulse, active):
            return True
        impulse[first, :] = 0.0
    # no set pushes under the friction rule: without friction, rather than no impulse (the
    # figure would sink, be lifted out by its position alone and gather a fall's velocity)
    compliance = COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
    frictionless_impulses(u, count, responses, impulse, system, compliance, active)
    return False


class StepWork(NamedTuple):
    """What ``step`` keeps between steps and works in, for a figure of N rods and E endpoints
    (``new_step_work`` makes it); M = MAX_CONTACTS. ``previous``, ``end_offset``,
    ``end_share`` and the last two rows of ``scratch`` carry from one step to the next;
    ``rod_ends`` and ``end_force`` are the step's outputs; the rest is scratch."""

    previous: np.ndarray  # (3,) the deformation's own spin I⁻¹ h in the world, rad/s
    rod_ends: np.ndarray  # (N, 2, 3) every rod's ends in the world after the step, m
    end_offset: np.ndarray  # (E, 3) each endpoint from the centre of mass, body frame, m
    end_velocity: np.ndarray  # (E, 3) each endpoint's velocity from the deformation, m/s
    end_force: np.ndarray  # (E,) the ground's normal force on each endpoint over the step, N
    frames: np.ndarray  # (N, 3, 3) each rod's frame in the body frame
    scratch: np.ndarray  # (N, 7, 3) ``body_frame``'s (``new_scratch``)
    matrices: np.ndarray  # (5, 3, 3) rotation, tensor, its inverse, world inverse, half turn
    vectors: np.ndarray  # (3, 4) spin, body rate, half-step quaternion
    contact: np.ndarray  # (3, M, 3) the contacts' velocities, offsets and impulses
    responses: np.ndarray  # (M, M, 3, 3) the contacts' responses
    system: np.ndarray  # (M + 4, M + 4) the shared-friction system
    mixing: np.ndarray  # (3, M, M) the shared-friction shares' memory (Anderson mixing)
    shares: np.ndarray  # (3, M) active flags, weights and last shares of the contacts
    chosen: np.ndarray  # (M,) int64 the contacts' endpoints
    entry: np.ndarray  # (E, 3) each endpoint in the world before the step, m
    end_share: np.ndarray  # (E,) each endpoint's share of the horizontal impulse last step
    pairs: np.ndarray  # (M, M, 9) the shared-friction solve's terms of each pair of contacts
    spins: np.ndarray  # (M, 3, 3) each contact's spin per impulse (``spin_per_impulse``)


@njit(cache=True)
def new_step_works(lanes, n_rods, n_ends):
    """StepWorks for ``lanes`` runs of a figure of N = n_rods rods and E = n_ends endpoints, at
    rest (no spin, no contact before, no force): one StepWork whose arrays have a leading axis
    ``lanes``, lane ``i``'s work ``lane_work(works, i, ...)``. Each lane's ``end_offset`` must
    be filled (``body_frame``) before its first step."""
    m = MAX_CONTACTS
    return StepWork(
        np.zeros((lanes, 3)),
        np.empty((lanes, n_rods, 2, 3)),
        np.empty((lanes, n_ends, 3)),
        np.empty((lanes, n_ends, 3)),
        np.zeros((lanes, n_ends)),
        np.empty((lanes, n_rods, 3, 3)),
        np.full((lanes, n_rods, 7, 3), np.nan),  # new_scratch's, for each lane
        np.empty((lanes, 5, 3, 3)),
        np.zeros((lanes, 3, 4)),
        np.empty((lanes, 3, m, 3)),
        np.empty((lanes, m, m, 3, 3)),
        np.empty((lanes, m + 4, m + 4)),
        np.empty((lanes, 3, m, m)),
        np.empty((lanes, 3, m)),
        np.empty((lanes, m), np.int64),
        np.empty((lanes, n_ends, 3)),
        np.zeros((lanes, n_ends)),
        np.empty((lanes, m, m, 9)),
        np.empty((lanes, m, 3, 3)),
    )


@njit(cache=True, inline="always")
def lane_work(works, lane, rod_ends, end_offset, end_velocity, frames):
    """Lane ``lane``'s StepWork of ``works`` (``new_step_works``), with the arrays given for the
    four that the body frame fills (``works``' own lane of them, or the lane's views of arrays
    that hold several lanes, as ``bsr3d_lanes.body_frame_lanes`` fills them)."""
    return StepWork(
        works.previous[lane],
        rod_ends,
        end_offset,
        end_velocity,
        works.end_force[lane],
        frames,
        works.scratch[lane],
        works.matrices[lane],
        works.vectors[lane],
        works.contact[lane],
        works.responses[lane],
        works.system[lane],
        works.mixing[lane],
        works.shares[lane],
        works.chosen[lane],
        works.entry[lane],
        works.end_share[lane],
        works.pairs[lane],
        works.spins[lane],
    )


@njit(cache=True)
def new_step_work(n_rods, n_ends):
    """A StepWork for N = n_rods rods and E = n_ends endpoints (``new_step_works``' one lane)."""
    works = new_step_works(1, n_rods, n_ends)
    return lane_work(
        works, 0, works.rod_ends[0], works.end_offset[0], works.end_velocity[0], works.frames[0]
    )


@njit(cache=True, inline="always", error_model="numpy")
def work_body_frame(figure, state, work):
    """``body_frame`` of the state's (S,) pose into the StepWork ``work`` (its rod_ends,
    end_offset, end_velocity, frames, scratch; the inertia tensor in work.matrices[1], the
    deformation's spin in work.vectors[0, :3]). Returns the total mass, kg."""
    n_joints = figure.joint_min.shape[0]
    return body_frame(
        figure.parent,
        figure.hinge,
        figure.rest,
        figure.length,
        figure.mass,
        figure.com,
        figure.inertia,
        figure.joint,
        figure.endpoints,
        state[JOINTS : JOINTS + n_joints],
        state[JOINTS + n_joints : JOINTS + 2 * n_joints],
        work.rod_ends,
        work.end_offset,
        work.end_velocity,
        work.frames,
        work.scratch,
        work.matrices[1],
        work.vectors[0, :3],
    )


@njit(cache=True, error_model="numpy")
def start_step_work(figure, state, work):
    """Make the StepWork ``work`` ready for a first step from the state (S,): the body-frame
    quantities of its pose (``body_frame``: the endpoints, rods and frames, the inertia tensor in
    work.matrices[1] and its inverse in work.matrices[2], the deformation's spin in
    work.vectors[0, :3]), the body's rotation in work.matrices[0], and the deformation's own
    spin I⁻¹ h in the world in work.previous. Kept out of ``step``'s callers' code (a call, not
    inlined): one copy of ``body_frame`` inlined there is enough to compile."""
    matrices = work.matrices
    vectors = work.vectors
    work_body_frame(figure, state, work)
    invert_symmetric(matrices[1], matrices[2])
    rotation_of(state[QW : QW + 4], matrices[0])
    sx, sy, sz = apply(matrices[2], vectors[0, 0], vectors[0, 1], vectors[0, 2])
    work.previous[0], work.previous[1], work.previous[2] = apply(matrices[0], sx, sy, sz)


@njit(cache=True, inline="always", error_model="numpy")
def step(figure, state, target, tau, dt, work, place_rods):
    """Advance the state (S,) of a figure (a FigureArrays3D) by dt seconds toward the target pose
    (J,) rad with time constant tau s, in the StepWork ``work`` (``work.previous``: the
    deformation's own spin before the step, updated to the one after it; ``work.end_offset``
    must hold the endpoints as the previous step or the start left them). Fills
    ``work.end_force`` with the ground's normal force on each endpoint over the step and, if
    place_rods, ``work.rod_ends`` with the world positions of every rod's ends after the step
    (else it keeps them in the body frame, from the centre of mass: a run that records no
    motion skips placing them). The state
    must be sound (``kernels.soundness.state_is_sound``): the runs of
    ``kernels.bsr3d_controller`` check it before every step and stop where it is not.

    ``step_deform``, ``body_frame`` and ``step_motion`` in turn, each inlined where it is
    called, so that no array crosses a call each step. The runs of ``kernels.bsr3d_controller``
    step four figures at once with the same parts and ``bsr3d_lanes.body_frame_lanes`` (this
    body frame, bit for bit) between them; this scalar step is what the simulator's tests drive.
    """
    step_deform(figure, state, target, tau, dt, work)
    total_mass = work_body_frame(figure, state, work)
    step_motion(figure, state, dt, work, total_mass, place_rods)


@njit(cache=True, inline="always", error_model="numpy")
def step_deform(figure, state, target, tau, dt, work):
    """``step``'s first part: the endpoints' world positions before the step (work.entry) and
    the joints advanced toward the target pose (J,) rad (``deform_joints``). The body frame of
    the new pose comes next (``body_frame``, or ``bsr3d_lanes.body_frame_lanes`` for several
    controllers at once), then ``step_motion``."""
    rotation = work.matrices[0]
    quaternion = state[QW : QW + 4]
    end_offset = work.end_offset
    entry = work.entry
    rotation_of(quaternion, rotation)
    for e in range(figure.endpoints.shape[0]):
        entry[e, 0], entry[e, 1], entry[e, 2] = endpoint_position(state, rotation, end_offset, e)
    n_joints = target.shape[0]
    theta = state[JOINTS : JOINTS + n_joints]
    theta_rate = state[JOINTS + n_joints : JOINTS + 2 * n_joints]
    deform_joints(theta, theta_rate, target, tau, figure.joint_min, figure.joint_max, dt)


@njit(cache=True, inline="always", error_model="numpy")
def step_motion(figure, state, dt, work, total_mass, place_rods):
    """``step``'s last part, after the body frame of the deformed pose is in ``work`` (its
    end_offset, end_velocity, inertia tensor work.matrices[1], spin work.vectors[0, :3];
    total_mass kg): the orientation correction, gravity, the contacts and the rigid motion."""
    endpoints = figure.endpoints
    gravity, floor, reach = figure[11:]
    previous, rod_ends, end_offset, end_velocity, end_force = work[:5]
    matrices, vectors, contact, responses, system, mixing, shares, chosen, entry = work[7:16]
    end_share, pairs, spins = work[16:]
    rotation = matrices[0]
    tensor = matrices[1]
    tensor_inverse = matrices[2]
    world_inverse = matrices[3]
    half_rotation = matrices[4]
    spin = vectors[0, :3]
    body_rate = vectors[1, :3]
    quaternion = state[QW : QW + 4]
    half = vectors[2]
    n_ends = endpoints.shape[0]
    invert_symmetric(tensor, tensor_inverse)
    # orientation correction: the deformation leaves the angular momentum unchanged
    sx, sy, sz = apply(tensor_inverse, spin[0], spin[1], spin[2])
    sx, sy, sz = apply(rotation, sx, sy, sz)
    turn(
        quaternion,
        -0.5 * (previous[0] + sx) * dt,
        -0.5 * (previous[1] + sy) * dt,
        -0.5 * (previous[2] + sz) * dt,
    )
    previous[0] = sx
    previous[1] = sy
    previous[2] = sz
    rotation_of(quaternion, rotation)
    conjugate(rotation, tensor_inverse, world_inverse)
    state[VY] -= gravity * dt
    body_rate[0], body_rate[1], body_rate[2] = rigid_rate(state, rotation, world_inverse, spin)
    end_force[:] = 0.0
    pushing = 0
    pinned = -1
    frictional = True
    if not math.isnan(floor):
        # the endpoints (at most M, the lowest) that would end the step within the contact
        # tolerance of the floor (speculative contacts, as in 2-D)
        lowest = shares[1]
        count = 0
        # an endpoint higher over the floor than any endpoint can fall in the step (and the
        # tolerance) is passed over unread
        fall = largest_fall(state, body_rate, end_velocity, reach, dt)
        for e in range(n_ends):
            height = endpoint_position(state, rotation, end_offset, e)[1] - floor
            if height - fall > CONTACT_TOLERANCE + PASS_OVER_MARGIN:
                continue
            _, ry, _, _, uy, _ = endpoint_motion(
                state, rotation, body_rate, end_offset, end_velocity, e
            )
            predicted = state[CY] + ry - floor + min(uy, 0.0) * dt
            if predicted > CONTACT_TOLERANCE:
                continue
            if count == MAX_CONTACTS and predicted >= lowest[count - 1]:
                continue
            place = min(count, MAX_CONTACTS - 1)
            while place > 0 and lowest[place - 1] > predicted:
                lowest[place] = lowest[place - 1]
                chosen[place] = chosen[place - 1]
                place -= 1
            lowest[place] = predicted
            chosen[place] = e
            count = min(count + 1, MAX_CONTACTS)
        u = contact[0]
        r = contact[1]
        impulse = contact[2]
        for i in range(count):
            rx, ry, rz, ux, uy, uz = endpoint_motion(
                state, rotation, body_rate, end_offset, end_velocity, chosen[i]
            )
            r[i, 0] = rx
            r[i, 1] = ry
            r[i, 2] = rz
            u[i, 0] = ux
            # the velocity that would take the point exactly to the floor counts as zero
            u[i, 1] = uy + max(state[CY] + ry - floor, 0.0) / dt
            u[i, 2] = uz
        frictional = contact_impulses(
            u,
            r,
            count,
            1.0 / total_mass,
            world_inverse,
            impulse,
            responses,
            system,
            mixing,
            shares,
            chosen,
            end_share,
            pairs,
            spins,
        )
        for i in range(count):
            # a frictionless push pins nothing (its points may slide)
            if frictional and impulse[i, 1] > 0.0:
                pushing += 1
                pinned = chosen[i]
            state[VX] += impulse[i, 0] / total_mass
            state[VY] += impulse[i, 1] / total_mass
            state[VZ] += impulse[i, 2] / total_mass
            tx, ty, tz = _cross(
                r[i, 0], r[i, 1], r[i, 2], impulse[i, 0], impulse[i, 1], impulse[i, 2]
            )
            state[LX] += tx
            state[LX + 1] += ty
            state[LX + 2] += tz
            end_force[chosen[i]] = impulse[i, 1] / dt
    state[CX] += state[VX] * dt
    state[CY] += state[VY] * dt
    state[CZ] += state[VZ] * dt
    # the rigid spin I⁻¹ L, taken at the half step (the midpoint rule)
    wx, wy, wz = apply(world_inverse, state[LX], state[LX + 1], state[LX + 2])
    for a in range(4):
        half[a] = quaternion[a]
    turn(half, 0.5 * wx * dt, 0.5 * wy * dt, 0.5 * wz * dt)
    rotation_of(half, half_rotation)
    conjugate(half_rotation, tensor_inverse, world_inverse)
    wx, wy, wz = apply(world_inverse, state[LX], state[LX + 1], state[LX + 2])
    turn(quaternion, wx * dt, wy * dt, wz * dt)
    rotation_of(quaternion, rotation)
    if pushing == 1:
        # one endpoint down does not slide: hold it where it stood before the step, on the floor
        x, y, z = apply(
            rotation, end_offset[pinned, 0], end_offset[pinned, 1], end_offset[pinned, 2]
        )
        state[CX] = entry[pinned, 0] - x
        state[CY] = floor - y
        state[CZ] = entry[pinned, 2] - z
    if not math.isnan(floor):
        lowest = np.inf
        next_lowest = np.inf
        bottom = -1
        for e in range(n_ends):
            y = endpoint_position(state, rotation, end_offset, e)[1]
            if y < lowest:
                next_lowest = lowest
                lowest = y
                bottom = e
            elif y < next_lowest:
                next_lowest = y
        lift, alone = lowest_on_floor(
            lowest, next_lowest, floor, not frictional and end_force[bottom] > 0.0
        )
        state[CY] += lift
        if alone and not (pushing == 1 and pinned == bottom):
            # one endpoint down does not slide, however it came to be alone on the floor (as in
            # 2-D): stopped dead if that pushes, else horizontally, and held where it stood
            conjugate(rotation, tensor_inverse, world_inverse)
            body_rate[0], body_rate[1], body_rate[2] = rigid_rate(
                state, rotation, world_inverse, spin
            )
            u = contact[0]
            r = contact[1]
            rx, ry, rz, ux, uy, uz = endpoint_motion(
                state, rotation, body_rate, end_offset, end_velocity, bottom
            )
            r[0, 0] = rx
            r[0, 1] = ry
            r[0, 2] = rz
            u[0, 0] = ux
            u[0, 1] = uy
            u[0, 2] = uz
            inverse_mass = 1.0 / total_mass
            spin_per_impulse(r, 0, world_inverse, spins)
            response(r, 0, 0, inverse_mass, spins, responses)
            px, py, pz = stop_dead(u, responses, 0)
            if py <= 0.0:
                px, py, pz = stop_horizontally(u, responses, 0)
            state[VX] += px * inverse_mass
            state[VY] += py * inverse_mass
            state[VZ] += pz * inverse_mass
            tx, ty, tz = _cross(rx, ry, rz, px, py, pz)
            state[LX] += tx
            state[LX + 1] += ty
            state[LX + 2] += tz
            end_force[bottom] += py / dt
            if entry[bottom, 1] - floor <= CONTACT_TOLERANCE:
                state[CX] = entry[bottom, 0] - rx
                state[CZ] = entry[bottom, 2] - rz
    if place_rods:
        place_in_world(state, rotation, rod_ends, rod_ends)
