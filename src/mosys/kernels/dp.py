"""Dynamic programming for state-space controllers (van de Panne et al. 1990, §3.5).

For every grid node S and every sampled control u, the figure is simulated from S with u held
constant until its state leaves S's cell — the box of half-width one grid step around S, whose
boundary carries S's neighbours (points A, B, C, F of the paper's Figure 10). The exit state E, the
segment cost ``t + Σ K|u| t`` and E's interpolation weights over the nodes of the face it crosses do
not depend on the cost-to-go, so they are computed once (``exit_transitions_template``, specialised
to each model), E's corners and weights as a *shape* (corners as offsets from S). A model whose
equations do not read some coordinates (the car's x and y) moves alike from every node of a
*class* (the nodes differing only there): its segments are integrated once per class and
replayed at each node (``replay_classes``), whose exits share the class's shapes. Value
iteration then repeats Bellman sweeps ``V(S) = min_u [cost(S,u) + Σ w V(corner)]`` until the
largest change is below a tolerance (``gauss_seidel_sweep``). The paper: "It
is difficult to sequence local optimizations such that each local optimization always uses accurate
information. It is simpler to approximate this order and repeat this for several iterations" —
the sweeps run through the grid in the 2**d orders of the fast sweeping method in turn
(``sweep_order``), each node using the values the sweep has just updated; between them, sweeps
of the policy the last one left, each node under its own control only (modified policy
iteration: ``policy_sweep``), run down the slow tail at a fraction of the cost. On large grids
both run in two blocks of the first axis side by side (``blocked_gauss_seidel_sweep``), each
reading the other's values as they stood when the sweep began. For a spec with
several destinations (the paper's "conditional" goals), ``destination_indices`` then finds
which destination each node's optimal path ends at, by the same sweeps over the exits.

All quantities here are SI (rad, rad/s, m, m/s, s, N·m); grids follow ``kernels.interpolate``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from mosys.kernels.arrival import braking_seconds, braking_stop, stops_in_box
from mosys.kernels.borrowed import borrowed
from mosys.kernels.figure_state import load_state
from mosys.kernels.geometry import box_in_polygon, box_is_clear, place_outline, pose_is_free
from mosys.kernels.interpolate import (
    corner_weights,
    falls_short,
    grid_strides,
    interpolation_scratch,
)
from mosys.kernels.prefetch import prefetch
from mosys.kernels.soundness import state_is_sound
from mosys.kernels.specialise import model_derivative

UNKNOWN = 1.0e9  # s: cost-to-go of a reachable node whose value is not known yet (the paper's
# upper bound, from which value iteration decreases)
DEAD_END_BOUND = 1.0e4  # s: that bound for a spec with known_weight, whose dead ends keep it (far
# above any path's seconds, and low enough that values resting partly on it settle in fewer sweeps)
DEAD_END_SECONDS = 1.0e3  # s: a cost-to-go this long rests on a dead end
SEGMENT_BOX_COLUMNS = 12  # ``segment_boxes``: the body's, the braking points' and the reference
# point's boxes, each [x low, x high, y low, y high]
DOMAIN_ROOM = 1e-9  # m: a node whose segments' reference points stay inside the domain polygon
# with this much room to spare on every side (``replay_classes``) is not tested step by step
PREFETCH_AHEAD = 2  # nodes: a sweep asks the cache for the exits of the node this far ahead in
# its order and for the segment costs of the one twice as far (``kernels.prefetch``)
CACHE_LINE = 64  # bytes
POLICY_PREFETCH_AHEAD = 16  # nodes: a policy sweep asks the cache for the compact row of the
# node this far ahead in its order (``_policy_block``)
PREFETCH_ABOVE_BYTES = 64 * 2**20  # tables of corners larger than this are swept with cache
# hints: on smaller ones (in or near the processor's caches) the hints cost more than they save


@njit(cache=True)
def prefetch_pays(index: np.ndarray, weight: np.ndarray) -> bool:
    """Whether sweeps over these tables of corners and weights (the exits', or the policy's
    compact copy) should ask the cache ahead (PREFETCH_ABOVE_BYTES)."""
    return index.nbytes + weight.nbytes > PREFETCH_ABOVE_BYTES


@njit(cache=True)
def node_coordinates(axis_min, axis_step, axis_count, node, out):
    """Coordinates (d,) of flat C-order node index ``node``, written into out."""
    rest = node
    for k in range(axis_count.shape[0] - 1, -1, -1):
        out[k] = axis_min[k] + axis_step[k] * (rest % axis_count[k])
        rest //= axis_count[k]


@njit(cache=True)
def axis_of_slot(state_slot, slot):
    """The controller axis whose model-state slot is ``slot`` (state_slot (d,) int64), 0 if
    none is."""
    for k in range(state_slot.shape[0]):
        if state_slot[k] == slot:
            return k
    return 0


WEIGHT_EPSILON = 1e-9  # interpolation weights below this are rounding noise
CELL_FRACTION = 1.0  # an integration step moves no controller coordinate further than this
# fraction of its grid step (at the rates of the step's start)
STEP_TOLERANCE = 1e-3  # the integrator's error per step on each controller axis, in grid steps
MIN_STEP = 1e-7  # s: a segment that needs shorter steps than this is discarded
MAX_SEGMENT_SECONDS = 2.0  # a segment still in its cell after this long is discarded
STIFF_STEP_FRACTION = 0.1  # a segment whose steps (tried) average under this fraction of the
# longest step over MAX_SEGMENT_SECONDS is too stiff to follow and is discarded
# Bogacki–Shampine 3(2) (Bogacki and Shampine 1989, "A 3(2) pair of Runge–Kutta formulas",
# Appl. Math. Lett. 2(4)): stage 2 at y + h A21 k1, stage 3 at y + h A32 k2; the third-order
# solution B; k4, the derivative there, serves as the next step's k1 (first same as last); E = B
# minus the second-order weights (the error estimate, E4 on k4); the step grows or shrinks with
# the error to the power ERROR_EXPONENT = -1/(2 + 1).
A21, A32 = 1 / 2, 3 / 4
B1, B2, B3 = 2 / 9, 1 / 3, 4 / 9
E1, E2, E3, E4 = -5 / 72, 1 / 12, 1 / 9, -1 / 8
ERROR_EXPONENT = -1 / 3


@njit(cache=True)
def hermite(x0, x1, d0, d1, s):
    """The cubic Hermite through x0 (s = 0) and x1 (s = 1) with slopes d0 and d1 (per unit s),
    at s."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2.0 * s3 - 3.0 * s2 + 1.0) * x0
        + (s3 - 2.0 * s2 + s) * d0
        + (3.0 * s2 - 2.0 * s3) * x1
        + (s3 - s2) * d1
    )


@njit(cache=True)
def hermite_slope(x0, x1, d0, d1, s):
    """d/ds of ``hermite`` at s."""
    return (
        6.0 * (s * s - s) * (x0 - x1)
        + (3.0 * s * s - 4.0 * s + 1.0) * d0
        + (3.0 * s * s - 2.0 * s) * d1
    )


@njit(cache=True)
def _level_in_piece(x0, x1, d0, d1, start, end, level):
    """The s in [start, end] where the Hermite, monotone there and on either side of ``level``
    at the ends, equals ``level``: Newton's method from the chord's guess, kept inside the
    bracket (a bisection step where Newton would leave it), until a step moves s by less than
    1e-13 of the bracket."""
    low_value = hermite(x0, x1, d0, d1, start) - level
    high_value = hermite(x0, x1, d0, d1, end) - level
    rising = high_value > low_value
    s = start + (end - start) * (-low_value) / (high_value - low_value)
    s = min(max(s, start), end)  # rounding can put the chord's guess an ulp past an end
    width = end - start
    for _ in range(60):
        value = hermite(x0, x1, d0, d1, s) - level
        if value == 0.0:
            return s
        if (value < 0.0) == rising:
            start = s
        else:
            end = s
        if end - start <= 1e-13 * width:
            break
        slope = hermite_slope(x0, x1, d0, d1, s)
        step = s - value / slope if slope != 0.0 else -1.0
        if not start < step < end:
            step = 0.5 * (start + end)
        elif abs(step - s) <= 1e-13 * width:
            return step
        s = step
    return s


