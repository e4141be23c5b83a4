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
step). The orientation is a unit quaternion (body to world), renormalised every step
(``kernels.rotation3d``). Gravity and ground contact act on the rigid figure: impulses at every
rod endpoint that would end the step on the floor (up to ``MAX_CONTACTS``, the lowest first;
``kernels.bsr3d_contact``), with the paper's friction carried to 3-D: a lone contact does not
slide; several take horizontal impulses in the ratio of their
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

from mosys.kernels.bsr3d_contact import (
    MAX_CONTACTS,
    contact_impulses,
    response,
    spin_per_impulse,
    stop_dead,
    stop_horizontally,
)
from mosys.kernels.bsr_simulate import CONTACT_TOLERANCE, deform_joints, lowest_on_floor
from mosys.kernels.rotation3d import apply, conjugate, cross, invert_symmetric, rotation_of, turn

CX, CY, CZ, VX, VY, VZ = 0, 1, 2, 3, 4, 5
QW = 6  # quaternion w, x, y, z
LX = 10  # angular momentum x, y, z
JOINTS = 13  # θ starts here, θ' follows it
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
            vx, vy, vz = cross(wx, wy, wz, hx, hy, hz)
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
        vx, vy, vz = cross(omega[k, 0], omega[k, 1], omega[k, 2], arm * ux, arm * uy, arm * uz)
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
        hx, hy, hz = cross(
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
        vx, vy, vz = cross(
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
    wx, wy, wz = cross(body_rate[0], body_rate[1], body_rate[2], rx, ry, rz)
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
            tx, ty, tz = cross(
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
            tx, ty, tz = cross(rx, ry, rz, px, py, pz)
            state[LX] += tx
            state[LX + 1] += ty
            state[LX + 2] += tz
            end_force[bottom] += py / dt
            if entry[bottom, 1] - floor <= CONTACT_TOLERANCE:
                state[CX] = entry[bottom, 0] - rx
                state[CZ] = entry[bottom, 2] - rz
    if place_rods:
        place_in_world(state, rotation, rod_ends, rod_ends)
