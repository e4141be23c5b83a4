"""The BSR physical simulator of the 1995 paper's §2.1.1, one step at a time.

Internal deformation is kinematic: each joint angle follows ``tau² θ'' + 2 tau θ' + (θ - θ0) = 0``
(solved exactly over a step: critically damped). The figure is otherwise a rigid body: its centre
of mass ``c`` and linear momentum are untouched by a deformation, and its orientation is corrected
so that its angular momentum ``L`` about the centre of mass is unchanged too (the body frame turns
at ``(L - h) / I``, where ``I`` is the deformed figure's inertia and ``h`` the angular momentum of
the deformation itself). Then gravity and ground contact act on the rigid figure: impulses at the
(at most two) lowest rod endpoints on the floor, solved so that no contact point moves into the
floor, with the paper's friction: one endpoint down does not slide; two down take tangential
impulses in the ratio of their normal impulses, sized so that their normal-impulse-weighted
tangential velocity is zero. An endpoint that still ends the step below the floor lifts the figure
out of it. An endpoint that ends the step alone on the floor (within ``CONTACT_TOLERANCE``, every
other one beyond it) does not slide, however it got there: the floor stops it (dead if that
pushes, else horizontally) and, if it was on the floor before the step too, holds it where it
stood. A contact's force is its impulse over the step. Rods do not collide with one another.

A figure travels to the kernels as one ``FigureArrays`` (``mosys.bsr.figure`` builds it). The
kernels that run every step (``step``, ``body_frame``) take its arrays one by one, unpacked once
before the step loop: numba counts a reference each time an array is taken out of a tuple, and
taking them out in every step measured 14% slower on recorded runs.

State vector (S = 6 + 2J): ``c_x, c_y`` (m), ``v_x, v_y`` (m/s), ``phi`` (the root rod's absolute
angle, rad, unwrapped), ``L`` (kg m²/s), ``θ`` (J, rad), ``θ'`` (J, rad/s).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

CX, CY, VX, VY, PHI, MOMENTUM = 0, 1, 2, 3, 4, 5
JOINTS = 6  # θ starts here, θ' follows it
CONTACT_TOLERANCE = 1e-3  # m: an endpoint this close to the floor is touching it
MAX_CONTACTS = 2


class FigureArrays(NamedTuple):
    """A figure as the kernels take it: N rods in an order where every parent precedes its
    children, J joints, E distinct endpoints, and the world it moves in."""

    parent: np.ndarray  # (N,) int64: each rod's parent, -1: the root
    hinge: np.ndarray  # (N,) m: where the rod hangs on its parent, from the parent's proximal end
    offset: np.ndarray  # (N,) rad: the rod's angle to its parent at joint angle 0
    length: np.ndarray  # (N,) m
    mass: np.ndarray  # (N,) kg
    com: np.ndarray  # (N,): the rod's centre of mass, a fraction from proximal to distal
    inertia: np.ndarray  # (N,) kg m² about the rod's own centre of mass
    joint: np.ndarray  # (N,) int64: the rod's joint's index in θ, -1: the root
    endpoints: np.ndarray  # (E, 2) int64: rod and end (0 proximal, 1 distal) of each endpoint
    joint_min: np.ndarray  # (J,) rad
    joint_max: np.ndarray  # (J,) rad
    gravity: float  # m/s², positive
    floor: float  # m: the floor's height (nan: no floor)
    reach: float  # m: the sum of the rods' lengths


@njit(cache=True)
def body_frame(
    parent,
    hinge,
    offset,
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
    scratch,
):
    """The deformed figure in its body frame (root angle 0), about its centre of mass.

    Fills rod_ends (N, 2, 2): each rod's proximal and distal end relative to the centre of
    mass, m; end_offset, end_velocity (E, 2): each distinct endpoint's position relative to the
    centre of mass (m) and its velocity from the deformation alone (m/s). Returns (M, I, h):
    total mass kg, inertia about the centre of mass kg m², the deformation's angular momentum
    about the centre of mass kg m²/s. scratch: (N, 8) work space.
    """
    n = parent.shape[0]
    angle = scratch[:, 0]
    rate = scratch[:, 1]
    proximal = scratch[:, 2:4]
    proximal_velocity = scratch[:, 4:6]
    cosine = scratch[:, 6]
    sine = scratch[:, 7]
    total_mass = 0.0
    mass_x = 0.0
    mass_y = 0.0
    momentum_x = 0.0
    momentum_y = 0.0
    for k in range(n):
        p = parent[k]
        if p < 0:
            angle[k] = 0.0
            rate[k] = 0.0
            proximal[k, 0] = 0.0
            proximal[k, 1] = 0.0
            proximal_velocity[k, 0] = 0.0
            proximal_velocity[k, 1] = 0.0
        else:
            cos_p = cosine[p]
            sin_p = sine[p]
            angle[k] = angle[p] + offset[k] + theta[joint[k]]
            rate[k] = rate[p] + theta_rate[joint[k]]
            proximal[k, 0] = proximal[p, 0] + hinge[k] * cos_p
            proximal[k, 1] = proximal[p, 1] + hinge[k] * sin_p
            proximal_velocity[k, 0] = proximal_velocity[p, 0] - hinge[k] * rate[p] * sin_p
            proximal_velocity[k, 1] = proximal_velocity[p, 1] + hinge[k] * rate[p] * cos_p
        arm = com[k] * length[k]
        cos_k = math.cos(angle[k])
        sin_k = math.sin(angle[k])
        cosine[k] = cos_k
        sine[k] = sin_k
        total_mass += mass[k]
        mass_x += mass[k] * (proximal[k, 0] + arm * cos_k)
        mass_y += mass[k] * (proximal[k, 1] + arm * sin_k)
        momentum_x += mass[k] * (proximal_velocity[k, 0] - arm * rate[k] * sin_k)
        momentum_y += mass[k] * (proximal_velocity[k, 1] + arm * rate[k] * cos_k)
    centre_x = mass_x / total_mass
    centre_y = mass_y / total_mass
    centre_vx = momentum_x / total_mass
    centre_vy = momentum_y / total_mass
    total_inertia = 0.0
    deformation_momentum = 0.0
    for k in range(n):
        arm = com[k] * length[k]
        cos_k = cosine[k]
        sin_k = sine[k]
        gx = proximal[k, 0] + arm * cos_k - centre_x
        gy = proximal[k, 1] + arm * sin_k - centre_y
        gvx = proximal_velocity[k, 0] - arm * rate[k] * sin_k - centre_vx
        gvy = proximal_velocity[k, 1] + arm * rate[k] * cos_k - centre_vy
        total_inertia += mass[k] * (gx * gx + gy * gy) + inertia[k]
        deformation_momentum += mass[k] * (gx * gvy - gy * gvx) + inertia[k] * rate[k]
        rod_ends[k, 0, 0] = proximal[k, 0] - centre_x
        rod_ends[k, 0, 1] = proximal[k, 1] - centre_y
        rod_ends[k, 1, 0] = proximal[k, 0] + length[k] * cos_k - centre_x
        rod_ends[k, 1, 1] = proximal[k, 1] + length[k] * sin_k - centre_y
    for e in range(endpoints.shape[0]):
        k = endpoints[e, 0]
        reach = length[k] * endpoints[e, 1]
        cos_k = cosine[k]
        sin_k = sine[k]
        end_offset[e, 0] = rod_ends[k, endpoints[e, 1], 0]
        end_offset[e, 1] = rod_ends[k, endpoints[e, 1], 1]
        end_velocity[e, 0] = proximal_velocity[k, 0] - reach * rate[k] * sin_k - centre_vx
        end_velocity[e, 1] = proximal_velocity[k, 1] + reach * rate[k] * cos_k - centre_vy
    return total_mass, total_inertia, deformation_momentum


@njit(cache=True)
def figure_body_frame(figure, theta, theta_rate, rod_ends, end_offset, end_velocity, scratch):
    """``body_frame`` of a FigureArrays, for use outside the step loop."""
    return body_frame(
        figure.parent,
        figure.hinge,
        figure.offset,
        figure.length,
        figure.mass,
        figure.com,
        figure.inertia,
        figure.joint,
        figure.endpoints,
        theta,
        theta_rate,
        rod_ends,
        end_offset,
        end_velocity,
        scratch,
    )


@njit(cache=True, inline="always")
def lowest_on_floor(lowest, next_lowest, floor, pushed):
    """After a step, the figure's lift (m, up) that puts its lowest endpoint (height lowest, m;
    the next lowest at next_lowest) on the floor (height floor): where it sank into the floor
    (no sinking), or where it took a frictionless push (``pushed``: it pushed, so it touches, as
    a pinned one does, and ends the step on the floor rather than skimming above it); else 0.
    And whether that endpoint is then alone on the floor (within CONTACT_TOLERANCE of it, the
    next beyond). 2-D and 3-D alike."""
    lift = 0.0
    if lowest < floor or pushed:
        lift = floor - lowest
        next_lowest += lift
        lowest = floor
    return lift, lowest - floor <= CONTACT_TOLERANCE < next_lowest - floor


@njit(cache=True, inline="always")
def endpoint_position(state, cos_phi, sin_phi, end_offset, e):
    """World (x, y) of endpoint e, m, from its offset from the centre of mass in the body frame
    (end_offset (E, 2)) and the body's orientation (cos_phi, sin_phi)."""
    x = state[CX] + cos_phi * end_offset[e, 0] - sin_phi * end_offset[e, 1]
    y = state[CY] + sin_phi * end_offset[e, 0] + cos_phi * end_offset[e, 1]
    return x, y