@njit(cache=True)
def first_crossing(x0, x1, d0, d1, low, high):
    """The first s in (0, 1] where the cubic Hermite (``hermite``) from x0, inside (low, high),
    reaches low or high; 2.0 if it stays inside. The cubic is monotone between its turning
    points, which split [0, 1] into at most three pieces, each checked at its end. First, the
    common case: the cubic lies within its Bézier control points (x0, x0 + d0/3, x1 - d1/3,
    x1), and if those keep clear of both levels (by far more than the rounding of evaluating it)
    it stays inside."""
    margin = 1e-9 * (high - low) + 1e-12 * (abs(x0) + abs(x1) + abs(d0) + abs(d1))
    inner0 = x0 + d0 / 3.0
    inner1 = x1 - d1 / 3.0
    if (
        max(max(x0, x1), max(inner0, inner1)) < high - margin
        and min(min(x0, x1), min(inner0, inner1)) > low + margin
    ):
        return 2.0
    # p'(s) = a s² + b s + c
    a = 6.0 * (x0 - x1) + 3.0 * (d0 + d1)
    b = 6.0 * (x1 - x0) - 4.0 * d0 - 2.0 * d1
    c = d0
    first = 1.0
    second = 1.0
    if abs(a) > 1e-12 * (abs(b) + abs(c)):
        discriminant = b * b - 4.0 * a * c
        if discriminant > 0.0:
            root = np.sqrt(discriminant)
            q = -0.5 * (b + root if b >= 0.0 else b - root)
            r1 = q / a
            r2 = c / q if q != 0.0 else r1
            if r1 > r2:
                r1, r2 = r2, r1
            if 0.0 < r1 < 1.0:
                first = r1
                if r2 < 1.0:
                    second = r2
            elif 0.0 < r2 < 1.0:
                first = r2
    elif b != 0.0:
        r = -c / b
        if 0.0 < r < 1.0:
            first = r
    start = 0.0
    for piece in range(3):
        end = first if piece == 0 else (second if piece == 1 else 1.0)
        if end <= start:
            continue
        value = hermite(x0, x1, d0, d1, end)
        if value >= high:
            return _level_in_piece(x0, x1, d0, d1, start, end, high)
        if value <= low:
            return _level_in_piece(x0, x1, d0, d1, start, end, low)
        start = end
    return 2.0


