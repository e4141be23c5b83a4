"""Running a BSR controller (the 1995 paper's Figure 2): the simulator steps, the sense variables
of Table 1, rule selection, and the fitness terms of the run; a population at once in parallel.

Sense variables (V = J + E + 2, each normalised to [0, 1] and clipped): joint angle j as
``(θ_j - min_j) / (max_j - min_j)``; the ground's normal force on endpoint e over the figure's
weight ``f_e / (M g)``; the centre of mass's height over the floor over the figure's reach
``y_cm / reach``; its vertical velocity ``0.5 + vy / (2 sqrt(2 g reach))``.

Fitness terms (the columns DISTANCE, MAX_HEIGHT, CONTACT_DISTANCE, ROTATIONS, FALL of
terms_out; ``parsing.bsr.FITNESS_TERMS`` names them in this order): ``distance`` com x at the end
minus at the start, m; ``max_height`` the largest com y, m; ``contact_distance`` the horizontal
distance travelled by endpoints while they touch the floor (within ``CONTACT_TOLERANCE``) at both
ends of a step, m; ``rotations`` |net rotation of the root rod| / 360°; ``fall`` the fraction of
steps that end with one of the ``fall`` endpoints touching the floor.

A run stops where the state is not sound (``kernels.soundness.state_is_sound``: NaN, inf or beyond
±STATE_LIMIT; checked before every step and after the last, which leaves the arithmetic of a
sound run as it was) and returns ``blown_up(step)`` (< 0) instead of the steps it took.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from mosys.kernels.bsr_simulate import (
    CONTACT_TOLERANCE,
    CX,
    CY,
    JOINTS,
    PHI,
    VY,
    endpoint_position,
    figure_body_frame,
    place_in_world,
    step,
)
from mosys.kernels.soundness import blown_up, state_is_sound

# Table 2 of the paper: a rule's hyper-rectangle side 2/lambda lies in [SIDE_MIN, SIDE_MAX], so
# lambda_min = 2 / SIDE_MAX (the rule weights below); centres are drawn in [CENTER_MIN, CENTER_MAX].
SIDE_MIN = 0.4
SIDE_MAX = 4.0
CENTER_MIN = -0.5
CENTER_MAX = 1.5
# the columns of terms_out
DISTANCE, MAX_HEIGHT, CONTACT_DISTANCE, ROTATIONS, FALL = range(5)
TERM_COUNT = 5


@njit(cache=True)
def measure_senses(state, joint_min, joint_max, end_force, weight, floor, reach, gravity, out):
    """Fill out (V,) with the normalised sense variables of the state (S,) and the endpoint
    forces (E,) N; weight = M g, N; reach m."""
    n_joints = joint_min.shape[0]
    for j in range(n_joints):
        value = (state[JOINTS + j] - joint_min[j]) / (joint_max[j] - joint_min[j])
        out[j] = min(max(value, 0.0), 1.0)
    for e in range(end_force.shape[0]):
        out[n_joints + e] = min(max(end_force[e] / weight, 0.0), 1.0)
    base = 0.0 if math.isnan(floor) else floor
    out[n_joints + end_force.shape[0]] = min(max((state[CY] - base) / reach, 0.0), 1.0)
    speed_scale = 2.0 * math.sqrt(2.0 * gravity * reach)
    out[n_joints + end_force.shape[0] + 1] = min(max(0.5 + state[VY] / speed_scale, 0.0), 1.0)


@njit(cache=True)
def rule_weights(side):
    """W_i = sum_j log(lambda_ij / lambda_min) of every rule: side (R, V) -> (R,)."""
    weights = np.zeros(side.shape[0])
    for i in range(side.shape[0]):
        for j in range(side.shape[1]):
            weights[i] += math.log(SIDE_MAX / side[i, j])
    return weights


@njit(cache=True)
def active_rule(senses, center, side, weights, previous):
    """The rule with the highest positive score W (1 - max_j [lambda_j (S_j - mu_j)]²), or
    ``previous`` if no score is positive. senses (V,); center, side (R, V); weights (R,)."""
    best = previous
    best_score = 0.0
    for i in range(center.shape[0]):
        worst = 0.0
        for j in range(senses.shape[0]):
            reach = 2.0 * (senses[j] - center[i, j]) / side[i, j]
            worst = max(worst, reach * reach)
            if worst >= 1.0:
                break
        score = weights[i] * (1.0 - worst)
        if score > best_score:
            best_score = score
            best = i
    return best


@njit(cache=True)
def segment_rule(time, segment_end, period):
    """The rule of a time-based controller at ``time`` s: the segment of ``time mod period``
    (segment_end (R,): cumulative ends, s, the last equal to period)."""
    phase = time - period * math.floor(time / period)
    for i in range(segment_end.shape[0]):
        if phase < segment_end[i]:
            return i
    return segment_end.shape[0] - 1


class ControllerArrays(NamedTuple):
    """A controller as the kernels take it (R rules, J joints, V senses): sense-based
    (time_based False), center and side select the rule; time-based, segment_end and period
    do. In ``run_population`` every array has a leading axis C, one controller each."""

    time_based: bool
    target: np.ndarray  # (R, J) rad: each rule's target pose
    tau: np.ndarray  # (R,) s: each rule's time constant
    center: np.ndarray  # (R, V): each rule's hyper-rectangle centre
    side: np.ndarray  # (R, V): each rule's hyper-rectangle side
    segment_end: np.ndarray  # (R,) s: cumulative ends of a time-based controller's segments
    period: float  # s: a time-based controller's period


class RunRecord(NamedTuple):
    """What ``run_controller`` fills (this one's and the 3-D one's, D = 2 or 3): senses_out
    (steps + 1, V) and rule_out (steps + 1,) (sample 0: the start), terms_out (TERM_COUNT,);
    ends_out (steps + 1, N, 2, D) and com_out (steps + 1, D), world metres, if ends_out has
    steps + 1 rows (else nothing is recorded); final_state (S,) and final_force (E,) N: the
    state and the endpoints' forces at the end. The 3-D run may pass senses_out (steps + 1, 0)
    for a time-based controller (it then measures no senses)."""

    senses_out: np.ndarray
    rule_out: np.ndarray
    terms_out: np.ndarray
    ends_out: np.ndarray
    com_out: np.ndarray
    final_state: np.ndarray
    final_force: np.ndarray


@njit(cache=True)
def stop_unsound(step, state, end_force, terms_out, final_state, final_force):
    """End a run (2-D or 3-D) whose state (S,) is not sound before step ``step`` (the step count:
    after the last): terms_out (T,) becomes NaN (no fitness), final_state and final_force take
    the unsound state and the endpoints' forces (E,) N. Returns ``blown_up(step)``."""
    terms_out[:] = np.nan
    final_state[:] = state
    final_force[:] = end_force
    return blown_up(step)


