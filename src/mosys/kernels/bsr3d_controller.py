"""Running BSR controllers of a 3-D figure (the 1995 paper's §4): the simulator steps, the
senses of §4.2, rule selection (shared with 2-D), and the 3-D fitness terms; four runs at once
in lockstep (``run_lockstep``: their body frames in vector lanes), one run as a lockstep of one
(``run_controller``); a population in groups of four is ``kernels.bsr3d_population``'s.

Senses (V = 10 + E + F, each normalised to [0, 1] and clipped), in this order: the centre of
mass's height over the floor ``y / (2 h0)``; its velocity, the body's angular velocity and the
world's up vector, each as three components in the figure-centric (body) frame, ``0.5 + v / (2
v0)``, ``0.5 + ω / (2 ω0)`` and ``0.5 + up / 2``; per endpoint the ground's normal force over
the step ``f / (2 M g)`` (every contact of this simulator is an impulse, so an endpoint's force
over a step is its collision impulse over dt: one sense carries both of the paper's); and the
angle of each free (flexible) joint angle ``(θ - min) / (max - min)``. ``h0`` is the standing
centre-of-mass height, ``v0 = sqrt(g h0)`` and ``ω0 = v0 / h0`` (``Task.scales``). The physical
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
search of a chain starts there); ``net_rotation`` |heading change|, deg (footnote 10's "net
rotation about the vertical axis", whichever way).

A run stops where the state is not sound (``kernels.soundness.state_is_sound``), as the 2-D
one does: checked before every step and after the last, it returns ``blown_up(step)`` (< 0);
the other runs of its lockstep go on.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from mosys.kernels.borrowed import borrowed, keep_alive
from mosys.kernels.bsr3d_lanes import body_frame_lanes
from mosys.kernels.bsr3d_simulate import (
    CX,
    CY,
    CZ,
    JOINTS,
    VX,
    joint_trig,
    lane_work,
    new_step_works,
    place_in_world,
    rigid_rate,
    start_step_work,
    step_deform,
    step_motion,
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
from mosys.kernels.lanes import LANES
from mosys.kernels.rotation3d import apply, conjugate
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
    NET_ROTATION,
) = range(12)
TERM_COUNT = 12
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


class Tally(NamedTuple):
    """What a 3-D run keeps between steps toward its fitness terms (``new_tallies``; K feet, E
    endpoints): ``touching`` (E,) bool each endpoint within the contact tolerance of the floor
    after the last step, ``foot_lift`` (K,) m each foot's highest point over the floor since it
    left it, ``foot_start`` (K, 3) m each foot at the start (x and z), ``sums`` (SUMS,) the
    running numbers indexed by HEADING_START ... DEVIATION, ``counts`` (3,) int64 the fallen
    steps, the foot steps and the foot that made the last one (-1: none yet)."""

    touching: np.ndarray
    foot_lift: np.ndarray
    foot_start: np.ndarray
    sums: np.ndarray
    counts: np.ndarray


# Tally.sums: headings rad, the forward direction's x and z, the start's x and z m, the com's
# highest and lowest height m, the sum over steps of |heading - heading at the start| rad
(HEADING_START, HEADING, FORWARD_X, FORWARD_Z, START_X, START_Z, HIGHEST, LOWEST, DEVIATION) = (
    range(9)
)
# Tally.counts
FALLEN_STEPS, STEPS_TAKEN, LAST_FOOT = range(3)


@njit(cache=True)
def new_tallies(lanes, n_ends, n_feet):
    """Empty Tallies for ``lanes`` runs of a figure of E = n_ends endpoints and K = n_feet feet:
    one Tally whose arrays have a leading axis ``lanes`` (``lane_tally``; ``start_tally`` fills
    each)."""
    return Tally(
        np.zeros((lanes, n_ends), np.bool_),
        np.zeros((lanes, n_feet)),
        np.zeros((lanes, n_feet, 3)),
        np.zeros((lanes, 9)),
        np.zeros((lanes, 3), np.int64),
    )


@njit(cache=True, inline="always")
def lane_tally(tallies, lane):
    """Lane ``lane``'s Tally of ``tallies`` (``new_tallies``)."""
    return Tally(
        tallies.touching[lane],
        tallies.foot_lift[lane],
        tallies.foot_start[lane],
        tallies.sums[lane],
        tallies.counts[lane],
    )