def exit_transitions_template(
    axis_min,
    axis_step,
    axis_count,
    wrap,
    state_slot,
    base_state,
    control_samples,
    control_slot,
    input_size,
    effort_weight,
    max_step,
    nodes,
    row_of,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    arrives,
    arrival_box,
    vehicle_slot,
    wheelbase,
    wheel_radius,
    brake,
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    recording,
    record_start,
    record_count,
    record,
    relative_slot,
):
    """Simulate every (node, control sample) pair until it leaves the node's cell; a template
    (``specialise.specialise``, with the model's ``derivative_into`` as ``model_derivative``).

    The integrator is Bogacki–Shampine 3(2) (three evaluations of the model a step) with a step
    sized to the cell: at most ``max_step`` seconds, short enough that no controller coordinate
    moves further than ``CELL_FRACTION`` of its grid step at the rate it has at the step's
    start, and shortened (the step repeated) where its error on some controller coordinate
    exceeds ``STEP_TOLERANCE`` grid steps. Where the state leaves the cell within a step, the
    crossing is found on the step's cubic Hermite (the states and rates at both ends: the
    method's own third-order dense output), not on the chord between them.

    axis_*: (d,) the controller grid, SI; state_slot: (d,) int64 index of each controller axis in
    the model's state (length S); base_state: (S,) values of the uncovered slots.
    control_samples: (U, m) sampled controls; control_slot: (m,) int64 entry of the model's
    inputs (input_size of them) each control drives; effort_weight: (m,) K of the cost
    t + Σ K|u| t. max_step: the longest integration step, s. A segment still in its cell after
    ``MAX_SEGMENT_SECONDS``, or whose step error is not finite, or that has tried as many
    steps as ``STIFF_STEP_FRACTION`` of ``max_step`` would take for all of that time (too
    stiff to follow: resting against a joint limit or the ground, shaking at the integrator's
    stability limit until it is discarded anyway), is discarded (cost inf); one whose accepted
    step's state is not sound (``soundness.state_is_sound``: NaN, inf or beyond 1e150) has cost
    nan, for the caller to report.
    nodes: (P,) int64 flat node indices to process, each with a row (``row_of``: (N,) int64,
    the row of each node in the outputs, -1 for a removed node, which has none).
    pose_slot, outline, obstacle_vertices, obstacle_start, domain: the obstacles, as
    ``geometry.pose_is_free`` takes them (pose_slot[0] < 0: none); a segment whose state is not
    free at the end of any integration step is discarded.
    arrives: whether the table runs by lookahead (a vehicle), whose runtime brakes to rest as
    soon as the point where full braking would stop it lies in ``arrival_box`` (3, d)
    (``arrival.stops_in_box``, with vehicle_slot (7,), wheelbase and wheel_radius m, brake
    rad/s²): then a segment that gets there before leaving its cell ends there, its cost the
    seconds so far plus the braking time (``braking_seconds``), and to_destination is True:
    it goes on to the destination, whose cost-to-go is 0, so that the DP's cost-to-go is what
    that runtime takes.
    Outputs, one row per node that is not removed: the exit's *shape*, exit_index (R, U,
    2**(d-1)) int32 and exit_weight (same shape) float32, the corners of the face it crosses
    (as offsets from the node's flat index) and their interpolation weights; segment_cost (R,
    U) float64, inf where the segment never leaves the cell, leaves the domain or hits an
    obstacle, nan where its state became non-finite; to_destination (R, U) bool.

    ``recording`` (for ``replay_classes``): also write each segment's accepted steps to
    ``record`` (T, S + 1), from row record_start[row, u] on (record_start, record_count: (R, U)
    int64): row 0 holds where the segment leaves its cell, as offsets from the node on the
    controller axes (columns 0..d-1), and in column S 1 if its last step leaves the cell (even
    beyond an axis's end), else 0; then one row per step: its end state (the slots where
    relative_slot (S,) bool is True as offsets from the start) and its length, s; record_count
    gets the rows. With an empty ``record`` only they are counted.
    """
    d = axis_min.shape[0]
    size = base_state.shape[0]
    n_controls = control_samples.shape[0]
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    max_steps = np.ceil(MAX_SEGMENT_SECONDS / (STIFF_STEP_FRACTION * max_step))
    for p in prange(nodes.shape[0]):
        node = nodes[p]
        row = row_of[node]
        center = np.empty(d)
        exit_state = np.empty(d)
        stages = np.empty((4, size))  # Bogacki–Shampine's k1..k4, k4 at the step's end
        k1 = stages[0]
        k2 = stages[1]
        k3 = stages[2]
        k4 = stages[3]
        start = np.empty(size)
        state = np.empty(size)
        after = np.empty(size)
        inputs = np.zeros(input_size)
        body = np.empty_like(outline)
        integer_scratch, fraction, corner_index, corner_weight = interpolation_scratch(d)
        node_coordinates(axis_min, axis_step, axis_count, node, center)
        load_state(center, state_slot, base_state, start)
        for u in range(n_controls):
            for i in range(size):
                state[i] = start[i]
            for i in range(input_size):
                inputs[i] = 0.0
            for j in range(control_slot.shape[0]):
                inputs[control_slot[j]] += control_samples[u, j]
            effort = control_effort(control_samples, effort_weight, u)
            segment_cost[row, u] = np.inf
            to_destination[row, u] = False
            for i in range(exit_index.shape[2]):
                exit_index[row, u, i] = 0
                exit_weight[row, u, i] = 0.0
            writing = recording and record.shape[0] > 0
            if recording:
                record_count[row, u] = 1
            if writing:
                for i in range(size + 1):
                    record[record_start[row, u], i] = 0.0
            model_derivative(state, inputs, k1)
            elapsed = 0.0
            h = max_step
            tried = 0
            while elapsed < MAX_SEGMENT_SECONDS and tried < max_steps:
                tried += 1
                for k in range(d):
                    speed = abs(k1[state_slot[k]])
                    if speed * h > CELL_FRACTION * axis_step[k]:
                        h = CELL_FRACTION * axis_step[k] / speed
                for i in range(size):
                    after[i] = state[i] + h * (A21 * k1[i])
                model_derivative(after, inputs, k2)
                for i in range(size):
                    after[i] = state[i] + h * (A32 * k2[i])
                model_derivative(after, inputs, k3)
                for i in range(size):
                    after[i] = state[i] + h * (B1 * k1[i] + B2 * k2[i] + B3 * k3[i])
                model_derivative(after, inputs, k4)
                # the error of the step, in units of the tolerance on each controller axis
                error = 0.0
                for k in range(d):
                    slot = state_slot[k]
                    estimate = h * (E1 * k1[slot] + E2 * k2[slot] + E3 * k3[slot] + E4 * k4[slot])
                    error = max(error, abs(estimate) / (STEP_TOLERANCE * axis_step[k]))
                if not np.isfinite(error):
                    break  # too stiff to follow at this step: cost stays inf
                if error > 1.0:
                    h *= max(0.2, 0.9 * error**ERROR_EXPONENT)
                    if h < MIN_STEP:
                        break  # too stiff to follow: cost stays inf
                    continue
                if recording:
                    r = record_start[row, u] + record_count[row, u]
                    record_count[row, u] += 1
                    if writing:
                        for i in range(size):
                            record[r, i] = after[i] - start[i] if relative_slot[i] else after[i]
                        record[r, size] = h
                if not state_is_sound(after):  # an accepted step (a nan input passes the error
                    segment_cost[row, u] = np.nan  # test): the caller reports it
                    break
                if not pose_is_free(
                    after, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body
                ):
                    break  # hits an obstacle or leaves the domain polygon: cost stays inf
                # the earliest crossing of the cell boundary within this step
                crossing = 2.0
                axis = -1
                for k in range(d):
                    slot = state_slot[k]
                    s = first_crossing(
                        state[slot],
                        after[slot],
                        h * k1[slot],
                        h * k4[slot],
                        center[k] - axis_step[k],
                        center[k] + axis_step[k],
                    )
                    if s < crossing:
                        crossing = s
                        axis = k
                if (
                    axis < 0
                    and arrives
                    and stops_in_box(
                        after,
                        vehicle_slot,
                        wheelbase,
                        wheel_radius,
                        brake,
                        state_slot,
                        arrival_box,
                        exit_state,
                    )
                ):
                    braking = braking_seconds(after, vehicle_slot, wheel_radius, brake)
                    segment_cost[row, u] = (elapsed + h + braking) * (1.0 + effort)
                    to_destination[row, u] = True
                    break
                if axis < 0:
                    elapsed += h
                    for i in range(size):
                        state[i] = after[i]
                        k1[i] = k4[i]
                    h = min(max_step, h * min(5.0, 0.9 * max(error, 1e-10) ** ERROR_EXPONENT))
                    continue
                for k in range(d):
                    slot = state_slot[k]
                    exit_state[k] = hermite(
                        state[slot],
                        after[slot],
                        h * k1[slot],
                        h * k4[slot],
                        crossing,
                    )
                if exit_state[axis] > center[axis]:
                    exit_state[axis] = center[axis] + axis_step[axis]
                else:
                    exit_state[axis] = center[axis] - axis_step[axis]
                if writing:  # where and that it crossed
                    for k in range(d):
                        record[record_start[row, u], k] = exit_state[k] - center[k]
                    record[record_start[row, u], size] = 1.0
                if not leaves_axes(axis_min, axis_step, axis_count, wrap, exit_state):
                    seconds = elapsed + crossing * h
                    segment_cost[row, u] = seconds * (1.0 + effort)
                    count = corner_weights(
                        axis_min,
                        axis_step,
                        axis_count,
                        wrap,
                        strides,
                        exit_state,
                        axis,
                        corner_index,
                        corner_weight,
                        integer_scratch,
                        fraction,
                    )
                    # weights of rounding size are zero: the exit lies on that node layer
                    total = 0.0
                    for i in range(count):
                        if corner_weight[i] < WEIGHT_EPSILON:
                            corner_weight[i] = 0.0
                        total += corner_weight[i]
                    for i in range(count):
                        exit_index[row, u, i] = corner_index[i] - node
                        exit_weight[row, u, i] = corner_weight[i] / total
                break


@njit(cache=True)
def control_effort(control_samples, effort_weight, u):
    """Σ K|u| of control sample u (control_samples (U, m), effort_weight (m,)): a segment of t
    seconds under it costs t (1 + Σ K|u|)."""
    effort = 0.0
    for j in range(control_samples.shape[1]):
        effort += effort_weight[j] * abs(control_samples[u, j])
    return effort


@njit(cache=True)
def leaves_axes(axis_min, axis_step, axis_count, wrap, exit_state):
    """True when the controller state exit_state (d,) lies beyond an end of an axis that does
    not wrap (by more than 1e-9 of its step)."""
    for k in range(axis_min.shape[0]):
        if not wrap[k]:
            top = axis_min[k] + axis_step[k] * (axis_count[k] - 1)
            if exit_state[k] < axis_min[k] - 1e-9 * axis_step[k]:
                return True
            if exit_state[k] > top + 1e-9 * axis_step[k]:
                return True
    return False


