"""Closed-loop simulation of a vehicle by one-step lookahead on a controller's cost-to-go.

The table's controls are the DP's best samples at the grid nodes; between nodes the paper blends
them, and for a car's bang-bang table the blend drives neither forward nor back. This runtime
asks the DP's own question at the vehicle's actual state instead: for every control sample, hold
it until the state leaves the box of ±1 grid step around the state where the choice is made (the
DP's cell), and cost that segment as the DP does (its seconds plus the interpolated cost-to-go
where it leaves). It takes the cheapest sample and holds it to that exit, as the DP's transition
assumes, then chooses again (where no admissible sample's exit is trusted, ``known_weight``, it
takes the cheapest by any known corner, the paper's rule; where none is admissible at all, it
brakes, choosing again every step); where the cheapest choice costs more than the interpolated
cost-to-go at the state promised, the run raises the table there (``_learn``; every raised value
is put back when the run ends), so that a spot where interpolation promises too much does not
hold the vehicle dithering in it.
A segment is admissible only if no step of it touches an obstacle or leaves the domain polygon,
and if braking to rest from its exit, steering held, touches nothing either; so the vehicle can
always stop. The body tested is the vehicle's grown by CLEARANCE (``ssc.lookahead``), so that the
poses between two tests, and the run's own steps, which trace the segment with a smaller step
than the DP's, are free too. Once the point where full braking would bring the vehicle to rest
lies in the arrival box around the destination, it brakes to rest there and holds.

SI units throughout; grids as in ``kernels.interpolate``; obstacles as ``geometry.pose_is_free``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, types

from mosys.kernels.arrival import braking_seconds, stops_in_box
from mosys.kernels.borrowed import borrowed, keep_alive
from mosys.kernels.figure_state import read_state
from mosys.kernels.geometry import pose_is_free_at
from mosys.kernels.integrate import (
    DERIVATIVE_INTO,
    FLAGS,
    INDICES,
    VECTOR,
    rk4_scratch,
    rk4_step,
)
from mosys.kernels.interpolate import (
    clamp_to_domain,
    falls_short,
    grid_strides,
    interpolate_with,
    interpolation_scratch,
)
from mosys.kernels.regions import crossed_a_region_border, region_membership
from mosys.kernels.soundness import blown_up, state_is_sound

OUTSIDE_PENALTY = 100.0  # s per grid step beyond the table's axes, added to the cost-to-go
SWEEP_STEP = 0.005  # m: the collision tests along a lookahead step are this far apart
# m: the body the lookahead tests is grown by this. Between two tests no point of the body moves
# more than SWEEP_STEP, so a pose between them lies within SWEEP_STEP / 2 of a tested one; the
# other half allows for the run, whose step (its dt) traces a segment a little differently from
# the DP's step it was planned with. Without it a corner clipped an obstacle's corner between
# two tests (a start grid with 7 steering rates, 2026-12-05).
CLEARANCE = SWEEP_STEP

LOOKAHEAD_SIGNATURE = types.int64(
    DERIVATIVE_INTO,  # derivative_into
    VECTOR,  # axis_min
    VECTOR,  # axis_step
    INDICES,  # axis_count
    FLAGS,  # wrap
    types.float64[:, ::1],  # value
    FLAGS,  # known
    types.float64,  # minimum_known_weight
    types.float64[:, ::1],  # control_samples
    INDICES,  # control_slot
    types.int64,  # input_size
    INDICES,  # state_slot
    INDICES,  # pose_slot
    types.float64[:, ::1],  # outline
    types.float64[:, ::1],  # obstacle_vertices
    INDICES,  # obstacle_start
    types.float64[:, ::1],  # domain
    INDICES,  # vehicle_slot
    types.float64,  # wheelbase
    types.float64,  # wheel_radius
    types.float64,  # brake
    types.float64[:, ::1],  # arrival_box
    types.int64,  # max_segment_steps
    types.float64,  # segment_dt
    VECTOR,  # state (in/out)
    types.float64,  # dt
    types.float64[:, ::1],  # record_state
    types.float64[:, ::1],  # record_control
    FLAGS,  # record_outside
    types.float64[:, ::1],  # region_lower
    types.float64[:, ::1],  # region_upper
    VECTOR,  # region_period
)


class TableAxes(NamedTuple):
    """The table's axes (as ``kernels.interpolate`` takes them) and where they lie in the model's
    state."""

    axis_min: np.ndarray  # (d,) SI
    axis_step: np.ndarray  # (d,) SI
    axis_count: np.ndarray  # (d,) int64
    wrap: np.ndarray  # (d,) bool
    state_slot: np.ndarray  # (d,) int64: each axis's slot in the model's state


class Scene(NamedTuple):
    """What every pose must keep clear of (``geometry.pose_is_free``)."""

    pose_slot: np.ndarray  # (3,) int64: x, y, heading in the model's state (-1: no obstacles)
    outline: np.ndarray  # (V, 2) m: the body, grown by CLEARANCE
    obstacle_vertices: np.ndarray  # (M, 2) m
    obstacle_start: np.ndarray  # (K + 1,) int64
    domain: np.ndarray  # (P, 2) m (P = 0: no domain polygon)


class Vehicle(NamedTuple):
    """How the vehicle is driven and brakes (``kernels.arrival``), and where its steer and speed
    stop."""

    slot: np.ndarray  # (7,) int64: x, y, heading, steer, speed, then steer_rate, wheel_accel
    wheelbase: float  # m
    wheel_radius: float  # m
    brake: float  # rad/s²: the largest wheel deceleration
    limits: np.ndarray  # (2, 2): the ends of the table's steer and speed axes (``_axis_limits``)


@njit(cache=True)
def _braking_inputs(state, vehicle, dt, inputs):
    """inputs (model's) that hold the steering and brake the wheels toward rest within one step,
    no harder than ``vehicle.brake`` (rad/s²)."""
    for i in range(inputs.shape[0]):
        inputs[i] = 0.0
    wanted = -state[vehicle.slot[4]] / (vehicle.wheel_radius * dt)
    inputs[vehicle.slot[6]] = min(max(wanted, -vehicle.brake), vehicle.brake)


@njit(cache=True, inline="always")
def _arrives(state, axes, vehicle, arrival_box, point):
    """True when the point where full braking would bring the vehicle to rest from model state
    ``state`` lies in ``arrival_box`` (``arrival.stops_in_box``); point: (d,) work array."""
    return stops_in_box(
        state,
        vehicle.slot,
        vehicle.wheelbase,
        vehicle.wheel_radius,
        vehicle.brake,
        axes.state_slot,
        arrival_box,
        point,
    )


@njit(cache=True)
def _swept_free(before, after, scene, body):
    """True when the body is free in ``scene`` (``geometry.pose_is_free_at``) at every pose of a
    step from model state ``before`` to ``after`` (S,), tested every SWEEP_STEP m of the farthest
    outline vertex's travel along the straight line between the two poses (their x, y and
    heading), the step's end included: a body corner that clips an obstacle between two steps is
    caught. body: like the outline, a work array."""
    pose_slot, outline, obstacle_vertices, obstacle_start, domain = scene
    if pose_slot[0] < 0:
        return True
    reach = 0.0
    for i in range(outline.shape[0]):
        reach = max(reach, math.hypot(outline[i, 0], outline[i, 1]))
    x, y, heading = before[pose_slot[0]], before[pose_slot[1]], before[pose_slot[2]]
    dx, dy = after[pose_slot[0]] - x, after[pose_slot[1]] - y
    turn = after[pose_slot[2]] - heading
    pieces = max(1, math.ceil((math.hypot(dx, dy) + reach * abs(turn)) / SWEEP_STEP))
    for j in range(1, pieces + 1):
        if not pose_is_free_at(
            x + dx * j / pieces,
            y + dy * j / pieces,
            heading + turn * j / pieces,
            outline,
            obstacle_vertices,
            obstacle_start,
            domain,
            body,
        ):
            return False
    return True


@njit(cache=True)
def _axis_limits(axis_min, axis_step, axis_count, state_slot, vehicle_slot):
    """(2, 2): the ends of the table's steer and speed axes (rad, m/s); ±inf for a vehicle
    variable the table has no axis for."""
    limits = np.empty((2, 2))
    limits[:, 0] = -np.inf
    limits[:, 1] = np.inf
    for k in range(state_slot.shape[0]):
        for j in range(2):
            if state_slot[k] == vehicle_slot[3 + j]:
                limits[j, 0] = axis_min[k]
                limits[j, 1] = axis_min[k] + axis_step[k] * (axis_count[k] - 1)
    return limits


@njit(cache=True)
def _limit_inputs(state, vehicle, dt, inputs, out):
    """out: ``inputs`` with the steer rate and the wheel acceleration cut so that a step of dt
    seconds ends with steer and speed no further out than ``vehicle.limits`` (2, 2): (steer low,
    high) rad and (speed low, high) m/s, the table's axis ends. So the vehicle stops at the ends
    of the axes instead of overshooting them (the model's steer_limit lies further out)."""
    limits = vehicle.limits
    for i in range(inputs.shape[0]):
        out[i] = inputs[i]
    for k, gain in ((0, 1.0), (1, vehicle.wheel_radius)):
        value = state[vehicle.slot[3 + k]]
        slot = vehicle.slot[5 + k]
        out[slot] = min(out[slot], max(0.0, (limits[k, 1] - value) / (gain * dt)))
        out[slot] = max(out[slot], min(0.0, (limits[k, 0] - value) / (gain * dt)))


@njit(cache=True)
def _cost_to_go(
    axis_min,
    axis_step,
    axis_count,
    wrap,
    strides,
    value,
    known,
    minimum_known_weight,
    exit_state,
    clamped,
    scratch,
    out,
):
    """Interpolated cost-to-go (s) at a controller state (d,); beyond the axes, the value at the
    nearest covered state plus OUTSIDE_PENALTY per grid step outside (summed over the axes), so
    that the way back in is the cheapest; inf where the corners whose value is known carry less
    than ``minimum_known_weight`` of the weight (as the DP, ``dp.discard_poorly_known_exits``)
    or none."""
    clamp_to_domain(axis_min, axis_step, axis_count, wrap, exit_state, clamped)
    known_weight = interpolate_with(
        axis_min, axis_step, axis_count, wrap, strides, value, known, clamped, scratch, out
    )
    if falls_short(known_weight, minimum_known_weight):
        return np.inf
    steps_outside = 0.0
    for k in range(exit_state.shape[0]):
        steps_outside += abs(exit_state[k] - clamped[k]) / axis_step[k]
    return out[0] + OUTSIDE_PENALTY * steps_outside


@njit(cache=True)
def _segment(derivative_into, start, axes, scene, vehicle, arrival_box, max_steps, dt, work):
    """Hold the model's inputs ``work.inputs`` from ``start`` (S,) until the controller state
    lies one grid step from where it began on some axis, or the point where full braking would
    stop it lies in ``arrival_box`` (``stops_in_box``: the runtime brakes there, and so does the
    DP), or for max_steps; the last state goes to ``work.exit``. Returns (the steps taken,
    whether it arrived); the steps are -1 when some step is not free (obstacle or domain
    polygon) or, from a start within the table's axes, lies beyond the end of a (non-wrap)
    axis. The inputs are cut at the ends of the steer and speed axes (``_limit_inputs``)."""
    end, origin, here, stop = work.exit, work.origin, work.here, work.clamped
    for i in range(start.shape[0]):
        end[i] = start[i]
    read_state(start, axes.state_slot, origin)
    inside = clamp_to_domain(
        axes.axis_min, axes.axis_step, axes.axis_count, axes.wrap, origin, stop
    )
    taken = 0
    while taken < max_steps:
        _limit_inputs(end, vehicle, dt, work.inputs, work.limited)
        work.before[:] = end
        rk4_step(derivative_into, end, work.limited, dt, work.rk4)
        taken += 1
        if not _swept_free(work.before, end, scene, work.body):
            return -1, False
        read_state(end, axes.state_slot, here)
        if inside and not clamp_to_domain(
            axes.axis_min, axes.axis_step, axes.axis_count, axes.wrap, here, here
        ):
            return -1, False
        for k in range(axes.axis_step.shape[0]):
            if abs(here[k] - origin[k]) >= axes.axis_step[k]:
                return taken, False
        if _arrives(end, axes, vehicle, arrival_box, stop):
            return taken, True
    return taken, False


@njit(cache=True)
def _can_brake(derivative_into, start, axes, scene, vehicle, inside, max_steps, dt, work):
    """True when braking to rest from ``start``, steering held, keeps every step free and, if
    ``inside``, within the ends of the table's (non-wrap) axes."""
    state, here = work.braking, work.here
    for i in range(start.shape[0]):
        state[i] = start[i]
    for _ in range(max_steps):
        if abs(state[vehicle.slot[4]]) < 1e-9:
            return True
        _braking_inputs(state, vehicle, dt, work.inputs)
        work.before[:] = state
        rk4_step(derivative_into, state, work.inputs, dt, work.rk4)
        if not _swept_free(work.before, state, scene, work.body):
            return False
        read_state(state, axes.state_slot, here)
        if inside and not clamp_to_domain(
            axes.axis_min, axes.axis_step, axes.axis_count, axes.wrap, here, here
        ):
            return False
    return True


@njit(cache=True)
def _sample_inputs(control_samples, control_slot, sample, inputs):
    """The model's inputs for control sample ``sample`` (other inputs 0)."""
    for i in range(inputs.shape[0]):
        inputs[i] = 0.0
    for j in range(control_slot.shape[0]):
        inputs[control_slot[j]] += control_samples[sample, j]


class ChoiceWork(NamedTuple):
    """The work arrays of ``_choose`` and the segments it tries (``choice_work``), for a model
    of S state variables and I inputs and a table of d axes."""

    exit: np.ndarray  # (S,) a segment's last state
    braking: np.ndarray  # (S,) the state braking from it
    before: np.ndarray  # (S,) the state before a step
    origin: np.ndarray  # (d,)
    here: np.ndarray  # (d,)
    clamped: np.ndarray  # (d,)
    out: np.ndarray  # (1,)
    inputs: np.ndarray  # (I,) a sample's (or braking's) inputs
    limited: np.ndarray  # (I,) the same cut at the axis ends
    rk4: np.ndarray  # ``rk4_scratch(S)``
    body: np.ndarray  # like the outline
    strides: np.ndarray  # (d,) int64, ``grid_strides``
    interpolation: tuple  # ``interpolation_scratch(d)``


@njit(cache=True)
def choice_work(axis_count, size, input_size, outline):
    """A ``ChoiceWork`` for a table of axes ``axis_count`` (d,), a model state of ``size``
    entries and ``input_size`` inputs, and a body ``outline``."""
    d = axis_count.shape[0]
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    states = np.empty((3, size))
    points = np.empty((4, d))
    inputs = np.zeros((2, input_size))
    return ChoiceWork(
        states[0],
        states[1],
        states[2],
        points[0],
        points[1],
        points[2],
        points[3, :1],
        inputs[0],
        inputs[1],
        rk4_scratch(size),
        np.empty_like(outline),
        strides,
        interpolation_scratch(d),
    )


@njit(cache=True)
def _choose(
    derivative_into,
    axes,
    scene,
    vehicle,
    value,
    known,
    minimum_known_weight,
    control_samples,
    control_slot,
    arrival_box,
    max_steps,
    dt,
    state,
    work,
):
    """(sample, steps, cost): the cheapest admissible control sample from ``state``, the length
    of its segment and its cost (s: the segment's seconds plus the cost-to-go at its exit, or,
    for a segment that arrives, plus the time to brake to rest); (-1, 1, inf) when none is
    admissible. work: ``choice_work``'s."""
    here, clamped = work.here, work.clamped
    read_state(state, axes.state_slot, here)
    inside = clamp_to_domain(
        axes.axis_min, axes.axis_step, axes.axis_count, axes.wrap, here, clamped
    )
    best = np.inf
    best_sample = -1
    best_steps = 1
    for u in range(control_samples.shape[0]):
        _sample_inputs(control_samples, control_slot, u, work.inputs)
        taken, arrived = _segment(
            derivative_into, state, axes, scene, vehicle, arrival_box, max_steps, dt, work
        )
        if taken < 0:
            continue
        read_state(work.exit, axes.state_slot, here)
        if arrived:  # it brakes to rest from here
            onward = braking_seconds(work.exit, vehicle.slot, vehicle.wheel_radius, vehicle.brake)
        else:
            onward = _cost_to_go(
                axes.axis_min,
                axes.axis_step,
                axes.axis_count,
                axes.wrap,
                work.strides,
                value,
                known,
                minimum_known_weight,
                here,
                clamped,
                work.interpolation,
                work.out,
            )
        cost = taken * dt + onward
        if not cost < best:
            continue
        if _can_brake(
            derivative_into, work.exit, axes, scene, vehicle, inside, max_steps, dt, work
        ):
            best = cost
            best_sample = u
            best_steps = taken
    return best_sample, best_steps, best


@njit(cache=True)
def undo_capacity(node_count, steps, dimensions):
    """The entries of a run's put-back log: a choice at most every step, each raising at most
    the 2**dimensions corners around it, and no node twice (``_learn``)."""
    return min(node_count, steps << dimensions)


def undo_log_bytes(node_count: int, steps: int, dimensions: int) -> float:
    """Bytes of the put-back log of a ``simulate_lookahead`` run of ``steps`` steps on a table
    of ``node_count`` nodes and ``dimensions`` axes: ``touched``, 1 byte a node; ``undo_index``
    and ``undo_value``, 16 bytes an entry of ``undo_capacity``."""
    # the Python function: exact for any count (the compiled one works in int64)
    return float(node_count) + 16.0 * float(undo_capacity.py_func(node_count, steps, dimensions))


@njit(cache=True)
def _learn(
    axis_min,
    axis_step,
    axis_count,
    wrap,
    strides,
    value,
    known,
    minimum_known_weight,
    state,
    cost,
    scratch,
    clamped,
    out,
    touched,
    undo_index,
    undo_value,
    logged,
):
    """Raise the cost-to-go where a choice found it too low (learning real-time search: Korf's
    LRTA*, 1990). When ``cost`` (s), the cheapest choice at controller state ``state`` (d,),
    exceeds the cost-to-go interpolated there, the known corners around the state rise by the
    least change (least squares) that makes the interpolation there equal ``cost``: each by
    shortfall · w / Σw², w its renormalised weight. value: (N, 1), raised in place; a node
    raised for the first time (touched (N,) bool False) is marked and logged with its value
    before, in undo_index[logged] and undo_value[logged]; returns the entries logged in all.
    scratch: ``interpolation_scratch(d)``; clamped: (d,), out: (1,) work arrays. Nothing changes
    where the known corners carry less than ``minimum_known_weight``, nor where ``cost`` is
    inf."""
    clamp_to_domain(axis_min, axis_step, axis_count, wrap, state, clamped)
    known_weight = interpolate_with(
        axis_min, axis_step, axis_count, wrap, strides, value, known, clamped, scratch, out
    )
    shortfall = cost - out[0]
    if (
        falls_short(known_weight, minimum_known_weight)
        or known_weight == 0.0
        or not 0.0 < shortfall < np.inf
    ):
        return logged
    # the corners of ``clamped`` and their weights, as interpolate_with left them in scratch
    corner_index, corner_weight = scratch[2], scratch[3]
    count = corner_index.shape[0]
    squares = 0.0
    for c in range(count):
        if known[corner_index[c]]:
            squares += (corner_weight[c] / known_weight) ** 2
    for c in range(count):
        if known[corner_index[c]]:
            node = corner_index[c]
            if not touched[node]:
                touched[node] = True
                undo_index[logged] = node
                undo_value[logged] = value[node, 0]
                logged += 1
            value[node, 0] += shortfall * corner_weight[c] / known_weight / squares
    return logged


@njit(LOOKAHEAD_SIGNATURE, cache=True, nogil=True)
def simulate_lookahead(
    derivative_into,
    axis_min,
    axis_step,
    axis_count,
    wrap,
    value,
    known,
    minimum_known_weight,
    control_samples,
    control_slot,
    input_size,
    state_slot,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    vehicle_slot,
    wheelbase,
    wheel_radius,
    brake,
    arrival_box,
    max_segment_steps,
    segment_dt,
    state,
    dt,
    record_state,
    record_control,
    record_outside,
    region_lower,
    region_upper,
    region_period,
):
    """Simulate up to ``record_state.shape[0]`` RK4 steps of dt seconds by lookahead on the
    cost-to-go (module docstring); return how many were taken, or ``soundness.blown_up(step)``
    (< 0) when the state is not sound before step ``step`` or after the last, as
    ``simulate.simulate_controlled``.

    Its arguments are the arrays one by one (its signature is compiled ahead); inside it passes
    them down in named tuples of borrowed views (``TableAxes``, ``Scene``, ``Vehicle``,
    ``ChoiceWork``), which take no reference counts.

    value: (N, 1) cost-to-go at the grid nodes, s; known: (N,) bool, the nodes with a finite
    value (interpolation renormalises over them, as ``interpolate_with``, and an exit whose
    known corners carry less than minimum_known_weight of its weight costs inf, as in the DP);
    the run raises it where a choice costs more than it promised (``_learn``), and puts every
    raised entry back before it returns: ``value`` is as it was, bit for bit, but runs at once
    need arrays of their own (``ssc.controller.Controller`` keeps one per thread; copying the
    table for every run took 14 % of a start grid's time). Steer and speed stop at the ends of their
    axes (``_limit_inputs``), and from a state within the table's axes a sample is admissible
    only if its segment, and braking from its exit, stay within them: the run stays on the
    table. control_samples: (U, m) the DP's control samples, SI, driving ``control_slot`` (m,)
    of the model's ``input_size`` inputs. state_slot: (d,) the controller's axes in the
    model's state. pose_slot, outline, obstacle_vertices, obstacle_start, domain: the
    obstacles.
    vehicle_slot: (7,) int64, the state slots of x, y, heading, steer and speed, then the
    input slots of steer_rate and wheel_accel; wheelbase and wheel_radius (m); brake: the
    largest wheel deceleration, rad/s². arrival_box: (3, d) lower, upper (SI, ±inf where free)
    and period (> 0: an angle) of the arrival box. Segments are simulated with RK4 steps of
    segment_dt seconds (the DP's, so that the choices do not depend on dt), at most
    max_segment_steps of them; the chosen sample is then held for the segment's duration in
    steps of dt. state: (S,) advanced in place. Records and regions as in
    ``simulate.simulate_controlled``; record_outside marks the steps whose state lies beyond the
    table's axes.
    """
    size = state.shape[0]
    d = axis_min.shape[0]
    own_membership = np.empty((2, region_lower.shape[0]), np.bool_)  # at the start, now
    region_membership(state, region_lower, region_upper, region_period, own_membership[0])
    own_inputs = np.zeros((2, input_size))  # the held inputs, and the same cut at the axis ends
    own_limits = _axis_limits(axis_min, axis_step, axis_count, state_slot, vehicle_slot)
    own_work = choice_work(axis_count, size, input_size, outline)
    # the nodes _learn raises, each with its value before: put back before the run returns
    logged = 0
    capacity = undo_capacity(value.shape[0], record_state.shape[0], d)
    own_touched = np.zeros(value.shape[0], np.bool_)
    own_undo_index = np.empty(capacity, np.int64)
    own_undo_value = np.empty(capacity)
    # borrowed views (``kernels.borrowed``) of the arguments and of the work arrays above (kept
    # alive to the end by keep_alive): numba's reference counts of the arrays passed down at
    # every step of every segment tried were two thirds of the run's time
    axes = borrowed(TableAxes(axis_min, axis_step, axis_count, wrap, state_slot))
    scene = borrowed(Scene(pose_slot, outline, obstacle_vertices, obstacle_start, domain))
    vehicle = borrowed(Vehicle(vehicle_slot, wheelbase, wheel_radius, brake, own_limits))
    value, known, control_samples, control_slot, arrival_box = borrowed(
        (value, known, control_samples, control_slot, arrival_box)
    )
    state, record_state, record_control, record_outside = borrowed(
        (state, record_state, record_control, record_outside)
    )
    regions = borrowed((region_lower, region_upper, region_period))
    work, membership, both_inputs = borrowed((own_work, own_membership, own_inputs))
    touched, undo_index, undo_value = borrowed((own_touched, own_undo_index, own_undo_value))
    inputs, limited = both_inputs[0], both_inputs[1]
    here, clamped = work.here, work.clamped  # read afresh wherever used, as _choose does
    held_until = 0  # the step at which the held sample's segment ends
    arrived = False
    taken = record_state.shape[0]
    for step in range(record_state.shape[0]):
        if not state_is_sound(state):
            taken = blown_up(step)
            break
        if crossed_a_region_border(state, *regions, membership[0], membership[1]):
            taken = step
            break
        for i in range(size):
            record_state[step, i] = state[i]
        read_state(state, axes.state_slot, here)
        record_outside[step] = not clamp_to_domain(
            axes.axis_min, axes.axis_step, axes.axis_count, axes.wrap, here, clamped
        )
        if not arrived:
            arrived = _arrives(state, axes, vehicle, arrival_box, here)
        if arrived:
            _braking_inputs(state, vehicle, dt, inputs)
        elif step >= held_until:
            # the cheapest sample whose exit is trusted; if none is, whose exit has any known
            # corner (the paper's rule), rather than braking where the trusted values end
            for trust in (minimum_known_weight, 0.0):
                sample, steps, cost = _choose(
                    derivative_into, axes, scene, vehicle, value, known, trust, control_samples,
                    control_slot, arrival_box, max_segment_steps, segment_dt, state, work,
                )  # fmt: skip
                if sample >= 0 or trust == 0.0:
                    break
            read_state(state, axes.state_slot, here)  # the choice used it
            logged = _learn(
                axes.axis_min,
                axes.axis_step,
                axes.axis_count,
                axes.wrap,
                work.strides,
                value,
                known,
                minimum_known_weight,
                here,
                cost,
                work.interpolation,
                clamped,
                work.out,
                touched,
                undo_index,
                undo_value,
                logged,
            )
            if sample < 0:  # nothing admissible: brake, and choose again next step (held
                # longer, a braking input made for one step overshoots rest and rocks the
                # vehicle to and fro, creeping)
                _braking_inputs(state, vehicle, dt, inputs)
                held_until = step + 1
            else:
                _sample_inputs(control_samples, control_slot, sample, inputs)
                held_until = step + max(1, round(steps * segment_dt / dt))
        _limit_inputs(state, vehicle, dt, inputs, limited)
        for j in range(control_slot.shape[0]):
            record_control[step, j] = limited[control_slot[j]]
        rk4_step(derivative_into, state, limited, dt, work.rk4)
    if taken == record_state.shape[0] and not state_is_sound(state):
        taken = blown_up(record_state.shape[0])
    for k in range(logged):  # the table as it was
        value[undo_index[k], 0] = undo_value[k]
    keep_alive((own_membership, own_inputs, own_limits, own_touched, own_undo_index))
    keep_alive(own_undo_value)
    keep_alive(own_work)
    return taken