@njit(cache=True, inline="always", error_model="numpy")
def start_tally(state, work, floor, task, tally):
    """Fill the Tally ``tally`` for a run starting at the state (S,) with the StepWork ``work``
    (its rotation, endpoints and the heading rod's frame; ``start_step_work``)."""
    rotation = work.matrices[0]
    end_offset = work.end_offset
    frames = work.frames
    touching, _, foot_start, sums, counts = tally
    for e in range(end_offset.shape[0]):
        y = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])[1]
        touching[e] = not math.isnan(floor) and state[CY] + y <= floor + CONTACT_TOLERANCE
    for f in range(task.feet.shape[0]):
        e = task.feet[f]
        x, _, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
        foot_start[f, 0] = state[CX] + x
        foot_start[f, 2] = state[CZ] + z
    heading_start = heading_of(frames, rotation, task.heading_rod, task.heading_offset)
    sums[HEADING_START] = heading_start
    sums[HEADING] = heading_start
    sums[FORWARD_X] = math.cos(heading_start)
    sums[FORWARD_Z] = -math.sin(heading_start)
    sums[START_X] = state[CX]
    sums[START_Z] = state[CZ]
    sums[HIGHEST] = state[CY]
    sums[LOWEST] = state[CY]
    counts[LAST_FOOT] = -1


@njit(cache=True, inline="always", error_model="numpy")
def tally_step(state, work, floor, task, tally):
    """Count a step that ended at the state (S,) (``work`` as ``start_tally`` reads it) into
    ``tally``: touch-downs, falls, heights, heading."""
    rotation = work.matrices[0]
    end_offset = work.end_offset
    frames = work.frames
    touching, foot_lift, _, sums, counts = tally
    n_feet = task.feet.shape[0]
    fallen = state[CY] < task.fall_height
    for e in range(end_offset.shape[0]):
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
                if f != counts[LAST_FOOT]:
                    counts[STEPS_TAKEN] += 1
                counts[LAST_FOOT] = f
            foot_lift[f] = 0.0
        touching[e] = now_touching
    for f in range(task.falls.shape[0]):
        if touching[task.falls[f]]:
            fallen = True
    if fallen:
        counts[FALLEN_STEPS] += 1
    sums[HIGHEST] = max(sums[HIGHEST], state[CY])
    sums[LOWEST] = min(sums[LOWEST], state[CY])
    now = heading_of(frames, rotation, task.heading_rod, task.heading_offset)
    turned = now - sums[HEADING]
    turned -= 2.0 * math.pi * math.floor((turned + math.pi) / (2.0 * math.pi))
    sums[HEADING] += turned
    sums[DEVIATION] += abs(sums[HEADING] - sums[HEADING_START])


@njit(cache=True, inline="always", error_model="numpy")
def tally_terms(state, work, task, tally, steps, terms_out):
    """Fill terms_out (TERM_COUNT,) from the tally of a run of ``steps`` steps that ended at
    the state (S,) with the StepWork ``work`` (its rotation, inverse inertia and spin)."""
    _, _, foot_start, sums, counts = tally
    forward_x = sums[FORWARD_X]
    forward_z = sums[FORWARD_Z]
    dx = state[CX] - sums[START_X]
    dz = state[CZ] - sums[START_Z]
    turned = sums[HEADING] - sums[HEADING_START]
    terms_out[DISTANCE] = dx * forward_x + dz * forward_z
    terms_out[SIDEWAYS] = abs(dx * forward_z - dz * forward_x)
    terms_out[HEADING_CHANGE] = math.degrees(turned)
    terms_out[MAX_HEIGHT] = sums[HIGHEST]
    terms_out[FALL] = counts[FALLEN_STEPS] / steps
    terms_out[HEADING_DEVIATION] = math.degrees(sums[DEVIATION] / steps)
    feet_distance = 0.0
    rotation = work.matrices[0]
    end_offset = work.end_offset
    n_feet = task.feet.shape[0]
    for f in range(n_feet):
        e = task.feet[f]
        x, _, z = apply(rotation, end_offset[e, 0], end_offset[e, 1], end_offset[e, 2])
        feet_distance += (state[CX] + x - foot_start[f, 0]) * forward_x
        feet_distance += (state[CZ] + z - foot_start[f, 2]) * forward_z
    terms_out[FEET_DISTANCE] = feet_distance / n_feet if n_feet > 0 else 0.0
    terms_out[FOOT_STEPS] = counts[STEPS_TAKEN]
    terms_out[MIN_HEIGHT] = sums[LOWEST]
    terms_out[HEADING_SINE] = math.sin(turned)
    terms_out[NET_ROTATION] = abs(math.degrees(turned))
    # the body's rate at the end: I⁻¹ (L - h) in the world (the deformation's own spin h)
    world_inverse = work.matrices[3]
    conjugate(rotation, work.matrices[2], world_inverse)
    wx, wy, wz = rigid_rate(state, rotation, world_inverse, work.vectors[0, :3])
    terms_out[FINAL_SPIN] = math.degrees(math.sqrt(wx * wx + wy * wy + wz * wz))