@njit(parallel=True, cache=True)
def replay_classes(
    axis_min,
    axis_step,
    axis_count,
    wrap,
    state_slot,
    base_state,
    control_samples,
    effort_weight,
    nodes,
    row_of,
    class_of,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    arrives,
    arrival_box,
    vehicle_slot,
    wheelbase,
    wheel_radius,
    brake,
    class_cost,
    record_start,
    record_count,
    record,
    relative_slot,
    segment_box,
    segment_cost,
    to_destination,
):
    """The exit transitions of a model whose equations do not read some controller axes (the
    car's x and y: ``IGNORABLE_STATES``) from the segments of one node of each *class* (the
    nodes that differ only on those axes), which move alike: the exit kernel's ``recording``,
    made without obstacles and arrival box (class_cost (C, U), record_start, record_count,
    record, relative_slot as ``exit_transitions_template`` writes them; class_of (N,) int64,
    each node's class). At each node of ``nodes`` (row ``row_of``) each class segment is moved
    there and its step ends tested as ``exit_transitions_template`` tests them: a step that
    hits an obstacle or leaves the domain polygon discards the segment, one whose braking point
    lies in the arrival box ends it at the destination; and a segment whose exit lies beyond
    the axes is discarded. Obstacles are tested only where the box the class's body sweeps
    (segment_box (C, U, 12), ``segment_boxes``), moved to the node, meets one's bounding box,
    and the arrival box only where the box of the class's braking points does; the domain only
    at nodes where the box of all the class's reference points, moved there and widened by
    ``DOMAIN_ROOM``, is not inside it (``geometry.box_in_polygon``), and a segment that then
    has nothing to test is not stepped through at all. Outputs
    segment_cost and to_destination (R, U); the exit's shape (its corners as offsets and their
    weights) is the class's."""
    d = axis_min.shape[0]
    size = base_state.shape[0]
    x_axis = axis_of_slot(state_slot, vehicle_slot[0])  # the vehicle's reference point
    y_axis = axis_of_slot(state_slot, vehicle_slot[1])
    for p in prange(nodes.shape[0]):
        node = nodes[p]
        row = row_of[node]
        segment_class = class_of[node]
        center = np.empty(d)
        exit_state = np.empty(d)
        shift = np.empty(size)  # the start state on the relative slots, else 0
        after = np.empty(size)
        body = np.empty_like(outline)
        stop = np.empty(d)
        node_coordinates(axis_min, axis_step, axis_count, node, center)
        load_state(center, state_slot, base_state, shift)
        for i in range(size):
            if not relative_slot[i]:
                shift[i] = 0.0
        step_domain = domain  # the domain each step's reference point is tested against
        if pose_slot[0] >= 0 and domain.shape[0] > 0:
            low_x = low_y = np.inf
            high_x = high_y = -np.inf
            for u in range(control_samples.shape[0]):
                low_x = min(low_x, segment_box[segment_class, u, 8])
                high_x = max(high_x, segment_box[segment_class, u, 9])
                low_y = min(low_y, segment_box[segment_class, u, 10])
                high_y = max(high_y, segment_box[segment_class, u, 11])
            x = shift[pose_slot[0]]
            y = shift[pose_slot[1]]
            if box_in_polygon(
                low_x + x - DOMAIN_ROOM,
                high_x + x + DOMAIN_ROOM,
                low_y + y - DOMAIN_ROOM,
                high_y + y + DOMAIN_ROOM,
                domain,
            ):
                step_domain = domain[:0]  # every step inside: none to test
        for u in range(control_samples.shape[0]):
            cost = class_cost[segment_class, u]
            to_destination[row, u] = False
            segment_cost[row, u] = cost
            if np.isnan(cost):
                continue  # the class's segment diverged: the caller reports it
            first = record_start[segment_class, u]
            steps = record_count[segment_class, u] - 1
            crossing_step = steps if record[first, size] != 0.0 else -1  # the step that leaves
            box = segment_box[segment_class, u]
            obstacles = obstacle_start
            arriving = arrives
            if pose_slot[0] >= 0:
                x = shift[pose_slot[0]]
                y = shift[pose_slot[1]]
                if box_is_clear(
                    box[0] + x, box[1] + x, box[2] + y, box[3] + y, obstacle_vertices, obstacles
                ):
                    obstacles = obstacle_start[:1]  # none
            if arrives:
                x = shift[vehicle_slot[0]]
                y = shift[vehicle_slot[1]]
                arriving = (
                    box[4] + x <= arrival_box[1, x_axis]
                    and box[5] + x >= arrival_box[0, x_axis]
                    and box[6] + y <= arrival_box[1, y_axis]
                    and box[7] + y >= arrival_box[0, y_axis]
                )
            if not cost < np.inf and not arriving:
                continue  # discarded, and never stops in the arrival box either
            if obstacles.shape[0] <= 1 and step_domain.shape[0] == 0 and not arriving:
                steps = 0  # no step can hit, leave or arrive: straight to the exit's test
            elapsed = 0.0
            for j in range(1, steps + 1):
                for i in range(size):
                    after[i] = record[first + j, i] + shift[i]
                elapsed += record[first + j, size]
                if not pose_is_free(
                    after, pose_slot, outline, obstacle_vertices, obstacles, step_domain, body
                ):
                    segment_cost[row, u] = np.inf
                    break
                if (
                    j != crossing_step
                    and arriving
                    and stops_in_box(
                        after,
                        vehicle_slot,
                        wheelbase,
                        wheel_radius,
                        brake,
                        state_slot,
                        arrival_box,
                        stop,
                    )
                ):
                    braking = braking_seconds(after, vehicle_slot, wheel_radius, brake)
                    effort = control_effort(control_samples, effort_weight, u)
                    segment_cost[row, u] = (elapsed + braking) * (1.0 + effort)
                    to_destination[row, u] = True
                    break
            if segment_cost[row, u] == cost < np.inf:
                for k in range(d):
                    exit_state[k] = center[k] + record[first, k]
                if leaves_axes(axis_min, axis_step, axis_count, wrap, exit_state):
                    segment_cost[row, u] = np.inf


@njit(cache=True)
def segment_boxes(
    record,
    record_start,
    record_count,
    pose_slot,
    outline,
    arrives,
    vehicle_slot,
    wheelbase,
    wheel_radius,
    brake,
    state_slot,
    out,
):
    """out (C, U, 12): for each class segment of a recording (``exit_transitions_template``),
    the box [x low, x high, y low, y high] (m, relative to the start's reference point) that
    holds its body (``pose_slot``, ``outline`` as ``geometry.pose_is_free`` takes them) at the
    end of each of its steps, then the box that holds the points where full braking from them
    would stop (``arrival.braking_stop``; where ``arrives``), then the box of the reference
    point itself at the ends of its steps (the point the domain polygon holds). An empty box
    (low inf, high -inf) where there is nothing to test."""
    size = record.shape[1] - 1
    body = np.empty_like(outline)
    stop = np.empty(state_slot.shape[0])
    x_axis = axis_of_slot(state_slot, vehicle_slot[0])
    y_axis = axis_of_slot(state_slot, vehicle_slot[1])
    for c in range(out.shape[0]):
        for u in range(out.shape[1]):
            for i in range(0, SEGMENT_BOX_COLUMNS, 2):
                out[c, u, i] = np.inf
                out[c, u, i + 1] = -np.inf
            for j in range(1, record_count[c, u]):
                state = record[record_start[c, u] + j, :size]
                if pose_slot[0] >= 0:
                    place_outline(
                        outline, state[pose_slot[0]], state[pose_slot[1]], state[pose_slot[2]], body
                    )
                    for i in range(body.shape[0]):
                        out[c, u, 0] = min(out[c, u, 0], body[i, 0])
                        out[c, u, 1] = max(out[c, u, 1], body[i, 0])
                        out[c, u, 2] = min(out[c, u, 2], body[i, 1])
                        out[c, u, 3] = max(out[c, u, 3], body[i, 1])
                    out[c, u, 8] = min(out[c, u, 8], state[pose_slot[0]])
                    out[c, u, 9] = max(out[c, u, 9], state[pose_slot[0]])
                    out[c, u, 10] = min(out[c, u, 10], state[pose_slot[1]])
                    out[c, u, 11] = max(out[c, u, 11], state[pose_slot[1]])
                if arrives:
                    braking_stop(
                        state, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, stop
                    )
                    out[c, u, 4] = min(out[c, u, 4], stop[x_axis])
                    out[c, u, 5] = max(out[c, u, 5], stop[x_axis])
                    out[c, u, 6] = min(out[c, u, 6], stop[y_axis])
                    out[c, u, 7] = max(out[c, u, 7], stop[y_axis])