@njit(cache=True, inline="always")
def endpoint_motion(state, cos_phi, sin_phi, body_rate, end_offset, end_velocity, e):
    """Endpoint e's offset (rx, ry) from the centre of mass in the world, m, and its velocity
    (ux, uy), m/s: the body's motion (velocity of the centre of mass, rotation at body_rate
    rad/s) plus the deformation's own (end_velocity (E, 2), body frame)."""
    rx = cos_phi * end_offset[e, 0] - sin_phi * end_offset[e, 1]
    ry = sin_phi * end_offset[e, 0] + cos_phi * end_offset[e, 1]
    ux = state[VX] - body_rate * ry + cos_phi * end_velocity[e, 0] - sin_phi * end_velocity[e, 1]
    uy = state[VY] + body_rate * rx + sin_phi * end_velocity[e, 0] + cos_phi * end_velocity[e, 1]
    return rx, ry, ux, uy


@njit(cache=True, inline="always")
def place_in_world(state, cos_phi, sin_phi, body_ends, out):
    """Every rod's ends in the world, m: body_ends (N, 2, 2) relative to the centre of mass in
    the body frame, turned by the body's orientation and moved to the state's centre of mass;
    written to out (N, 2, 2), which may be body_ends itself."""
    for k in range(body_ends.shape[0]):
        for end in range(2):
            bx = body_ends[k, end, 0]
            by = body_ends[k, end, 1]
            out[k, end, 0] = state[CX] + cos_phi * bx - sin_phi * by
            out[k, end, 1] = state[CY] + sin_phi * bx + cos_phi * by


