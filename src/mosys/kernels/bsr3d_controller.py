"""Running a BSR controller of a 3-D figure (the 1995 paper's §4): the simulator steps, the
senses of §4.2, rule selection (shared with 2-D), and the 3-D fitness terms; a population at
once in parallel.

Senses (V = 10 + E + F, each normalised to [0, 1] and clipped), in this order: the centre of
mass's height over the floor ``y / (2 h0)``; its velocity, the body's angular velocity and the
world's up vector, each as three components in the figure-centric (body) frame, ``0.5 + v / (2
v0)``, ``0.5 + ω / (2 ω0)`` and ``0.5 + up / 2``; per endpoint the ground's normal force over
the step ``f / (2 M g)`` (every contact of this simulator is an impulse, so an endpoint's force
over a step is its collision impulse over dt: one sense carries both of the paper's); and the
angle of each free (flexible) joint angle ``(θ - min) / (max - min)``. ``h0`` is the standing
centre-of-mass height, ``v0 = sqrt(g h0)`` and ``ω0 = v0 / h0`` (``SenseScales``). The physical
senses (all but the joint angles) pass through a first-order low-pass filter of time constant
``filter_time`` s (§4.2: "to remove noise and high-frequency variation").

Fitness terms (the columns of terms_out, named by ``parsing.bsr.FITNESS_TERMS_3D``):
``distance`` the com's displacement along the heading at t = 0, m; ``sideways`` |the
displacement across it|, m; ``heading_change`` the unwrapped change of heading, deg
(counter-clockwise seen from above positive);
``max_height`` the largest com height, m; ``fall`` the fraction of steps that end fallen (com
below ``fall_height`` or a ``fall`` endpoint on the floor); ``heading_deviation`` the mean of
|heading - heading at t = 0| over the steps, deg; ``feet_distance`` the mean displacement
of the feet along the heading at t = 0, m; ``foot_steps`` the touch-downs (after a lift of at
least ``STEP_LIFT``) of a foot other than the one that touched down last; ``min_height`` the
lowest com height, m; ``heading_sine`` the sine of the heading change (1: a quarter turn to the
left, whatever the turns before it: a turn that a spin does not beat); ``final_spin`` the body's
angular speed at the end, deg/s (a run that ends toppling or spinning pays for it: the next
search of a chain starts there).

A run stops where the state is not sound (``kernels.soundness.state_is_sound``), as the 2-D
one does: checked before every step and after the last, it returns ``blown_up(step)`` (< 0).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from mosys.kernels.borrowed import borrowed
from mosys.kernels.bsr3d_simulate import (
    CX,
    CY,
    CZ,
    JOINTS,
    VX,
    apply,
    conjugate,
    new_step_work,
    rigid_rate,
    start_step_work,
    step,
)
from mosys.kernels.bsr_controller import (
    ControllerArrays,
    RunRecord,
    active_rule,
    rule_weights,
    segment_rule,
    stop_unsound,
)
from mosys.kernels.bsr_simulate import CONTACT_TOLERANCE
from mosys.kernels.soundness import state_is_sound

# the columns of terms_out (``parsing.bsr.FITNESS_TERMS_3D`` names them in this order)
(
    DISTANCE,
    SIDEWAYS,
    HEADING_CHANGE,
    MAX_HEIGHT,
    FALL,
    HEADING_DEVIATION,
    FEET_DISTANCE,
    FOOT_STEPS,
    MIN_HEIGHT,
    HEADING_SINE,
    FINAL_SPIN,
) = range(11)
TERM_COUNT = 11
PHYSICAL_SENSES = 10  # height, velocity (3), angular velocity (3), up (3)
STEP_LIFT = 0.01  # m: a foot that comes down counts as a step if it rose this high since it left


class Task(NamedTuple):
    """What a 3-D run measures and how it senses: ``falls`` (F,) int64 endpoints that count as
    a fall on the floor, ``fall_height`` m (com below it: fallen), ``feet`` (K,) int64 the
    endpoints the figure walks on, ``heading_rod`` and ``heading_offset`` (rad) the heading's
    rod and offset, ``free`` (F',) int64 the free angles sensed, ``scales`` (3,): h0 m, v0 m/s,
    ω0 rad/s, ``filter_time`` s: the senses' low-pass time constant."""

    falls: np.ndarray
    fall_height: float
    feet: np.ndarray
    heading_rod: int
    heading_offset: float
    free: np.ndarray
    scales: np.ndarray
    filter_time: float


@njit(cache=True, error_model="numpy")
def heading_of(frames, rotation, rod, offset):
    """The figure's heading, rad: the direction of rod ``rod``'s horizontal projection (its
    frame's first column, body frame, turned to the world by rotation), counter-clockwise seen
    from above (+x = 0, -z = +π/2), plus offset rad."""
    x, _, z = apply(rotation, frames[rod, 0, 0], frames[rod, 1, 0], frames[rod, 2, 0])
    return math.atan2(-z, x) + offset


@njit(cache=True, error_model="numpy")
def measure_senses(
    state, rotation, world_inverse, spin, end_force, weight, floor, task, joint_min, joint_max, out
):
    """Fill out (V,) with the unfiltered normalised senses of the state (S,): rotation (3, 3)
    the body's orientation, world_inverse (3, 3) its inverse inertia in the world, spin (3,) the
    deformation's angular momentum (body frame), end_force (E,) N, weight = M g N."""
    h0 = task.scales[0]
    v0 = task.scales[1]
    w0 = task.scales[2]
    base = 0.0 if math.isnan(floor) else floor
    out[0] = min(max((state[CY] - base) / (2.0 * h0), 0.0), 1.0)
    # velocity in the body frame: R^T v
    for a in range(3):
        value = (
            rotation[0, a] * state[VX]
            + rotation[1, a] * state[VX + 1]
            + rotation[2, a] * state[VX + 2]
        )
        out[1 + a] = min(max(0.5 + value / (2.0 * v0), 0.0), 1.0)
    wx, wy, wz = rigid_rate(state, rotation, world_inverse, spin)
    for a in range(3):
        value = rotation[0, a] * wx + rotation[1, a] * wy + rotation[2, a] * wz
        out[4 + a] = min(max(0.5 + value / (2.0 * w0), 0.0), 1.0)
        out[7 + a] = 0.5 + 0.5 * rotation[1, a]  # world up (0, 1, 0) in the body frame
    n_ends = end_force.shape[0]
    for e in range(n_ends):
        out[PHYSICAL_SENSES + e] = min(max(end_force[e] / (2.0 * weight), 0.0), 1.0)
    for f in range(task.free.shape[0]):
        j = task.free[f]
        value = (state[JOINTS + j] - joint_min[j]) / (joint_max[j] - joint_min[j])
        out[PHYSICAL_SENSES + n_ends + f] = min(max(value, 0.0), 1.0)


@njit(cache=True, error_model="numpy")
def run_controller(figure, controller, task, start, start_force, carry_over, steps, dt, record):
    """Run a controller (a ControllerArrays) of the 3-D figure (a FigureArrays3D) for ``steps``
    steps of dt seconds from the state ``start`` (S,), measuring as ``task`` (a Task) says,
    filling ``record`` (a RunRecord). start_force (E,): the endpoints' normal forces at the
    start, N; carry_over: start with the rule the senses pick (a controller continuing another)
    instead of rule 0. Long on purpose, as the 2-D run_controller; its arrays are borrowed
    (``kernels.borrowed``), so that the step loop raises and lowers no reference count.
    Returns ``steps``, or ``blown_up(n)`` (< 0) if the state is not sound (``state_is_sound``)
    before step n (n = steps: after the last), as the 2-D run_controller: the samples 0 to n
    recorded, terms_out NaN, final_state the unsound state."""
    figure = borrowed(figure)
    task = borrowed(task)
    parent, hinge, rest, length, mass, com, inertia, joint, endpoints = figure[:9]
    joint_min, joint_max, gravity, floor, _ = figure[9:]
    time_based, target, tau, center, side, segment_end, period = borrowed(controller)
    senses_out, rule_out, terms_out, ends_out, com_out, final_state, final_force = borrowed(record)
    own_state = start.copy()
    state = borrowed(own_state)
    n_rods = parent.shape[0]
    n_ends = endpoints.shape[0]
    own_work = new_step_work(n_rods, n_ends)
    work = borrowed(own_work)
    rod_ends, end_offset, _, end_force, frames = work[1:6]
    matrices, vectors = work[7:9]
    end_force[:] = start_force
    world_inverse = np.empty((3, 3))
    sensing = senses_out.shape[1] > 0
    raw = np.empty(senses_out.shape[1])
    filtered = np.empty(senses_out.shape[1])
    weight = mass.sum() * gravity
    recording = ends_out.shape[0] == steps + 1
    weights = rule_weights(side)
    start_step_work(figure, state, work)
    rotation = matrices[0]
    conjugate(rotation, matrices[2], world_inverse)
    # the start
    n_feet = task.feet.shape[0]
    foot_start = np.empty((n_feet, 3))
    touching = np.zeros(n_ends, np.bool_)
    for e in range(n_ends):
        x, y, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
        touching[e] = not math.isnan(floor) and state[CY] + y <= floor + CONTACT_TOLERANCE
    for f in range(n_feet):
        e = task.feet[f]
        x, y, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
        foot_start[f, 0] = state[CX] + x
        foot_start[f, 2] = state[CZ] + z
    if recording:
        for k in range(n_rods):
            for end in range(2):
                x, y, z = apply(
                    rotation, rod_ends[k, end, 0], rod_ends[k, end, 1], rod_ends[k, end, 2]
                )
                ends_out[0, k, end, 0] = state[CX] + x
                ends_out[0, k, end, 1] = state[CY] + y
                ends_out[0, k, end, 2] = state[CZ] + z
        com_out[0, 0] = state[CX]
        com_out[0, 1] = state[CY]
        com_out[0, 2] = state[CZ]
    if sensing:
        measure_senses(
            state,
            rotation,
            world_inverse,
            vectors[0, :3],
            end_force,
            weight,
            floor,
            task,
            joint_min,
            joint_max,
            filtered,
        )
        senses_out[0] = filtered
    smoothing = 1.0 - math.exp(-dt / task.filter_time) if task.filter_time > 0.0 else 1.0
    rule = 0
    if carry_over and not time_based:
        rule = active_rule(senses_out[0], center, side, weights, 0)
    rule_out[0] = rule
    heading_start = heading_of(frames, rotation, task.heading_rod, task.heading_offset)
    heading = heading_start
    forward_x = math.cos(heading_start)
    forward_z = -math.sin(heading_start)
    start_x = state[CX]
    start_z = state[CZ]
    max_height = state[CY]
    min_height = state[CY]
    deviation = 0.0
    fallen_steps = 0
    foot_steps = 0
    last_foot = -1
    foot_lift = np.zeros(n_feet)  # each foot's highest point since it left the floor, m
    for n in range(steps):
        if not state_is_sound(state):
            return stop_unsound(n, state, end_force, terms_out, final_state, final_force)
        step(figure, state, target[rule], tau[rule], dt, work, recording)
        rotation = matrices[0]
        fallen = state[CY] < task.fall_height
        for e in range(n_ends):
            y = state[CY] + (
                rotation[1, 0] * end_offset[e, 0]
                + rotation[1, 1] * end_offset[e, 1]
                + rotation[1, 2] * end_offset[e, 2]
            )
            now_touching = not math.isnan(floor) and y <= floor + CONTACT_TOLERANCE
            for f in range(n_feet):
                if task.feet[f] != e:
                    continue
                if not now_touching:
                    foot_lift[f] = max(foot_lift[f], y - floor)
                    continue
                if not touching[e] and foot_lift[f] >= STEP_LIFT:
                    # a touch-down after a lift: a step if another foot made the last one
                    if f != last_foot:
                        foot_steps += 1
                    last_foot = f
                foot_lift[f] = 0.0
            touching[e] = now_touching
        for f in range(task.falls.shape[0]):
            if touching[task.falls[f]]:
                fallen = True
        if fallen:
            fallen_steps += 1
        max_height = max(max_height, state[CY])
        min_height = min(min_height, state[CY])
        now = heading_of(frames, rotation, task.heading_rod, task.heading_offset)
        turned = now - heading
        turned -= 2.0 * math.pi * math.floor((turned + math.pi) / (2.0 * math.pi))
        heading += turned
        deviation += abs(heading - heading_start)
        if sensing:
            conjugate(rotation, matrices[2], world_inverse)
            measure_senses(
                state,
                rotation,
                world_inverse,
                vectors[0, :3],
                end_force,
                weight,
                floor,
                task,
                joint_min,
                joint_max,
                raw,
            )
            for v in range(PHYSICAL_SENSES + n_ends):
                filtered[v] += smoothing * (raw[v] - filtered[v])
            for v in range(PHYSICAL_SENSES + n_ends, raw.shape[0]):
                filtered[v] = raw[v]
            senses_out[n + 1] = filtered
        if time_based:
            rule = segment_rule((n + 1) * dt, segment_end, period)
        else:
            rule = active_rule(senses_out[n + 1], center, side, weights, rule)
        rule_out[n + 1] = rule
        if recording:
            ends_out[n + 1] = rod_ends
            com_out[n + 1, 0] = state[CX]
            com_out[n + 1, 1] = state[CY]
            com_out[n + 1, 2] = state[CZ]
    if not state_is_sound(state):
        return stop_unsound(steps, state, end_force, terms_out, final_state, final_force)
    dx = state[CX] - start_x
    dz = state[CZ] - start_z
    terms_out[DISTANCE] = dx * forward_x + dz * forward_z
    terms_out[SIDEWAYS] = abs(dx * forward_z - dz * forward_x)
    terms_out[HEADING_CHANGE] = math.degrees(heading - heading_start)
    terms_out[MAX_HEIGHT] = max_height
    terms_out[FALL] = fallen_steps / steps
    terms_out[HEADING_DEVIATION] = math.degrees(deviation / steps)
    feet_distance = 0.0
    rotation = matrices[0]
    for f in range(n_feet):
        e = task.feet[f]
        x, _, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
        feet_distance += (state[CX] + x - foot_start[f, 0]) * forward_x
        feet_distance += (state[CZ] + z - foot_start[f, 2]) * forward_z
    terms_out[FEET_DISTANCE] = feet_distance / n_feet if n_feet > 0 else 0.0
    terms_out[FOOT_STEPS] = foot_steps
    terms_out[MIN_HEIGHT] = min_height
    terms_out[HEADING_SINE] = math.sin(heading - heading_start)
    # the body's rate at the end: I⁻¹ (L - h) in the world (the deformation's own spin h)
    conjugate(rotation, matrices[2], world_inverse)
    wx, wy, wz = rigid_rate(state, rotation, world_inverse, vectors[0, :3])
    terms_out[FINAL_SPIN] = math.degrees(math.sqrt(wx * wx + wy * wy + wz * wz))
    final_state[:] = own_state  # (its last use: the borrowed state's memory is kept to here)
    final_force[:] = own_work.end_force  # (as own_work's, the borrowed work's)
    return steps


@njit(cache=True, parallel=True)
def run_population(
    figure,
    controllers,
    task,
    starts,
    steps,
    dt,
    senses_out,
    rule_out,
    terms_out,
    taken_out,
    final_out,
):
    """``run_controller`` for C controllers at once, in parallel (each run is independent, so
    the results do not depend on the number of threads): controllers a ControllerArrays whose
    arrays have a leading axis C, starts (C, S); fills senses_out (C, steps + 1, V), rule_out
    (C, steps + 1), terms_out (C, TERM_COUNT), taken_out (C,) int64 what each run returned
    (steps, or ``blown_up(n)`` < 0: its terms are NaN) and final_out (C, S) each run's last
    state (the unsound one where it stopped)."""
    n_rods = figure.parent.shape[0]
    n_ends = figure.endpoints.shape[0]
    for c in prange(starts.shape[0]):
        controller = ControllerArrays(
            controllers.time_based,
            controllers.target[c],
            controllers.tau[c],
            controllers.center[c],
            controllers.side[c],
            controllers.segment_end[c],
            controllers.period,
        )
        record = RunRecord(
            senses_out[c],
            rule_out[c],
            terms_out[c],
            np.empty((0, n_rods, 2, 3)),
            np.empty((0, 3)),
            final_out[c],
            np.empty(n_ends),
        )
        taken_out[c] = run_controller(
            figure,
            controller,
            task,
            starts[c],
            np.zeros(n_ends),
            np.bool_(False),  # a bool, not the literal False: the run_controller a call
            steps,  # from Python compiles (a literal is a signature of its own)
            dt,
            record,
        )