@njit(cache=True, inline="always", error_model="numpy")
def sense_step(state, work, weight, task, figure, smoothing, raw, filtered):
    """Measure the senses after a step into raw (V,) and low-pass them into filtered (V,) (the
    physical ones with the factor ``smoothing``; the joint angles as measured); weight = M g N."""
    end_force = work.end_force
    rotation = work.matrices[0]
    world_inverse = work.matrices[3]
    conjugate(rotation, work.matrices[2], world_inverse)
    measure_senses(
        state,
        rotation,
        world_inverse,
        work.vectors[0, :3],
        end_force,
        weight,
        figure.floor,
        task,
        figure.joint_min,
        figure.joint_max,
        raw,
    )
    physical = PHYSICAL_SENSES + end_force.shape[0]
    for v in range(physical):
        filtered[v] += smoothing * (raw[v] - filtered[v])
    for v in range(physical, raw.shape[0]):
        filtered[v] = raw[v]


@njit(cache=True, inline="always")
def _lane_work(works, lane, rod_ends, end_offset, end_velocity, frames):
    """Lane ``lane``'s StepWork of ``works`` (``new_step_works``), its body frame's arrays the
    lane's views of the lanes-last ones (``body_frame_lanes``)."""
    return lane_work(
        works,
        lane,
        rod_ends[:, :, :, lane],
        end_offset[:, :, lane],
        end_velocity[:, :, lane],
        frames[:, :, :, lane],
    )


@njit(cache=True, inline="always")
def _stopped_unsound(step, c, state, work, records, taken_out):
    """If the state (S,) of run c is not sound before step ``step`` (``state_is_sound``), stop
    the run there (``stop_unsound``: its terms NaN, its final state and forces the unsound
    ones, taken_out[c] ``blown_up(step)``) and return True; else False."""
    if state_is_sound(state):
        return False
    taken_out[c] = stop_unsound(
        step,
        state,
        work.end_force,
        records.terms_out[c],
        records.final_state[c],
        records.final_force[c],
    )
    return True