@njit(cache=True)
def deform_joints(theta, theta_rate, target, tau, joint_min, joint_max, dt):
    """Advance every joint dt seconds along tau² θ'' + 2 tau θ' + (θ - target) = 0, exactly
    (critically damped), then hold it inside [joint_min, joint_max] (rad; at a stop its rate
    becomes 0). theta, theta_rate: (J,) rad, rad/s, in place; target (J,) rad; tau s."""
    decay = math.exp(-dt / tau)
    for j in range(theta.shape[0]):
        error = theta[j] - target[j]
        slope = theta_rate[j] + error / tau
        theta[j] = target[j] + (error + slope * dt) * decay
        theta_rate[j] = (slope - (error + slope * dt) / tau) * decay
        if theta[j] < joint_min[j]:
            theta[j] = joint_min[j]
            theta_rate[j] = 0.0
        elif theta[j] > joint_max[j]:
            theta[j] = joint_max[j]
            theta_rate[j] = 0.0


@njit(cache=True, inline="always")
def _response(rx_i, ry_i, rx_j, ry_j, inverse_mass, inverse_inertia):
    """The 2×2 block K_ij as (xx, xy, yx, yy): the velocity change at point i (offset r_i from
    the centre of mass) per unit impulse at point j, for a rigid body."""
    return (
        inverse_mass + ry_i * ry_j * inverse_inertia,
        -ry_i * rx_j * inverse_inertia,
        -rx_i * ry_j * inverse_inertia,
        inverse_mass + rx_i * rx_j * inverse_inertia,
    )