@njit(cache=True)
def run_controller(figure, controller, start, start_force, carry_over, steps, dt, falls, record):
    """Run a controller (a ControllerArrays) of the figure (a FigureArrays) for ``steps`` steps
    of dt seconds from the state ``start`` (S,), filling ``record`` (a RunRecord). Returns
    ``steps``, or ``blown_up(n)`` (< 0) if the state is not sound (``state_is_sound``) before step
    n (n = steps: after the last): then the samples 0 to n are recorded (sample n the unsound
    state), terms_out is NaN and final_state the unsound state (``stop_unsound``).

    Long on purpose: the tuples are unpacked once, before the step loop, and the loop is one
    piece (the module docstring of ``mosys.kernels.bsr_simulate`` says why).

    start_force (E,): the endpoints' normal forces at the start, N (zeros for a fresh start);
    carry_over: a controller taking over from another (a composite motion) starts with the rule
    its score picks from the carried-over senses (rule 0 if none scores positive) instead of
    rule 0, as Figure 2 begins. falls (F,) int64: the endpoints that count as a fall.
    """
    parent, hinge, offset, length, mass, com, inertia, joint, endpoints = figure[:9]
    joint_min, joint_max, gravity, floor, reach = figure[9:]
    time_based, target, tau, center, side, segment_end, period = controller
    senses_out, rule_out, terms_out, ends_out, com_out, final_state, final_force = record
    state = start.copy()
    n_rods = parent.shape[0]
    n_ends = endpoints.shape[0]
    rod_ends = np.empty((n_rods, 2, 2))
    end_offset = np.empty((n_ends, 2))
    end_velocity = np.empty((n_ends, 2))
    end_force = start_force.copy()
    end_x = np.empty(n_ends)
    touching = np.zeros(n_ends, np.bool_)
    previous = np.zeros(1)
    scratch = np.empty((n_rods, 8))
    contact = np.empty((3, 2, 2))
    entry = np.empty((n_ends, 2))
    weight = mass.sum() * gravity
    recording = ends_out.shape[0] == steps + 1
    weights = rule_weights(side)
    # the start: its pose, no forces yet
    n_joints = joint_min.shape[0]
    theta = state[JOINTS : JOINTS + n_joints]
    theta_rate = state[JOINTS + n_joints : JOINTS + 2 * n_joints]
    _, total_inertia, deformation_momentum = figure_body_frame(
        figure, theta, theta_rate, rod_ends, end_offset, end_velocity, scratch
    )
    previous[0] = deformation_momentum / total_inertia
    cos_phi = math.cos(state[PHI])
    sin_phi = math.sin(state[PHI])
    for e in range(n_ends):
        end_x[e], y = endpoint_position(state, cos_phi, sin_phi, end_offset, e)
        touching[e] = not math.isnan(floor) and y <= floor + CONTACT_TOLERANCE
    if recording:
        place_in_world(state, cos_phi, sin_phi, rod_ends, ends_out[0])
        com_out[0, 0] = state[CX]
        com_out[0, 1] = state[CY]
    measure_senses(
        state, joint_min, joint_max, end_force, weight, floor, reach, gravity, senses_out[0]
    )
    rule = 0
    if carry_over and not time_based:
        rule = active_rule(senses_out[0], center, side, weights, 0)
    rule_out[0] = rule
    start_x = state[CX]
    start_phi = state[PHI]
    max_height = state[CY]
    contact_distance = 0.0
    fallen_steps = 0
    for n in range(steps):
        if not state_is_sound(state):
            return stop_unsound(n, state, end_force, terms_out, final_state, final_force)
        step(
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
            target[rule],
            tau[rule],
            dt,
            previous,
            rod_ends,
            end_offset,
            end_velocity,
            end_force,
            scratch,
            contact,
            entry,
        )
        cos_phi = math.cos(state[PHI])
        sin_phi = math.sin(state[PHI])
        fallen = False
        for e in range(n_ends):
            x, y = endpoint_position(state, cos_phi, sin_phi, end_offset, e)
            now_touching = not math.isnan(floor) and y <= floor + CONTACT_TOLERANCE
            if now_touching and touching[e]:
                contact_distance += abs(x - end_x[e])
            end_x[e] = x
            touching[e] = now_touching
        for f in range(falls.shape[0]):
            if touching[falls[f]]:
                fallen = True
        if fallen:
            fallen_steps += 1
        max_height = max(max_height, state[CY])
        measure_senses(
            state, joint_min, joint_max, end_force, weight, floor, reach, gravity, senses_out[n + 1]
        )
        if time_based:
            rule = segment_rule((n + 1) * dt, segment_end, period)
        else:
            rule = active_rule(senses_out[n + 1], center, side, weights, rule)
        rule_out[n + 1] = rule
        if recording:
            ends_out[n + 1] = rod_ends
            com_out[n + 1, 0] = state[CX]
            com_out[n + 1, 1] = state[CY]
    if not state_is_sound(state):
        return stop_unsound(steps, state, end_force, terms_out, final_state, final_force)
    terms_out[DISTANCE] = state[CX] - start_x
    terms_out[MAX_HEIGHT] = max_height
    terms_out[CONTACT_DISTANCE] = contact_distance
    terms_out[ROTATIONS] = abs(state[PHI] - start_phi) / (2.0 * math.pi)
    terms_out[FALL] = fallen_steps / steps
    final_state[:] = state
    final_force[:] = end_force
    return steps


@njit(cache=True, parallel=True)
def run_population(
    figure,
    controllers,
    starts,
    steps,
    dt,
    falls,
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
            np.empty((0, n_rods, 2, 2)),
            np.empty((0, 2)),
            final_out[c],
            np.empty(n_ends),
        )
        taken_out[c] = run_controller(
            figure,
            controller,
            starts[c],
            np.zeros(n_ends),
            False,  # the literal: numba prunes the carry-over branch, and the search runs
            steps,  # 2x faster with 10,000 rules (7.4 s against 15 s for a generation of 50)
            dt,
            falls,
            record,
        )