@njit(cache=True, error_model="numpy")
def run_lockstep(
    figure,
    controllers,
    task,
    members,
    starts,
    start_forces,
    carry_over,
    steps,
    dt,
    records,
    taken_out,
):
    """Run the controllers ``members`` (LANES,) int64 (-1: an empty lane) of ``controllers`` (a
    ControllerArrays whose arrays have a leading axis C) of the 3-D figure (a FigureArrays3D)
    for ``steps`` steps of dt seconds at once, in lockstep: lane i runs controller c =
    members[i] from the state starts[c] (C, S) with the endpoints' normal forces
    start_forces[c] (C, E) N, measuring as ``task`` (a Task) says, filling lane c of
    ``records`` (a RunRecord whose arrays have a leading axis C) and taken_out[c] (taken_out
    (C,) int64: what the run of c returns). carry_over: start with the rule the senses pick (a
    controller continuing another) instead of rule 0.

    Each step deforms every lane's figure, computes the lanes' body frames at once in vector
    lanes (``bsr3d_lanes.body_frame_lanes``, bit for bit the scalar ``body_frame``), then moves
    and measures each lane's figure. A lane's numbers do not depend on the others (tested): a
    run is the same alone (``run_controller``) as in a population (``bsr3d_population``). A run
    returns ``steps``, or ``blown_up(n)`` (< 0) if the state is not sound (``state_is_sound``)
    before step n (n = steps: after the last), as the 2-D run_controller: the samples 0 to n
    recorded, its terms NaN, its final state the unsound one; the other lanes go on. Its arrays
    are borrowed (``kernels.borrowed``), so that the step loop raises and lowers no reference
    count."""
    figure = borrowed(figure)
    task = borrowed(task)
    controllers = borrowed(controllers)
    records = borrowed(records)
    parent, joint, endpoints = figure.parent, figure.joint, figure.endpoints
    senses_out, rule_out, terms_out, ends_out, com_out, final_out, final_force = records
    floor = figure.floor
    time_based = controllers.time_based
    n_rods = parent.shape[0]
    n_ends = endpoints.shape[0]
    n_joints = figure.joint_min.shape[0]
    n_senses = senses_out.shape[2]
    sensing = n_senses > 0
    recording = ends_out.shape[1] == steps + 1
    # the body frames' inputs and outputs, lanes last (``body_frame_lanes``): each lane's work
    # reads and writes its rods' and endpoints' frames, ends and velocities there
    own_trig = np.ones((4, n_rods, LANES))
    own_rates = np.zeros((n_joints, LANES))
    own_rod_ends = np.empty((n_rods, 2, 3, LANES))
    own_end_offset = np.empty((n_ends, 3, LANES))
    own_end_velocity = np.empty((n_ends, 3, LANES))
    own_frames = np.empty((n_rods, 3, 3, LANES))
    own_rod_work = np.empty((5, n_rods, 3, LANES))
    own_tensor = np.empty((3, 3, LANES))
    own_spin = np.empty((3, LANES))
    own_states = np.empty((LANES, starts.shape[1]))
    own_works = new_step_works(LANES, n_rods, n_ends)
    own_tallies = new_tallies(LANES, n_ends, task.feet.shape[0])
    own_weights = np.empty((LANES, controllers.side.shape[1]))
    own_raw = np.empty((LANES, n_senses))
    own_filtered = np.empty((LANES, n_senses))
    own_moving = np.zeros(n_rods, np.bool_)  # rods with an angle that is not fixed
    own_rules = np.zeros(LANES, np.int64)
    own_live = members >= 0
    trig = borrowed(own_trig)
    rates = borrowed(own_rates)
    rod_ends = borrowed(own_rod_ends)
    end_offset = borrowed(own_end_offset)
    end_velocity = borrowed(own_end_velocity)
    frames = borrowed(own_frames)
    rod_work = borrowed(own_rod_work)
    tensor = borrowed(own_tensor)
    spin = borrowed(own_spin)
    states = borrowed(own_states)
    works = borrowed(own_works)
    tallies = borrowed(own_tallies)
    weights = borrowed(own_weights)
    raw = borrowed(own_raw)
    filtered = borrowed(own_filtered)
    moving = borrowed(own_moving)
    rules = borrowed(own_rules)
    live = borrowed(own_live)
    for k in range(n_rods):
        j = joint[k]
        if j >= 0:
            for a in range(j, j + 2):
                moving[k] |= figure.joint_min[a] != figure.joint_max[a]
    weight = figure.mass.sum() * figure.gravity
    smoothing = 1.0 - math.exp(-dt / task.filter_time) if task.filter_time > 0.0 else 1.0
    for lane in range(LANES):
        if not live[lane]:
            continue
        c = members[lane]
        state = states[lane]
        work = _lane_work(works, lane, rod_ends, end_offset, end_velocity, frames)
        state[:] = starts[c]
        work.end_force[:] = start_forces[c]
        weights[lane] = rule_weights(controllers.side[c])
        start_step_work(figure, state, work)
        start_tally(state, work, floor, task, lane_tally(tallies, lane))
        if recording:
            place_in_world(state, work.matrices[0], work.rod_ends, ends_out[c, 0])
            com_out[c, 0] = state[CX : CX + 3]
        if sensing:
            matrices = work.matrices
            conjugate(matrices[0], matrices[2], matrices[3])
            measure_senses(
                state,
                matrices[0],
                matrices[3],
                work.vectors[0, :3],
                work.end_force,
                weight,
                floor,
                task,
                figure.joint_min,
                figure.joint_max,
                filtered[lane],
            )
            senses_out[c, 0] = filtered[lane]
        if carry_over and not time_based:
            rules[lane] = active_rule(
                senses_out[c, 0], controllers.center[c], controllers.side[c], weights[lane], 0
            )
        rule_out[c, 0] = rules[lane]
    for n in range(steps):
        running = 0
        for lane in range(LANES):
            if not live[lane]:
                continue
            c = members[lane]
            state = states[lane]
            work = _lane_work(works, lane, rod_ends, end_offset, end_velocity, frames)
            if _stopped_unsound(n, c, state, work, records, taken_out):
                live[lane] = False
                continue
            running += 1
            rule = rules[lane]
            target = controllers.target[c, rule]
            step_deform(figure, state, target, controllers.tau[c, rule], dt, work)
            joint_trig(parent, joint, state[JOINTS : JOINTS + n_joints], work.scratch)
            for k in range(n_rods):
                if n == 0 or moving[k]:
                    for t in range(4):
                        trig[t, k, lane] = work.scratch[k, 5 + t // 2, 1 + t % 2]
            for j in range(n_joints):
                rates[j, lane] = state[JOINTS + n_joints + j]
        if running == 0:
            break
        total_mass = body_frame_lanes(
            figure, trig, rates, rod_ends, end_offset, end_velocity, frames, rod_work, tensor, spin
        )
        for lane in range(LANES):
            if not live[lane]:
                continue
            c = members[lane]
            state = states[lane]
            work = _lane_work(works, lane, rod_ends, end_offset, end_velocity, frames)
            for a in range(3):
                for b in range(3):
                    work.matrices[1, a, b] = tensor[a, b, lane]
                work.vectors[0, a] = spin[a, lane]
            step_motion(figure, state, dt, work, total_mass, recording)
            tally_step(state, work, floor, task, lane_tally(tallies, lane))
            if sensing:
                sense_step(state, work, weight, task, figure, smoothing, raw[lane], filtered[lane])
                senses_out[c, n + 1] = filtered[lane]
            if time_based:
                rule = segment_rule((n + 1) * dt, controllers.segment_end[c], controllers.period)
            else:
                rule = active_rule(
                    senses_out[c, n + 1],
                    controllers.center[c],
                    controllers.side[c],
                    weights[lane],
                    rules[lane],
                )
            rules[lane] = rule
            rule_out[c, n + 1] = rule
            if recording:
                ends_out[c, n + 1] = work.rod_ends
                com_out[c, n + 1] = state[CX : CX + 3]
    for lane in range(LANES):
        if not live[lane]:
            continue
        c = members[lane]
        state = states[lane]
        work = _lane_work(works, lane, rod_ends, end_offset, end_velocity, frames)
        if _stopped_unsound(steps, c, state, work, records, taken_out):
            continue
        tally_terms(state, work, task, lane_tally(tallies, lane), steps, terms_out[c])
        final_out[c] = state
        final_force[c] = work.end_force
        taken_out[c] = steps
    # the owned arrays' last uses: their borrowed views' memory is kept to here
    keep_alive((own_trig, own_rates, own_rod_ends, own_end_offset, own_end_velocity, own_frames))
    keep_alive((own_rod_work, own_tensor, own_spin, own_states, own_weights, own_raw))
    keep_alive((own_filtered, own_moving, own_rules, own_live))
    keep_alive(own_works)
    keep_alive(own_tallies)


@njit(cache=True, inline="always")
def _one(array):
    """``array`` as the only row of an array with a leading axis of 1 (a view)."""
    return array.reshape((1,) + array.shape)


@njit(cache=True, error_model="numpy")
def run_controller(figure, controller, task, start, start_force, carry_over, steps, dt, record):
    """Run a controller (a ControllerArrays) of the 3-D figure (a FigureArrays3D) for ``steps``
    steps of dt seconds from the state ``start`` (S,), measuring as ``task`` (a Task) says,
    filling ``record`` (a RunRecord). start_force (E,): the endpoints' normal forces at the
    start, N; carry_over: start with the rule the senses pick (a controller continuing another)
    instead of rule 0. ``run_lockstep`` with this run in one lane: returns ``steps``, or
    ``blown_up(n)`` (< 0) if the state is not sound before step n, as that says."""
    members = np.full(LANES, -1, np.int64)
    members[0] = 0
    taken = np.zeros(1, np.int64)
    run_lockstep(
        figure,
        ControllerArrays(
            controller.time_based,
            _one(controller.target),
            _one(controller.tau),
            _one(controller.center),
            _one(controller.side),
            _one(controller.segment_end),
            controller.period,
        ),
        task,
        members,
        _one(start),
        _one(start_force),
        carry_over,
        steps,
        dt,
        RunRecord(
            _one(record.senses_out),
            _one(record.rule_out),
            _one(record.terms_out),
            _one(record.ends_out),
            _one(record.com_out),
            _one(record.final_state),
            _one(record.final_force),
        ),
        taken,
    )
    return taken[0]
