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


@njit(cache=True)
def _braking_inputs(state, vehicle_slot, wheel_radius, brake, dt, inputs):
    """inputs (model's) that hold the steering and brake the wheels toward rest within one step,
    no harder than ``brake`` (rad/s²)."""
    for i in range(inputs.shape[0]):
        inputs[i] = 0.0
    wanted = -state[vehicle_slot[4]] / (wheel_radius * dt)
    inputs[vehicle_slot[6]] = min(max(wanted, -brake), brake)


@njit(cache=True)
def _swept_free(before, after, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body):
    """True when the body is free (``geometry.pose_is_free_at``) at every pose of a step from
    model state ``before`` to ``after`` (S,), tested every SWEEP_STEP m of the farthest outline
    vertex's travel along the straight line between the two poses (their x, y and heading), the
    step's end included: a body corner that clips an obstacle between two steps is caught."""
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
def _limit_inputs(state, vehicle_slot, limits, wheel_radius, dt, inputs, out):
    """out: ``inputs`` with the steer rate and the wheel acceleration cut so that a step of dt
    seconds ends with steer and speed no further out than ``limits`` (2, 2): (steer low, high)
    rad and (speed low, high) m/s, the table's axis ends. So the vehicle stops at the ends of
    the axes instead of overshooting them (the model's steer_limit lies further out)."""
    for i in range(inputs.shape[0]):
        out[i] = inputs[i]
    for k, gain in ((0, 1.0), (1, wheel_radius)):
        value = state[vehicle_slot[3 + k]]
        slot = vehicle_slot[5 + k]
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
def _segment(
    derivative_into,
    start,
    inputs,
    vehicle_slot,
    limits,
    wheel_radius,
    limited,
    axis_min,
    axis_step,
    axis_count,
    wrap,
    state_slot,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    wheelbase,
    brake,
    arrival_box,
    max_steps,
    dt,
    end,
    origin,
    here,
    stop,
    scratch,
    body,
    before,
):
    """Hold the model's ``inputs`` from ``start`` (S,) until the controller state lies one grid
    step from where it began on some axis, or the point where full braking would stop it lies
    in ``arrival_box`` (``stops_in_box``: the runtime brakes there, and so does the DP), or for
    max_steps; the last state goes to ``end``. Returns (the steps taken, whether it arrived);
    the steps are -1 when some step is not free (obstacle or domain polygon) or, from a start
    within the table's axes, lies beyond the end of a (non-wrap) axis. The inputs are cut at
    the ends of the steer and speed axes (``_limit_inputs``: vehicle_slot, limits,
    wheel_radius; limited: a work array like inputs). origin, here, stop: (d,) work arrays;
    scratch: ``rk4_scratch(S)``; body: like outline; before: (S,) work array."""
    for i in range(start.shape[0]):
        end[i] = start[i]
    read_state(start, state_slot, origin)
    inside = clamp_to_domain(axis_min, axis_step, axis_count, wrap, origin, stop)
    taken = 0
    while taken < max_steps:
        _limit_inputs(end, vehicle_slot, limits, wheel_radius, dt, inputs, limited)
        before[:] = end
        rk4_step(derivative_into, end, limited, dt, scratch)
        taken += 1
        if not _swept_free(
            before, end, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body
        ):
            return -1, False
        read_state(end, state_slot, here)
        if inside and not clamp_to_domain(axis_min, axis_step, axis_count, wrap, here, here):
            return -1, False
        for k in range(axis_step.shape[0]):
            if abs(here[k] - origin[k]) >= axis_step[k]:
                return taken, False
        if stops_in_box(
            end, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, arrival_box, stop
        ):
            return taken, True
    return taken, False


@njit(cache=True)
def _can_brake(
    derivative_into,
    start,
    vehicle_slot,
    wheel_radius,
    brake,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    max_steps,
    dt,
    axis_min,
    axis_step,
    axis_count,
    wrap,
    state_slot,
    inside,
    state,
    inputs,
    scratch,
    body,
    here,
    before,
):
    """True when braking to rest from ``start``, steering held, keeps every step free and, if
    ``inside``, within the ends of the table's (non-wrap) axes. here: (d,), before: (S,) work
    arrays."""
    for i in range(start.shape[0]):
        state[i] = start[i]
    for _ in range(max_steps):
        if abs(state[vehicle_slot[4]]) < 1e-9:
            return True
        _braking_inputs(state, vehicle_slot, wheel_radius, brake, dt, inputs)
        before[:] = state
        rk4_step(derivative_into, state, inputs, dt, scratch)
        if not _swept_free(
            before, state, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body
        ):
            return False
        read_state(state, state_slot, here)
        if inside and not clamp_to_domain(axis_min, axis_step, axis_count, wrap, here, here):
            return False
    return True