@njit(cache=True)
def sweep_order(axis_count, sweep, out):
    """The grid's nodes in the order of sweep number ``sweep`` (out: (N,) int64): C order with
    the axes whose bit is set in ``sweep mod 2**d`` run backwards. Successive sweeps take the
    2**d orders in turn (the fast sweeping method), so that what is known spreads along every
    direction of the grid within a few sweeps, each running through memory in order. The first
    layer of the first axis is walked with the node index carried from one node to the next (a
    step along the last axis that moves, back to the start of the axes after it); every other
    layer is that one shifted by its steps along the first axis, a plain add that the compiler
    vectorises (the car's 1.6 million nodes in 0.4 ms against 1.2–1.6 ms walked node by node)."""
    d = axis_count.shape[0]
    backwards = sweep % (1 << d)
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    step = np.empty(d, np.int64)  # the index change of one step along each axis
    node = 0
    for k in range(d):
        if (backwards >> k) & 1:
            step[k] = -strides[k]
            node += (axis_count[k] - 1) * strides[k]
        else:
            step[k] = strides[k]
    n = out.shape[0]  # N; fewer: the order's first n nodes (0: none, to compile the kernel)
    layer = min(strides[0], n)
    first = np.empty(layer, np.int64)  # apart from ``out``, so that the adds below vectorise
    position = np.zeros(d, np.int64)
    for p in range(layer):
        first[p] = node
        k = d - 1
        while k >= 1:
            position[k] += 1
            if position[k] < axis_count[k]:
                node += step[k]
                break
            position[k] = 0
            node -= (axis_count[k] - 1) * step[k]
            k -= 1
    for i in range(axis_count[0]):
        start = i * strides[0]
        shift = i * step[0]
        count = min(layer, n - start)
        destination = out[start : start + count]  # a view from 0: the loop below vectorises
        for j in range(count):
            destination[j] = first[j] + shift


@njit(cache=True, inline="always")
def shape_of(shape_row_of, row_of, node):
    """The row of a node's exit shapes: its own row (shape_row_of None: each node has shapes of
    its own, renormalised once by ``discard_poorly_known_exits``) or its class's
    (shape_row_of (N,) int64: the nodes of a class share them, ``replay_classes``). Which it is,
    is a type, so that the kernels are compiled for each and hold no test of it."""
    if shape_row_of is None:
        return row_of[node]
    return shape_row_of[node]


@njit(cache=True)
def reach_sweep(
    exit_index, exit_weight, segment_cost, to_destination, row_of, shape_row_of, reached, order
):
    """One sweep of reachability in ``order`` (``sweep_order``), in place: a node with a row
    joins ``reached`` when some control leaves its cell (finite cost) for the destination or
    onto a face with at least one reached corner (weight > 0). Start from the destination nodes;
    repeat until nothing joins. The nodes never reached cannot reach the destination: their
    cost-to-go is inf. The exit tables as ``gauss_seidel_sweep`` takes them; reached: (N,)
    bool. Returns how many nodes joined."""
    joined = 0
    for p in range(order.shape[0]):
        node = order[p]
        row = row_of[node]
        if reached[node] or row < 0:
            continue
        shape = shape_of(shape_row_of, row_of, node)
        for u in range(segment_cost.shape[1]):
            if segment_cost[row, u] == np.inf:
                continue
            if to_destination[row, u]:
                reached[node] = True
            for i in range(exit_index.shape[2]):
                if exit_weight[shape, u, i] > 0.0 and reached[node + exit_index[shape, u, i]]:
                    reached[node] = True
                    break
            if reached[node]:
                joined += 1
                break
    return joined


@njit(cache=True)
def discard_poorly_known_exits(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    reachable,
    minimum_known_weight,
):
    """The paper's Figure 10: the cost-to-go at an exit is interpolated between the neighbours
    whose values are known, the reachable corners of its face, their weights renormalised (here,
    once, for nodes with shapes of their own, ``shape_of``; as they are read for shared shapes,
    ``known_value``); an exit whose reachable corners carry less than ``minimum_known_weight``
    of its weight (in (0, 1]; up to rounding, ``interpolate.falls_short``), or none, gets cost
    inf here. Afterwards every finite transition rests on reachable nodes. The exit tables as
    ``gauss_seidel_sweep`` takes them; reachable: (N,) bool."""
    for node in range(row_of.shape[0]):
        row = row_of[node]
        if row < 0:
            continue
        shape = shape_of(shape_row_of, row_of, node)
        for u in range(segment_cost.shape[1]):
            if segment_cost[row, u] == np.inf or to_destination[row, u]:
                continue
            known = 0.0
            for i in range(exit_index.shape[2]):
                w = exit_weight[shape, u, i]
                if w > 0.0 and reachable[node + exit_index[shape, u, i]]:
                    known += w
                elif shape_row_of is None:
                    exit_weight[shape, u, i] = 0.0
            if known == 0.0 or falls_short(known, minimum_known_weight):
                segment_cost[row, u] = np.inf
            elif shape_row_of is None:
                for i in range(exit_index.shape[2]):
                    exit_weight[shape, u, i] /= known


@njit(cache=True, inline="always")
def block_read(value, snapshot, low, high, corner):
    """The cost-to-go at ``corner`` as a sweep block [low, high) of node indices sees it
    (``blocked_gauss_seidel_sweep``): its own nodes' values as the sweep leaves them
    (``value``), the other blocks' as they stood when the sweep began (``snapshot``).
    snapshot None: one block, ``value`` alone (a type: compiled without the test, which in
    the plain sweep's loop cost four times its time)."""
    if snapshot is None:
        return value[corner]
    return value[corner] if low <= corner < high else snapshot[corner]


@njit(cache=True, inline="always")
def known_value(exit_index, exit_weight, shape, u, node, value, shape_row_of, snapshot, low, high):
    """The cost-to-go at the exit of (node, u): Σ w·V over the corners of its shape (row
    ``shape`` of the tables, corners as offsets from ``node``) whose value is known (finite:
    reachable), over the sum of their weights; zero-weight corners are skipped. Shapes of a
    node's own (shape_row_of None, ``shape_of``) have been renormalised already: Σ w·V. Values
    are read as the sweep block [low, high) sees them (``block_read``; snapshot None: all from
    ``value``)."""
    total = 0.0
    if shape_row_of is None:
        for i in range(exit_index.shape[2]):
            w = exit_weight[shape, u, i]
            if w != 0.0:
                total += w * block_read(value, snapshot, low, high, node + exit_index[shape, u, i])
        return total
    known = 0.0
    for i in range(exit_index.shape[2]):
        w = exit_weight[shape, u, i]
        if w != 0.0:
            v = block_read(value, snapshot, low, high, node + exit_index[shape, u, i])
            if v < np.inf:
                total += w * v
                known += w
    return total / known


@njit(cache=True, inline="always")
def _bellman(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    value,
    row,
    shape,
    node,
    shape_row_of,
    snapshot,
    low,
    high,
):
    """(min over u of cost(row, u) + the exit's cost-to-go (``known_value``, read as the block
    [low, high) sees it; 0 for an exit to the destination), the first minimising u); (inf, 0)
    where every control costs inf. Inlined where it is called (numba's ``inline="always"``): a
    call per node would cost more than the node's arithmetic."""
    best = np.inf
    choice = 0
    for u in range(segment_cost.shape[1]):
        cost = segment_cost[row, u]
        if cost == np.inf:
            continue
        candidate = cost
        if not to_destination[row, u]:
            candidate += known_value(
                exit_index, exit_weight, shape, u, node, value, shape_row_of, snapshot, low, high
            )
        if candidate < best:
            best = candidate
            choice = u
    return best, choice


@njit(cache=True, inline="always")
def block_positions(blocks, k, order):
    """(first, end): the positions in ``order`` (``sweep_order``) of sweep block k, the nodes
    [blocks[k], blocks[k + 1]) (blocks: (K + 1,) int64, node indices at boundaries between
    the first axis's layers, 0 and N at the ends). Each order runs through the first axis's
    layers forwards or backwards, so each block is a run of positions: forwards where the
    order starts in the first block."""
    n = order.shape[0]
    if blocks.shape[0] == 2 or order[0] < blocks[1]:
        return blocks[k], blocks[k + 1]
    return n - blocks[k + 1], n - blocks[k]