@njit(cache=True, inline="always")
def _det3(a00, a01, a02, a10, a11, a12, a20, a21, a22):
    return (
        a00 * (a11 * a22 - a12 * a21)
        - a01 * (a10 * a22 - a12 * a20)
        + a02 * (a10 * a21 - a11 * a20)
    )


@njit(cache=True)
def _single_contact(ux, uy, rx, ry, inverse_mass, inverse_inertia):
    """The impulse (x, y) that stops one contact point dead (no sliding, no sinking), or None
    if that would pull the point down (it is leaving the floor)."""
    kxx, kxy, kyx, kyy = _response(rx, ry, rx, ry, inverse_mass, inverse_inertia)
    determinant = kxx * kyy - kxy * kyx
    px = (-ux * kyy + uy * kxy) / determinant
    py = (-uy * kxx + ux * kyx) / determinant
    return px, py


@njit(cache=True)
def _horizontal_stop(ux, rx, ry, inverse_mass, inverse_inertia):
    """The horizontal impulse N s that stops one contact point's horizontal velocity ux m/s
    alone (offset rx, ry m from the centre of mass): the lone contact's stop where stopping it
    dead would pull (the point then does not sink)."""
    return -ux / _response(rx, ry, rx, ry, inverse_mass, inverse_inertia)[0]


@njit(cache=True)
def _two_contacts(u, r, inverse_mass, inverse_inertia, impulse):
    """Impulses (2, 2) at two contact points with velocities u (2, 2) and offsets r (2, 2):
    both stop sinking, tangential impulses in the ratio of the normal ones, and the
    normal-weighted tangential velocity vanishes (a fixed point over the weights, iterated
    to 1e-12).
    Returns False if a normal impulse would pull or the points coincide (the caller then tries
    one contact)."""
    k00 = _response(r[0, 0], r[0, 1], r[0, 0], r[0, 1], inverse_mass, inverse_inertia)
    k01 = _response(r[0, 0], r[0, 1], r[1, 0], r[1, 1], inverse_mass, inverse_inertia)
    k10 = _response(r[1, 0], r[1, 1], r[0, 0], r[0, 1], inverse_mass, inverse_inertia)
    k11 = _response(r[1, 0], r[1, 1], r[1, 0], r[1, 1], inverse_mass, inverse_inertia)
    w0 = 0.5
    w1 = 0.5
    normal0 = 0.0
    normal1 = 0.0
    tangential = 0.0
    for _ in range(50):
        # unknowns: normal impulses 0 and 1, the total tangential impulse (split w0 : w1)
        # rows 0, 1: the vertical velocity of point i after the impulses is 0
        a00, a01, a02 = k00[3], k01[3], w0 * k00[2] + w1 * k01[2]
        a10, a11, a12 = k10[3], k11[3], w0 * k10[2] + w1 * k11[2]
        # row 2: sum_i w_i * horizontal velocity of point i after the impulses is 0
        a20 = w0 * k00[1] + w1 * k10[1]
        a21 = w0 * k01[1] + w1 * k11[1]
        a22 = w0 * (w0 * k00[0] + w1 * k01[0]) + w1 * (w0 * k10[0] + w1 * k11[0])
        b0 = -u[0, 1]
        b1 = -u[1, 1]
        b2 = -(w0 * u[0, 0] + w1 * u[1, 0])
        det = _det3(a00, a01, a02, a10, a11, a12, a20, a21, a22)
        scale = abs(a00) + abs(a11) + abs(a22)
        if abs(det) <= 1e-9 * scale * scale * scale:
            return False
        normal0 = _det3(b0, a01, a02, b1, a11, a12, b2, a21, a22) / det
        normal1 = _det3(a00, b0, a02, a10, b1, a12, a20, b2, a22) / det
        tangential = _det3(a00, a01, b0, a10, a11, b1, a20, a21, b2) / det
        if normal0 <= 0.0 or normal1 <= 0.0:
            return False
        updated = normal0 / (normal0 + normal1)
        if abs(updated - w0) <= 1e-12:
            break
        w0 = updated
        w1 = 1.0 - w0
    impulse[0, 0] = tangential * w0
    impulse[0, 1] = normal0
    impulse[1, 0] = tangential * w1
    impulse[1, 1] = normal1
    return True