@njit(cache=True)
def _sample_inputs(control_samples, control_slot, sample, inputs):
    """The model's inputs for control sample ``sample`` (other inputs 0)."""
    for i in range(inputs.shape[0]):
        inputs[i] = 0.0
    for j in range(control_slot.shape[0]):
        inputs[control_slot[j]] += control_samples[sample, j]


@njit(cache=True)
def _choose(
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
    limits,
    arrival_box,
    max_steps,
    dt,
    state,
):
    """(sample, steps, cost): the cheapest admissible control sample from ``state``, the length
    of its segment and its cost (s: the segment's seconds plus the cost-to-go at its exit, or,
    for a segment that arrives, plus the time to brake to rest); (-1, 1, inf) when none is
    admissible."""
    size = state.shape[0]
    d = axis_min.shape[0]
    n = control_samples.shape[0]
    own_strides = np.empty(d, np.int64)
    grid_strides(axis_count, own_strides)
    own_interpolation = interpolation_scratch(d)
    own_scratch = rk4_scratch(size)
    own_body = np.empty_like(outline)
    own_states = np.empty((3, size))  # the segment's exit, the braking's state, a step's start
    own_points = np.empty((4, d))  # origin, here, clamped; out (one entry)
    own_inputs = np.zeros((2, input_size))  # the sample's inputs, limited
    # borrowed views (``kernels.borrowed``), kept alive to the end (keep_alive)
    strides, interpolation, scratch, body = borrowed(
        (own_strides, own_interpolation, own_scratch, own_body)
    )
    states, points, both_inputs = borrowed((own_states, own_points, own_inputs))
    first, braking, before = states[0], states[1], states[2]
    origin, here, clamped, out = points[0], points[1], points[2], points[3, :1]
    inputs, limited = both_inputs[0], both_inputs[1]
    read_state(state, state_slot, here)
    inside = clamp_to_domain(axis_min, axis_step, axis_count, wrap, here, clamped)
    best = np.inf
    best_sample = -1
    best_steps = 1
    for u in range(n):
        _sample_inputs(control_samples, control_slot, u, inputs)
        taken, arrived = _segment(
            derivative_into,
            state,
            inputs,
            vehicle_slot,
            limits,
            wheel_radius,
            limited,
            axis_min,
            axis_step,
            axis_count,
            wrap,
            state_slot,
            pose_slot,
            outline,
            obstacle_vertices,
            obstacle_start,
            domain,
            wheelbase,
            brake,
            arrival_box,
            max_steps,
            dt,
            first,
            origin,
            here,
            clamped,
            scratch,
            body,
            before,
        )
        if taken < 0:
            continue
        read_state(first, state_slot, here)
        if arrived:  # it brakes to rest from here
            onward = braking_seconds(first, vehicle_slot, wheel_radius, brake)
        else:
            onward = _cost_to_go(
                axis_min,
                axis_step,
                axis_count,
                wrap,
                strides,
                value,
                known,
                minimum_known_weight,
                here,
                clamped,
                interpolation,
                out,
            )
        cost = taken * dt + onward
        if not cost < best:
            continue
        if _can_brake(
            derivative_into,
            first,
            vehicle_slot,
            wheel_radius,
            brake,
            pose_slot,
            outline,
            obstacle_vertices,
            obstacle_start,
            domain,
            max_steps,
            dt,
            axis_min,
            axis_step,
            axis_count,
            wrap,
            state_slot,
            inside,
            braking,
            inputs,
            scratch,
            body,
            origin,
            before,
        ):
            best = cost
            best_sample = u
            best_steps = taken
    keep_alive((own_strides, own_interpolation, own_scratch, own_body))
    keep_alive((own_states, own_points, own_inputs))
    return best_sample, best_steps, best


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
    scratch: ``interpolation_scratch(d)``;
    clamped: (d,), out: (1,) work arrays. Nothing changes where the known corners carry less
    than ``minimum_known_weight``, nor where ``cost`` is inf."""
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

    Long because it threads the grid, table, obstacle and vehicle arrays through to ``_choose``
    one by one. Named tuples for those groups would shorten it, but measure first: passed to a
    kernel called every step, a named tuple of arrays cost the BSR simulator 10-16% per step.

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
    own_inputs = np.zeros(input_size)
    own_limited = np.zeros(input_size)
    own_limits = _axis_limits(axis_min, axis_step, axis_count, state_slot, vehicle_slot)
    own_here = np.empty(d)
    own_clamped = np.empty(d)
    regions = region_lower.shape[0]
    own_start_membership = np.empty(regions, np.bool_)
    own_membership = np.empty(regions, np.bool_)
    region_membership(state, region_lower, region_upper, region_period, own_start_membership)
    own_scratch = rk4_scratch(size)
    # the nodes _learn raises, each with its value before: put back before the run returns (a
    # choice at most every step, each raising at most the 2**d corners around it)
    logged = 0
    capacity = min(value.shape[0], record_state.shape[0] << d)
    own_touched = np.zeros(value.shape[0], np.bool_)
    own_undo_index = np.empty(capacity, np.int64)
    own_undo_value = np.empty(capacity)
    own_strides = np.empty(d, np.int64)
    grid_strides(axis_count, own_strides)
    own_interpolation = interpolation_scratch(d)
    own_out = np.empty(1)
    # borrowed views (``kernels.borrowed``): the arguments, and the work arrays above, which
    # keep_alive keeps to the end
    axis_min, axis_step, axis_count, wrap, known = borrowed(
        (axis_min, axis_step, axis_count, wrap, known)
    )
    control_samples, control_slot, state_slot, pose_slot, vehicle_slot = borrowed(
        (control_samples, control_slot, state_slot, pose_slot, vehicle_slot)
    )
    outline, obstacle_vertices, obstacle_start, domain, arrival_box = borrowed(
        (outline, obstacle_vertices, obstacle_start, domain, arrival_box)
    )
    state, record_state, record_control, record_outside = borrowed(
        (state, record_state, record_control, record_outside)
    )
    region_lower, region_upper, region_period = borrowed(
        (region_lower, region_upper, region_period)
    )
    inputs, limited, limits, here, clamped, scratch, strides, out = borrowed(
        (own_inputs, own_limited, own_limits, own_here, own_clamped, own_scratch, own_strides,
         own_out)
    )  # fmt: skip
    value, touched, undo_index, undo_value = borrowed(
        (value, own_touched, own_undo_index, own_undo_value)
    )
    start_membership, membership, interpolation = borrowed(
        (own_start_membership, own_membership, own_interpolation)
    )
    held_until = 0  # the step at which the held sample's segment ends
    arrived = False
    taken = record_state.shape[0]
    for step in range(record_state.shape[0]):
        if not state_is_sound(state):
            taken = blown_up(step)
            break
        if crossed_a_region_border(
            state, region_lower, region_upper, region_period, start_membership, membership
        ):
            taken = step
            break
        for i in range(size):
            record_state[step, i] = state[i]
        read_state(state, state_slot, here)
        record_outside[step] = not clamp_to_domain(
            axis_min, axis_step, axis_count, wrap, here, clamped
        )
        if not arrived:
            arrived = stops_in_box(
                state, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, arrival_box, here
            )
        if arrived:
            _braking_inputs(state, vehicle_slot, wheel_radius, brake, dt, inputs)
        elif step >= held_until:
            # the cheapest sample whose exit is trusted; if none is, whose exit has any known
            # corner (the paper's rule), rather than braking where the trusted values end
            for trust in (minimum_known_weight, 0.0):
                sample, steps, cost = _choose(
                    derivative_into,
                    axis_min,
                    axis_step,
                    axis_count,
                    wrap,
                    value,
                    known,
                    trust,
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
                    limits,
                    arrival_box,
                    max_segment_steps,
                    segment_dt,
                    state,
                )
                if sample >= 0 or trust == 0.0:
                    break
            read_state(state, state_slot, here)  # stops_in_box used it for the braking point
            logged = _learn(
                axis_min,
                axis_step,
                axis_count,
                wrap,
                strides,
                value,
                known,
                minimum_known_weight,
                here,
                cost,
                interpolation,
                clamped,
                out,
                touched,
                undo_index,
                undo_value,
                logged,
            )
            if sample < 0:  # nothing admissible: brake, and choose again next step (held
                # longer, a braking input made for one step overshoots rest and rocks the
                # vehicle to and fro, creeping)
                _braking_inputs(state, vehicle_slot, wheel_radius, brake, dt, inputs)
                held_until = step + 1
            else:
                _sample_inputs(control_samples, control_slot, sample, inputs)
                held_until = step + max(1, round(steps * segment_dt / dt))
        _limit_inputs(state, vehicle_slot, limits, wheel_radius, dt, inputs, limited)
        for j in range(control_slot.shape[0]):
            record_control[step, j] = limited[control_slot[j]]
        rk4_step(derivative_into, state, limited, dt, scratch)
    if taken == record_state.shape[0] and not state_is_sound(state):
        taken = blown_up(record_state.shape[0])
    for k in range(logged):  # the table as it was
        value[undo_index[k], 0] = undo_value[k]
    keep_alive((own_inputs, own_limited, own_limits, own_here, own_clamped, own_scratch))
    keep_alive((own_strides, own_out, own_start_membership, own_membership, own_interpolation))
    keep_alive((own_touched, own_undo_index, own_undo_value))
    return taken
