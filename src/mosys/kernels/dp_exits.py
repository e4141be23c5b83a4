"""The DP's grid and its exit transitions (van de Panne et al. 1990, §3.5): what value
iteration (``kernels.dp``) sweeps over.

For every grid node S and every sampled control u, the figure is simulated from S with u held
constant until its state leaves S's cell — the box of half-width one grid step around S, whose
boundary carries S's neighbours (points A, B, C, F of the paper's Figure 10). The exit state E, the
segment cost ``t + Σ K|u| t`` and E's interpolation weights over the nodes of the face it crosses do
not depend on the cost-to-go, so they are computed once (``exit_transitions_template``, specialised
to each model), E's corners and weights as a *shape* (corners as offsets from S). A model whose
equations do not read some coordinates (the car's x and y) moves alike from every node of a
*class* (the nodes differing only there): its segments are integrated once per class and
replayed at each node (``replay_classes``), whose exits share the class's shapes. Which nodes
exist at all (free of obstacles, inside the domain) is ``free_nodes``.

All quantities here are SI (rad, rad/s, m, m/s, s, N·m); grids follow ``kernels.interpolate``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from mosys.kernels.arrival import braking_seconds, braking_stop, stops_in_box
from mosys.kernels.figure_state import load_state
from mosys.kernels.geometry import box_in_polygon, box_is_clear, place_outline, pose_is_free
from mosys.kernels.interpolate import corner_weights, grid_strides, interpolation_scratch
from mosys.kernels.soundness import state_is_sound
from mosys.kernels.specialise import model_derivative

SEGMENT_BOX_COLUMNS = 12  # ``segment_boxes``: the body's, the braking points' and the reference
# point's boxes, each [x low, x high, y low, y high]
DOMAIN_ROOM = 1e-9  # m: a node whose segments' reference points stay inside the domain polygon
# with this much room to spare on every side (``replay_classes``) is not tested step by step


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