@njit(cache=True)
def _frictionless(u, r, inverse_mass, inverse_inertia, impulse):
    """Normal impulses alone into impulse[:, 1] (x 0) at two points: the floor's last resort
    when no set of the friction rule pushes. Both points stop sinking if both then push; else
    the one whose impulse alone stops it sinking and leaves the other not sinking
    (non-penetration with no friction: for a positive definite normal block exactly one such
    set)."""
    a00 = _response(r[0, 0], r[0, 1], r[0, 0], r[0, 1], inverse_mass, inverse_inertia)[3]
    a01 = _response(r[0, 0], r[0, 1], r[1, 0], r[1, 1], inverse_mass, inverse_inertia)[3]
    a11 = _response(r[1, 0], r[1, 1], r[1, 0], r[1, 1], inverse_mass, inverse_inertia)[3]
    determinant = a00 * a11 - a01 * a01
    if determinant > 1e-12 * max(a00, a11) ** 2:
        normal0 = (-u[0, 1] * a11 + u[1, 1] * a01) / determinant
        normal1 = (-u[1, 1] * a00 + u[0, 1] * a01) / determinant
        if normal0 > 0.0 and normal1 > 0.0:
            impulse[0, 1] = normal0
            impulse[1, 1] = normal1
            return
    for i in range(2):
        if u[i, 1] >= 0.0:
            continue
        own = a00 if i == 0 else a11
        normal = -u[i, 1] / own
        if u[1 - i, 1] + a01 * normal < -1e-9:
            continue
        impulse[i, 1] = normal
        return


@njit(cache=True)
def contact_impulses(u, r, count, inverse_mass, inverse_inertia, impulse):
    """The ground's impulses on ``count`` (0, 1 or 2) touching endpoints: u (2, 2) their
    velocities m/s, r (2, 2) their offsets from the centre of mass m; fills impulse (2, 2) N s.
    Tries both endpoints together, then each alone (the one sinking faster first), keeping the
    first set whose normal impulses push and whose other endpoint does not sink. A lone point
    that stopping dead would pull is stopped horizontally alone (it then rises: the lone-contact
    rule). Two points of which no set pushes take normal impulses alone (``_frictionless``: no
    friction for that step) rather than none (the figure would sink, be lifted out by its
    position alone and gather a fall's velocity, until one step's impulse threw it).
    Returns whether the impulses follow the friction rule (False: the frictionless ones)."""
    impulse[:, :] = 0.0
    if count == 0:
        return True
    if count == 2 and u[0, 1] < 0.0 and u[1, 1] < 0.0:
        if _two_contacts(u, r, inverse_mass, inverse_inertia, impulse):
            return True
        impulse[:, :] = 0.0
    first = 0
    if count == 2 and u[1, 1] < u[0, 1]:
        first = 1
    for attempt in range(count):
        i = first if attempt == 0 else 1 - first
        if u[i, 1] >= 0.0:
            continue
        px, py = _single_contact(u[i, 0], u[i, 1], r[i, 0], r[i, 1], inverse_mass, inverse_inertia)
        if py <= 0.0:
            if count == 1:
                # stopping dead would pull: the horizontal stop alone, after which it rises
                # (its vertical velocity is the full stop's Schur complement times -py, >= 0)
                impulse[0, 0] = _horizontal_stop(
                    u[0, 0], r[0, 0], r[0, 1], inverse_mass, inverse_inertia
                )
                return True
            continue
        if count == 2:
            other = 1 - i
            _, _, kyx, kyy = _response(
                r[other, 0], r[other, 1], r[i, 0], r[i, 1], inverse_mass, inverse_inertia
            )
            if u[other, 1] + kyx * px + kyy * py < -1e-9:
                continue
        impulse[i, 0] = px
        impulse[i, 1] = py
        return True
    if count == 2:
        _frictionless(u, r, inverse_mass, inverse_inertia, impulse)
        return False
    return True