@njit(cache=True, inline="always")
def _bellman_block(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    order,
    first,
    end,
    low,
    high,
    settled_above,
    prefetching,
    control,
):
    """``gauss_seidel_sweep`` over the positions [first, end) of ``order``, reading values as
    the block of nodes [low, high) sees them (``block_read``); returns the largest decrease.
    ``prefetching``: ask the cache, a step before the sweep needs them, for the segment costs
    of the node 2·PREFETCH_AHEAD places ahead and the exit shapes (corners and weights) of the
    finite-cost controls of the node PREFETCH_AHEAD ahead. Written out in the loop: as an
    inlined function taking the tables, the hints took and dropped a reference to each table at
    every node (numba's reference counts). Measured on a car grid with exits of its own at every
    node (840,840 nodes, 1.2 GB of exit shapes; ``benchmarks/dp_sweeps.py``, mean over the
    2**5 orders): a blocked sweep 113 ms without hints, 115 ms with the inlined function, 105
    ms written out; the hints for the cost-to-go at the next node's corners (400 a node) cost
    more than they saved (117 ms) and are gone."""
    largest = 0.0
    for p in range(first, end):
        if prefetching:
            if p + 2 * PREFETCH_AHEAD < end:  # the segment costs, two steps ahead
                far = row_of[order[p + 2 * PREFETCH_AHEAD]]
                if far >= 0:
                    for u in range(0, segment_cost.shape[1], CACHE_LINE // segment_cost.itemsize):
                        prefetch(segment_cost, (far, u))
            if p + PREFETCH_AHEAD < end:  # the exit shapes of the finite-cost controls
                ahead_node = order[p + PREFETCH_AHEAD]
                ahead = row_of[ahead_node]
                if ahead >= 0:
                    ahead_shape = shape_of(shape_row_of, row_of, ahead_node)
                    per_line = CACHE_LINE // exit_index.itemsize
                    for u in range(segment_cost.shape[1]):
                        if segment_cost[ahead, u] != np.inf:
                            for i in range(0, exit_index.shape[2], per_line):
                                prefetch(exit_index, (ahead_shape, u, i))
                                prefetch(exit_weight, (ahead_shape, u, i))
        node = order[p]
        row = row_of[node]
        if row < 0 or is_destination[node]:
            continue
        old = value[node]
        if old == np.inf:  # unreachable: every exit reads only unknown corners (NaN or inf)
            continue
        best, choice = _bellman(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            value,
            row,
            shape_of(shape_row_of, row_of, node),
            node,
            shape_row_of,
            snapshot,
            low,
            high,
        )
        if best < old:
            value[node] = best
            control[node] = choice
            if old - best > largest and best < settled_above:
                largest = old - best
    return largest


@njit(cache=True)
def gauss_seidel_sweep(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    order,
    settled_above,
    prefetching,
    control,
):
    """One Gauss–Seidel sweep of value iteration over the nodes in ``order`` (``sweep_order``):
    each node's cost-to-go becomes ``min(old, update)`` at once, so the nodes after it in the
    sweep use it. Returns the largest decrease, s. control: (N,) int64, in place: where a
    node's value decreases, the control sample that gave the new value (the policy that
    ``policy_sweep`` follows).

    The exit tables: segment_cost and to_destination (R, U), one row per node that is not
    removed (row_of: (N,) int64, each node's row, -1: removed, skipped); the exits' shapes
    exit_index (int32 corner offsets from the node) and exit_weight (float32), (E, U,
    2**(d-1)), the row of a node's exits its own or, where shape_row_of is an array, its
    class's (``shape_of``). value: (N,) float64 cost-to-go, s, in place.
    Value iteration starts from an upper bound (0 at the destination nodes, a large finite
    ``UNKNOWN`` at the other reachable nodes: the paper's "values not yet known"; inf at
    unreachable nodes, which ``known_value`` leaves out), so values only decrease, as the paper
    describes; a node at inf is not swept (the car's unreachable 8 %). is_destination: (N,)
    bool, held at 0. A decrease to a value still at or above
    ``settled_above`` (s; inf: none) does not count in the largest decrease: such a node is a
    dead end (``known_weight``), whatever its exact bound. One thread, in a fixed order: the
    same result on any machine whatever the thread count (``blocked_gauss_seidel_sweep``: two
    threads, the same). ``prefetching``: ask the cache for the rows a few nodes ahead
    (``_bellman_block``; ``prefetch_pays``): half the orders run backwards through memory,
    where the processor's own prefetch falls behind on tables larger than its caches. The hint
    changes no value.
    """
    n = order.shape[0]
    # borrowed views (``kernels.borrowed``): with each class's shapes shared, the inlined
    # ``_bellman`` took and dropped references to the tables at every node (a one-block sweep of
    # park.ssc's 1.6 M nodes 286 ms, borrowed 254 ms); the arguments keep the arrays alive.
    # shape_row_of is borrowed in a call of its own: None unpacked from a tuple is no longer an
    # argument, whose ``is None`` numba decides when it compiles
    tables = (exit_index, exit_weight, segment_cost, to_destination, row_of)
    index, weight, cost, ends, rows = borrowed(tables)
    destination, values, nodes, controls = borrowed((is_destination, value, order, control))
    if shape_row_of is None:
        return _bellman_block(
            index, weight, cost, ends, rows, None, destination, values, None, nodes,
            0, n, 0, value.shape[0], settled_above, prefetching, controls,
        )  # fmt: skip
    return _bellman_block(
        index, weight, cost, ends, rows, borrowed(shape_row_of), destination, values, None, nodes,
        0, n, 0, value.shape[0], settled_above, prefetching, controls,
    )  # fmt: skip


@njit(cache=True, parallel=True)
def blocked_gauss_seidel_sweep(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    order,
    blocks,
    largest,
    settled_above,
    prefetching,
    control,
):
    """``gauss_seidel_sweep`` in blocks (``block_positions``; blocks (K + 1,) int64): the K
    blocks are swept side by side on numba's threads, each in its own part of the order,
    reading its own nodes' values as it updates them and the other blocks' from ``snapshot``
    (N,), ``value`` as it stood when the sweep began (``copy_block_edges``: at least every
    node read across a block's edge). Nothing a block reads depends on how the blocks are
    scheduled: the same result whatever the thread count. largest: (K,) work space. Returns
    the largest decrease, s."""
    for k in prange(blocks.shape[0] - 1):
        first, end = block_positions(blocks, k, order)
        largest[k] = _bellman_block(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            row_of,
            shape_row_of,
            is_destination,
            value,
            snapshot,
            order,
            first,
            end,
            blocks[k],
            blocks[k + 1],
            settled_above,
            prefetching,
            control,
        )
    return largest.max()


def policy_tables(rows: int, corners: int) -> tuple[np.ndarray, ...]:
    """The tables ``gather_policy`` fills for the policy sweeps, for ``rows`` nodes that are not
    removed and exits of ``corners`` (2**(d-1)) corners: policy_corner, policy_weight,
    policy_count, policy_cost, policy_known, and gathered (-1: nothing gathered yet)."""
    return (
        np.zeros((rows, corners), dtype=np.int32),
        np.zeros((rows, corners), dtype=np.float32),
        np.zeros(rows, dtype=np.int32),
        np.empty(rows),
        np.empty(rows),
        np.full(rows, -1, dtype=np.int64),
    )


@njit(cache=True)
def gather_policy(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    control,
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    gathered,
):
    """The exit of each node under its control (control: (N,) int64), compacted for
    ``policy_sweep`` to read in order instead of picking one control's exit out of every row
    of the full tables: for row R, its weighted corners that ``known_value`` reads, in its
    order, as node indices and weights (policy_corner (R, 2**(d-1)) int32, policy_weight
    float32, the first policy_count[R] (int32) of them), the segment's cost (policy_cost (R,),
    inf where the node is never updated: a destination, a discarded segment, an exit none of
    whose corners is known) and the sum that ``known_value`` divides by (policy_known (R,):
    the known corners' weight for shared shapes, 1 for a node's own, which are renormalised
    already; an exit to the destination has no corners). The corners with a known value
    (finite) are those of the start: value iteration only lowers finite values. Only the rows
    whose control differs from the one gathered before (gathered (R,) int64, -1: none yet)
    are rewritten: after the first Bellman sweeps few controls change. A sweep over these
    tables gives the values ``known_value`` would, bit for bit (the same sums in the same
    order), and reads about one cache line of them a node instead of the shape tables, the
    segment costs and the flags. One thread, like the sweeps of a grid swept in one block (a
    parallel loop here would be compiled for every grid)."""
    for node in range(row_of.shape[0]):
        row = row_of[node]
        if row < 0:
            continue
        u = control[node]
        if gathered[row] == u:
            continue
        gathered[row] = u
        cost = segment_cost[row, u]
        count = 0
        known = 0.0
        if is_destination[node]:
            cost = np.inf
        elif cost < np.inf and not to_destination[row, u]:
            shape = shape_of(shape_row_of, row_of, node)
            for i in range(exit_index.shape[2]):
                w = exit_weight[shape, u, i]
                if w != 0.0:
                    corner = node + exit_index[shape, u, i]
                    if shape_row_of is None or value[corner] < np.inf:
                        policy_corner[row, count] = corner
                        policy_weight[row, count] = w
                        known += w
                        count += 1
            if shape_row_of is not None and count == 0:
                cost = np.inf  # 0/0: known_value's NaN, which never lowers a value
        policy_cost[row] = cost
        policy_count[row] = count
        policy_known[row] = known if shape_row_of is not None and count > 0 else 1.0


@njit(cache=True, inline="always")
def _policy_block(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    snapshot,
    order,
    first,
    end,
    low,
    high,
    settled_above,
    prefetching,
):
    """``policy_sweep`` over the positions [first, end) of ``order``, reading values as the
    block of nodes [low, high) sees them (``block_read``), asking the cache ahead where
    ``prefetching``: the compact row of the node POLICY_PREFETCH_AHEAD places ahead, which in
    the orders that run some inner axes backwards and others forwards the processor's own
    prefetcher does not fetch in time (the car's policy sweep 12.5 ms on two threads without
    the hint, 10 ms with it, over the 2**5 orders). Written out in the loop: as an inlined
    function taking the tables, the hint took and dropped a reference to each table at every
    node (numba's reference counts), which made a one-block sweep of the car's tables 85 ms
    instead of 12. Returns the largest decrease."""
    largest = 0.0
    for p in range(first, end):
        if prefetching and p + POLICY_PREFETCH_AHEAD < end:
            ahead = row_of[order[p + POLICY_PREFETCH_AHEAD]]
            if ahead >= 0:
                prefetch(policy_corner, (ahead,))
                prefetch(policy_weight, (ahead,))
                prefetch(policy_count, (ahead,))
                prefetch(policy_cost, (ahead,))
                prefetch(policy_known, (ahead,))
        node = order[p]
        row = row_of[node]
        if row < 0:
            continue
        candidate = policy_cost[row]
        if candidate == np.inf:
            continue
        total = 0.0
        for i in range(policy_count[row]):
            total += policy_weight[row, i] * block_read(
                value, snapshot, low, high, policy_corner[row, i]
            )
        candidate += total / policy_known[row]
        old = value[node]
        if candidate < old:
            value[node] = candidate
            if old - candidate > largest and candidate < settled_above:
                largest = old - candidate
    return largest


@njit(cache=True)
def policy_sweep(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    order,
    settled_above,
    prefetching,
):
    """One Gauss–Seidel sweep in ``order`` of the Bellman update restricted to each node's
    control in the compact tables of ``gather_policy``: ``min(old, cost + the exit's
    cost-to-go)`` under that one control. Each update is the cost of a real control from the
    node, onto values that are themselves upper bounds, so values stay upper bounds of the
    cost-to-go and still only decrease; a sweep reads one control's exit per node instead of
    all of them. Returns the largest decrease, s (decreases to values at or above
    ``settled_above`` not counted, as in ``gauss_seidel_sweep``). ``prefetching``: ask the
    cache for the rows a few nodes ahead (``_policy_block``; ``prefetch_pays`` of the
    compact tables). The hint changes no value."""
    return _policy_block(
        policy_corner,
        policy_weight,
        policy_count,
        policy_cost,
        policy_known,
        row_of,
        value,
        None,
        order,
        0,
        order.shape[0],
        0,
        value.shape[0],
        settled_above,
        prefetching,
    )


@njit(cache=True, parallel=True)
def blocked_policy_sweep(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    snapshot,
    order,
    blocks,
    largest,
    settled_above,
    prefetching,
):
    """``policy_sweep`` in blocks, as ``blocked_gauss_seidel_sweep`` runs them."""
    for k in prange(blocks.shape[0] - 1):
        first, end = block_positions(blocks, k, order)
        largest[k] = _policy_block(
            policy_corner,
            policy_weight,
            policy_count,
            policy_cost,
            policy_known,
            row_of,
            value,
            snapshot,
            order,
            first,
            end,
            blocks[k],
            blocks[k + 1],
            settled_above,
            prefetching,
        )
    return largest.max()


@njit(cache=True)
def copy_block_edges(value, snapshot, edges):
    """snapshot[a:b] = value[a:b] for each row (a, b) of ``edges`` ((M, 2) int64): the nodes
    that some sweep block reads across its edge (``gauss_seidel_sweep``)."""
    for m in range(edges.shape[0]):
        for node in range(edges[m, 0], edges[m, 1]):
            snapshot[node] = value[node]


@njit(cache=True)
def gauss_seidel_sweeps(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    blocks,
    edges,
    axis_count,
    first,
    count,
    tolerance,
    order,
    settled_above,
    prefetching,
    control,
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    gathered,
    policy_sweeps,
):
    """Value iteration by modified policy iteration: Bellman sweeps (``gauss_seidel_sweep``),
    at most ``count`` of them, stopping after the first whose largest decrease is below
    ``tolerance`` (s); after each other one, up to ``policy_sweeps`` sweeps of the policy it
    left (``gather_policy``, ``policy_sweep``), stopping early once one of them changes less
    than ``tolerance``. Where Bellman sweeps shrink the largest change by only a few per cent a
    sweep (the policy's chain keeps returning to a few cells before it escapes: 130 of Luxo's
    191 sweeps, most of the car's 222), the policy has nearly settled; the policy sweeps
    run that slow mode down reading one control's exit per node from a compact table instead
    of all of them (about a tenth of a Bellman sweep's time). Every sweep takes the next of
    the orders of ``sweep_order``, counting from sweep number ``first``. The exit tables as
    ``gauss_seidel_sweep`` takes them; order: (N,) int64 and control (N,) int64 work space
    (control: zeros before the first call, kept between calls); policy_* and gathered:
    ``gather_policy``'s tables (gathered: -1 before the first call, kept between calls as the
    tables are); settled_above, prefetching: as ``gauss_seidel_sweep``. edges None: one block, each
    sweep ``gauss_seidel_sweep`` or ``policy_sweep`` (snapshot and blocks unread); else the
    blocked sweeps (``blocked_gauss_seidel_sweep``; snapshot, blocks as they take them), each
    from ``copy_block_edges`` (edges). Which it is, is a type: a grid swept in one block
    compiles no parallel sweep. Returns (Bellman sweeps run, policy sweeps run, the last
    Bellman sweep's largest decrease)."""
    block_largest = np.empty(blocks.shape[0] - 1)
    policy_prefetching = prefetch_pays(policy_corner, policy_weight)
    largest = np.inf
    sweep = first
    policy = 0
    for k in range(count):
        sweep_order(axis_count, sweep, order)
        sweep += 1
        if edges is None:
            largest = gauss_seidel_sweep(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                order,
                settled_above,
                prefetching,
                control,
            )
        else:
            copy_block_edges(value, snapshot, edges)
            largest = blocked_gauss_seidel_sweep(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                snapshot,
                order,
                blocks,
                block_largest,
                settled_above,
                prefetching,
                control,
            )
        if largest < tolerance:
            return k + 1, policy, largest
        if policy_sweeps > 0:
            gather_policy(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                control,
                policy_corner,
                policy_weight,
                policy_count,
                policy_cost,
                policy_known,
                gathered,
            )
        for _ in range(policy_sweeps):
            sweep_order(axis_count, sweep, order)
            sweep += 1
            policy += 1
            if edges is None:
                change = policy_sweep(
                    policy_corner,
                    policy_weight,
                    policy_count,
                    policy_cost,
                    policy_known,
                    row_of,
                    value,
                    order,
                    settled_above,
                    policy_prefetching,
                )
            else:
                copy_block_edges(value, snapshot, edges)
                change = blocked_policy_sweep(
                    policy_corner,
                    policy_weight,
                    policy_count,
                    policy_cost,
                    policy_known,
                    row_of,
                    value,
                    snapshot,
                    order,
                    blocks,
                    block_largest,
                    settled_above,
                    policy_prefetching,
                )
            if change < tolerance:
                break
    return count, policy, largest


@njit(cache=True)
def best_controls(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    value,
    settled_above,
    best_control,
):
    """The minimising control sample index of every node (the first on ties; 0 where every
    sample costs inf, the node is removed or its value is inf: unreachable, where every sample's
    exit reads only unknown corners). best_control: (N,) int64 out. Returns the largest excess,
    s, of a node's Bellman update over its value, over the nodes whose value is above 0 (not a
    destination) and below ``settled_above`` (0 where there are none): at most 0 for values
    reached from an upper bound (each update only lowers a value that its own update does not
    exceed), above 0 where a value lies below what its best control gives, which no value
    iteration from above leaves (``ssc.generate.solve`` checks a warm start by it)."""
    excess = 0.0
    for node in range(value.shape[0]):
        row = row_of[node]
        if row < 0 or value[node] == np.inf:
            best_control[node] = 0
            continue
        best, choice = _bellman(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            value,
            row,
            shape_of(shape_row_of, row_of, node),
            node,
            shape_row_of,
            None,
            0,
            value.shape[0],
        )
        best_control[node] = choice
        if 0.0 < value[node] < settled_above and best - value[node] > excess:
            excess = best - value[node]
    return excess


@njit(parallel=True, cache=True)
def free_nodes(
    axis_min,
    axis_step,
    axis_count,
    state_slot,
    base_state,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    out,
):
    """out (N,) bool: True for the grid nodes whose state is free of obstacles and inside the
    domain polygon (``geometry.pose_is_free``); the grid and state slots as in
    ``exit_transitions``."""
    d = axis_min.shape[0]
    for node in prange(out.shape[0]):
        center = np.empty(d)
        state = np.empty(base_state.shape[0])
        body = np.empty_like(outline)
        node_coordinates(axis_min, axis_step, axis_count, node, center)
        load_state(center, state_slot, base_state, state)
        out[node] = pose_is_free(
            state, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body
        )


DESTINATION_TOLERANCE = 1e-9  # the largest change of a destination share that ends the sweeps
DESTINATION_MAX_SWEEPS = 10_000  # a cap on them (a converged table needs tens)


@njit(cache=True)
def destination_share_sweep(
    exit_index,
    exit_weight,
    to_destination,
    row_of,
    shape_row_of,
    best_control,
    reachable,
    terminal_node,
    active,
    share,
    order,
):
    """One Gauss–Seidel sweep, in ``order`` (``sweep_order``), of the destination shares
    (``destination_indices``): each ``active`` node's share of every destination becomes the
    weighted sum of its best exit's reachable corners' shares (weights renormalised over them,
    as ``known_value`` does; the share of ``terminal_node`` for an exit to the destination), at
    once, so that the nodes after it in the sweep use it. active: (N,) bool; share: (N, D)
    float64, in place. Returns the largest change of a share."""
    largest = 0.0
    for p in range(order.shape[0]):
        node = order[p]
        if not active[node]:
            continue
        row = row_of[node]
        shape = shape_of(shape_row_of, row_of, node)
        u = best_control[node]
        for k in range(share.shape[1]):
            if to_destination[row, u]:
                total = share[terminal_node, k]
            else:
                total = 0.0
                known = 0.0
                for i in range(exit_index.shape[2]):
                    w = exit_weight[shape, u, i]
                    corner = node + exit_index[shape, u, i]
                    if w != 0.0 and reachable[corner]:
                        total += w * share[corner, k]
                        known += w
                total /= known
            change = abs(total - share[node, k])
            if change > largest:
                largest = change
            share[node, k] = total
    return largest


@njit(cache=True)
def destination_indices(
    exit_index,
    exit_weight,
    to_destination,
    row_of,
    shape_row_of,
    best_control,
    reachable,
    terminal_node,
    value,
    destination_label,
    axis_count,
    tolerance,
    max_sweeps,
    order,
    share,
    out,
):
    """Which destination each node's optimal path ends at, for a spec with several ``dest``
    lines (the contract's ``/destination_index``), written into out (N,) int64; returns the
    sweeps run.

    The exit tables as ``gauss_seidel_sweep`` takes them (after ``discard_poorly_known_exits``);
    best_control (N,) int64 (``best_controls``); reachable (N,) bool, the nodes whose value the
    DP knew; terminal_node: the destination node an exit to the destination
    (``to_destination``) ends at; value (N,) float64, the table's cost-to-go, s (inf:
    unreachable or dead end); destination_label (N,) int64, the ``dest`` line (0 .. D-1) a
    destination node matches (the first, if several), -1 for the other nodes; axis_count (d,)
    int64; order (N,) int64 work space; share (N, D) float64 out: the destination shares below.

    The rule. The DP reads an exit as going on to the corners of the face it crosses in the
    proportions of their interpolation weights: the cost-to-go is the expected cost of that
    path. The share of destination k at a node is the probability that this path ends at k:
    1 for k's own nodes (0 for the other destinations), and elsewhere the weighted sum of the
    shares of the best control's exit corners, ``share(S) = Σ w_i share(corner_i)`` — a
    weight vote over the exit's corners, repeated until it is a fixed point. That is solved
    by Gauss–Seidel sweeps in the orders of ``sweep_order`` until no share changes by more
    than ``tolerance`` (or ``max_sweeps``); chains of exits that loop back are part of the
    linear system and need no special case. A node's index is the destination with the
    largest share (ties: the lowest index); -1 where the value is inf. A finite-valued node
    whose shares are all 0 (its path never reaches a destination: not seen in a converged
    table, since every exit costs time) takes 0, the first destination. One thread, fixed
    orders: deterministic.
    """
    n = value.shape[0]
    active = np.zeros(n, np.bool_)
    for node in range(n):
        for k in range(share.shape[1]):
            share[node, k] = 0.0
        if not value[node] < np.inf:
            continue
        if destination_label[node] >= 0:
            share[node, destination_label[node]] = 1.0
        elif row_of[node] >= 0:
            active[node] = True
    sweeps = 0
    while sweeps < max_sweeps:
        sweep_order(axis_count, sweeps, order)
        largest = destination_share_sweep(
            exit_index,
            exit_weight,
            to_destination,
            row_of,
            shape_row_of,
            best_control,
            reachable,
            terminal_node,
            active,
            share,
            order,
        )
        sweeps += 1
        if largest <= tolerance:
            break
    for node in range(n):
        if not value[node] < np.inf:
            out[node] = -1
            continue
        choice = 0
        for k in range(1, share.shape[1]):
            if share[node, k] > share[node, choice]:
                choice = k
        out[node] = choice
    return sweeps