@njit(cache=True)
def step(
    parent,
    hinge,
    offset,
    length,
    mass,
    com,
    inertia,
    joint,
    endpoints,
    joint_min,
    joint_max,
    gravity,
    floor,
    state,
    target,
    tau,
    dt,
    previous,
    rod_ends,
    end_offset,
    end_velocity,
    end_force,
    scratch,
    contact,
    entry,
):
    """Advance the state (S,) of a figure (its arrays as in FigureArrays) by dt seconds toward
    the target pose (J,) rad with time constant tau s. ``previous`` (1,): h / I of the figure
    before the step (rad/s), updated to the figure after it. Fills rod_ends (N, 2, 2) with world
    positions of every rod's ends after the step (m), end_offset/end_velocity (E, 2) scratch,
    end_force (E,) the ground's normal force on each endpoint over the step, N. gravity m/s²,
    floor: the floor's height, m (nan: no floor). scratch (N, 8), contact (3, 2, 2), entry
    (E, 2): work space; end_offset must hold the figure's endpoints as the previous step (or the
    start) left them. The state must be sound (``kernels.soundness.state_is_sound``): the runs of
    ``kernels.bsr_controller`` check it before every step and stop where it is not.

    One piece on purpose, and its arrays one by one (the module docstring says why): it runs
    every step, and split into helpers it measured 3-17% slower.
    """
    cos_phi = math.cos(state[PHI])
    sin_phi = math.sin(state[PHI])
    for e in range(endpoints.shape[0]):
        entry[e, 0], entry[e, 1] = endpoint_position(state, cos_phi, sin_phi, end_offset, e)
    n_joints = target.shape[0]
    theta = state[JOINTS : JOINTS + n_joints]
    theta_rate = state[JOINTS + n_joints : JOINTS + 2 * n_joints]
    deform_joints(theta, theta_rate, target, tau, joint_min, joint_max, dt)
    total_mass, total_inertia, deformation_momentum = body_frame(
        parent,
        hinge,
        offset,
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
        scratch,
    )
    spin_of_deformation = deformation_momentum / total_inertia
    # orientation correction: the deformation leaves the angular momentum unchanged
    state[PHI] -= 0.5 * (previous[0] + spin_of_deformation) * dt
    previous[0] = spin_of_deformation
    state[VY] -= gravity * dt
    cos_phi = math.cos(state[PHI])
    sin_phi = math.sin(state[PHI])
    body_rate = (state[MOMENTUM] - deformation_momentum) / total_inertia
    end_force[:] = 0.0
    pushing = 0
    pinned = 0
    pinned_x = 0.0
    frictional = True
    if not math.isnan(floor):
        # the (at most two) endpoints that would end the step lowest, if within the contact
        # tolerance of the floor (speculative contacts: a point still above the floor may come
        # down to it, but not through it, during the step)
        chosen0 = -1
        chosen1 = -1
        lowest0 = np.inf
        lowest1 = np.inf
        for e in range(endpoints.shape[0]):
            _, ry, _, uy = endpoint_motion(
                state, cos_phi, sin_phi, body_rate, end_offset, end_velocity, e
            )
            predicted = state[CY] + ry - floor + min(uy, 0.0) * dt
            if predicted <= CONTACT_TOLERANCE:
                if predicted < lowest0:
                    lowest1 = lowest0
                    chosen1 = chosen0
                    lowest0 = predicted
                    chosen0 = e
                elif predicted < lowest1:
                    lowest1 = predicted
                    chosen1 = e
        u = contact[0]
        r = contact[1]
        impulse = contact[2]
        count = 0
        for e in (chosen0, chosen1):
            if e < 0:
                continue
            rx, ry, ux, uy = endpoint_motion(
                state, cos_phi, sin_phi, body_rate, end_offset, end_velocity, e
            )
            r[count, 0] = rx
            r[count, 1] = ry
            u[count, 0] = ux
            # the velocity that would take the point exactly to the floor counts as zero
            gap = max(state[CY] + ry - floor, 0.0)
            u[count, 1] = uy + gap / dt
            count += 1
        frictional = contact_impulses(u, r, count, 1.0 / total_mass, 1.0 / total_inertia, impulse)
        for i in range(count):
            # a frictionless push pins nothing (its points may slide)
            if frictional and impulse[i, 1] > 0.0:
                pushing += 1
                pinned = chosen0 if i == 0 else chosen1
                pinned_x = entry[pinned, 0]
        for i in range(count):
            state[VX] += impulse[i, 0] / total_mass
            state[VY] += impulse[i, 1] / total_mass
            state[MOMENTUM] += r[i, 0] * impulse[i, 1] - r[i, 1] * impulse[i, 0]
            end_force[chosen0 if i == 0 else chosen1] = impulse[i, 1] / dt
    state[CX] += state[VX] * dt
    state[CY] += state[VY] * dt
    state[PHI] += state[MOMENTUM] / total_inertia * dt
    cos_phi = math.cos(state[PHI])
    sin_phi = math.sin(state[PHI])
    if pushing == 1:
        # one endpoint down does not slide: hold it where it stood before the step (the
        # velocity constraint alone lets it drift by O(dt²) as the figure turns about it)
        # (and on the floor: it pushed, so it stays in contact)
        state[CX] = pinned_x - (cos_phi * end_offset[pinned, 0] - sin_phi * end_offset[pinned, 1])
        state[CY] = floor - (sin_phi * end_offset[pinned, 0] + cos_phi * end_offset[pinned, 1])
    if not math.isnan(floor):
        lowest = np.inf
        next_lowest = np.inf
        bottom = -1
        for e in range(endpoints.shape[0]):
            y = endpoint_position(state, cos_phi, sin_phi, end_offset, e)[1]
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
            # one endpoint down does not slide, however it came to be alone on the floor (the
            # lift above, a stop that would have pulled it down, a deformation that lifts it
            # as the figure moves): the floor stops it, dead if that pushes, else by a
            # horizontal impulse alone (after which it does not sink), and if it stood on the
            # floor before the step it stays where it stood
            body_rate = (state[MOMENTUM] - deformation_momentum) / total_inertia
            rx, ry, ux, uy = endpoint_motion(
                state, cos_phi, sin_phi, body_rate, end_offset, end_velocity, bottom
            )
            inverse_mass = 1.0 / total_mass
            inverse_inertia = 1.0 / total_inertia
            px, py = _single_contact(ux, uy, rx, ry, inverse_mass, inverse_inertia)
            if py <= 0.0:
                px = _horizontal_stop(ux, rx, ry, inverse_mass, inverse_inertia)
                py = 0.0
            state[VX] += px * inverse_mass
            state[VY] += py * inverse_mass
            state[MOMENTUM] += rx * py - ry * px
            end_force[bottom] += py / dt
            if entry[bottom, 1] - floor <= CONTACT_TOLERANCE:
                state[CX] = entry[bottom, 0] - rx
    place_in_world(state, cos_phi, sin_phi, rod_ends, rod_ends)
