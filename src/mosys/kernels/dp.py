"""Dynamic programming for state-space controllers (van de Panne et al. 1990, §3.5).

For every grid node S and every sampled control u, the figure is simulated from S with u held
constant until its state leaves S's cell — the box of half-width one grid step around S, whose
boundary carries S's neighbours (points A, B, C, F of the paper's Figure 10). The exit state E, the
segment cost ``t + Σ K|u| t`` and E's interpolation weights over the nodes of the face it crosses do
not depend on the cost-to-go, so they are computed once (``exit_transitions``). Value iteration then
repeats Bellman sweeps ``V(S) = min_u [cost(S,u) + Σ w V(corner)]`` until the largest change is
below a tolerance (``bellman_sweep``).

All quantities here are SI (rad, rad/s, m, m/s, s, N·m); grids follow ``kernels.interpolate``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types

from mosys.kernels.figure_state import load_state, read_state
from mosys.kernels.geometry import pose_is_free
from mosys.kernels.integrate import (
    DERIVATIVE_INTO,
    FLAGS,
    INDICES,
    VECTOR,
    rk4_scratch,
    rk4_step,
)
from mosys.kernels.interpolate import corner_weights, grid_strides, interpolation_scratch


@njit(cache=True)
def node_coordinates(axis_min, axis_step, axis_count, node, out):
    """Coordinates (d,) of flat C-order node index ``node``, written into out."""
    rest = node
    for k in range(axis_count.shape[0] - 1, -1, -1):
        out[k] = axis_min[k] + axis_step[k] * (rest % axis_count[k])
        rest //= axis_count[k]


WEIGHT_EPSILON = 1e-9  # interpolation weights below this are rounding noise
EXIT_TRANSITIONS_SIGNATURE = types.void(
    DERIVATIVE_INTO,  # derivative_into
    VECTOR,  # axis_min
    VECTOR,  # axis_step
    INDICES,  # axis_count
    FLAGS,  # wrap
    INDICES,  # state_slot
    VECTOR,  # base_state
    types.float64[:, ::1],  # control_samples
    INDICES,  # control_slot
    types.int64,  # input_size
    VECTOR,  # effort_weight
    types.float64,  # dt
    types.int64,  # max_steps
    INDICES,  # nodes
    FLAGS,  # node_valid
    INDICES,  # pose_slot
    types.float64[:, ::1],  # outline
    types.float64[:, ::1],  # obstacle_vertices
    INDICES,  # obstacle_start
    types.float64[:, ::1],  # domain
    types.int32[:, :, ::1],  # exit_index
    types.float32[:, :, ::1],  # exit_weight
    types.float64[:, ::1],  # segment_cost
)


# An explicit signature types derivative_into as a first-class function, so this kernel is cached
# once for every model (a plain Dispatcher argument would recompile it in every process).
@njit(EXIT_TRANSITIONS_SIGNATURE, parallel=True, cache=True)
def exit_transitions(
    derivative_into,
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
    dt,
    max_steps,
    nodes,
    node_valid,
    pose_slot,
    outline,
    obstacle_vertices,
    obstacle_start,
    domain,
    exit_index,
    exit_weight,
    segment_cost,
):
    """Simulate every (node, control sample) pair until it leaves the node's cell.

    Long because the explicit signature (one cached kernel for every model) lists each argument
    and each prange iteration allocates its own scratch in this body; the cell-crossing and
    exit-weight blocks could move into helpers later.

    derivative_into: the model's first-class dynamics (``integrate.DERIVATIVE_INTO``).
    axis_*: (d,) the controller grid, SI; state_slot: (d,) int64 index of each controller axis in
    the model's state (length S); base_state: (S,) values of the uncovered slots.
    control_samples: (U, m) sampled controls; control_slot: (m,) int64 entry of the model's
    inputs (input_size of them) each control drives; effort_weight: (m,) K of the cost
    t + Σ K|u| t.
    dt: RK4 step, s; max_steps: a segment that has not left its cell after this many steps is
    discarded (cost inf).
    nodes: (P,) int64 flat node indices to process; node_valid: (N,) bool (False: removed node).
    pose_slot, outline, obstacle_vertices, obstacle_start, domain: the obstacles, as
    ``geometry.pose_is_free`` takes them (pose_slot[0] < 0: none); a segment whose state is not
    free at the end of any integration step is discarded.
    Outputs, rows indexed by node: exit_index (N, U, 2**(d-1)) int32 and exit_weight
    (N, U, 2**(d-1)) float32, the nodes and weights interpolating the exit state on the face it
    crosses; segment_cost (N, U) float64, inf where the segment never leaves the cell, leaves
    the domain or hits an obstacle.
    """
    d = axis_min.shape[0]
    size = base_state.shape[0]
    n_controls = control_samples.shape[0]
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    for p in prange(nodes.shape[0]):
        node = nodes[p]
        if not node_valid[node]:
            for u in range(n_controls):
                segment_cost[node, u] = np.inf
            continue
        center = np.empty(d)
        before = np.empty(d)
        after = np.empty(d)
        exit_state = np.empty(d)
        state = np.empty(size)
        inputs = np.zeros(input_size)
        scratch = rk4_scratch(size)
        body = np.empty_like(outline)
        integer_scratch, fraction, corner_index, corner_weight = interpolation_scratch(d)
        node_coordinates(axis_min, axis_step, axis_count, node, center)
        for u in range(n_controls):
            load_state(center, state_slot, base_state, state)
            for i in range(input_size):
                inputs[i] = 0.0
            effort = 0.0
            for j in range(control_slot.shape[0]):
                inputs[control_slot[j]] += control_samples[u, j]
                effort += effort_weight[j] * abs(control_samples[u, j])
            segment_cost[node, u] = np.inf
            for i in range(exit_index.shape[2]):
                exit_index[node, u, i] = node
                exit_weight[node, u, i] = 0.0
            for step in range(max_steps):
                read_state(state, state_slot, before)
                rk4_step(derivative_into, state, inputs, dt, scratch)
                if not pose_is_free(
                    state, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body
                ):
                    break  # hits an obstacle or leaves the domain polygon: cost stays inf
                read_state(state, state_slot, after)
                # earliest crossing of the cell boundary within this step, by linear interpolation
                crossing = 2.0
                axis = -1
                for k in range(d):
                    low = center[k] - axis_step[k]
                    high = center[k] + axis_step[k]
                    if after[k] >= high:
                        s = (high - before[k]) / (after[k] - before[k])
                    elif after[k] <= low:
                        s = (low - before[k]) / (after[k] - before[k])
                    else:
                        continue
                    if s < crossing:
                        crossing = s
                        axis = k
                if axis < 0:
                    continue
                for k in range(d):
                    exit_state[k] = before[k] + crossing * (after[k] - before[k])
                if exit_state[axis] > center[axis]:
                    exit_state[axis] = center[axis] + axis_step[axis]
                else:
                    exit_state[axis] = center[axis] - axis_step[axis]
                leaves_domain = False
                for k in range(d):
                    if not wrap[k]:
                        top = axis_min[k] + axis_step[k] * (axis_count[k] - 1)
                        if exit_state[k] < axis_min[k] - 1e-9 * axis_step[k]:
                            leaves_domain = True
                        if exit_state[k] > top + 1e-9 * axis_step[k]:
                            leaves_domain = True
                if not leaves_domain:
                    seconds = (step + crossing) * dt
                    segment_cost[node, u] = seconds * (1.0 + effort)
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
                        exit_index[node, u, i] = corner_index[i]
                        exit_weight[node, u, i] = corner_weight[i] / total
                break


@njit(parallel=True, cache=True)
def reach_sweep(exit_index, exit_weight, segment_cost, valid, reached, new_reached):
    """One sweep of reachability: a valid node joins ``reached`` when some control leaves its
    cell (finite cost) onto a face with at least one reached corner (weight > 0). Start from the
    destination nodes; repeat until nothing joins. The nodes never reached cannot reach the
    destination: their cost-to-go is inf.
    valid, reached, new_reached: (N,) bool. Returns how many nodes joined."""
    joined = np.zeros(reached.shape[0], np.int64)
    for node in prange(reached.shape[0]):
        new_reached[node] = reached[node]
        if reached[node] or not valid[node]:
            continue
        for u in range(segment_cost.shape[1]):
            if segment_cost[node, u] == np.inf:
                continue
            for i in range(exit_index.shape[2]):
                if exit_weight[node, u, i] > 0.0 and reached[exit_index[node, u, i]]:
                    new_reached[node] = True
                    joined[node] = 1
                    break
            if new_reached[node]:
                break
    return joined.sum()


@njit(parallel=True, cache=True)
def interpolate_known_values_only(exit_index, exit_weight, segment_cost, reachable):
    """Restrict every exit's interpolation to the reachable corners of its face (the paper's
    Figure 10: the cost-to-go at the exit is interpolated between the neighbours whose values
    are known) by zeroing the other weights and renormalising; an exit with no reachable corner
    gets cost inf. Afterwards every finite transition rests on reachable nodes only."""
    for node in prange(segment_cost.shape[0]):
        for u in range(segment_cost.shape[1]):
            if segment_cost[node, u] == np.inf:
                continue
            total = 0.0
            for i in range(exit_index.shape[2]):
                if exit_weight[node, u, i] > 0.0 and not reachable[exit_index[node, u, i]]:
                    exit_weight[node, u, i] = 0.0
                total += exit_weight[node, u, i]
            if total == 0.0:
                segment_cost[node, u] = np.inf
            else:
                for i in range(exit_index.shape[2]):
                    exit_weight[node, u, i] /= total


@njit(cache=True)
def _expected_value(exit_index, exit_weight, node, u, value):
    """Σ w·V over the exit corners of (node, u); zero-weight corners are skipped."""
    total = 0.0
    for i in range(exit_index.shape[2]):
        w = exit_weight[node, u, i]
        if w != 0.0:
            total += w * value[exit_index[node, u, i]]
    return total


@njit(cache=True)
def _bellman(exit_index, exit_weight, segment_cost, value, node):
    """(min over u of cost(node, u) + Σ w·V(corner), the first minimising u); (inf, 0) where
    every control costs inf."""
    best = np.inf
    choice = 0
    for u in range(segment_cost.shape[1]):
        cost = segment_cost[node, u]
        if cost == np.inf:
            continue
        candidate = cost + _expected_value(exit_index, exit_weight, node, u, value)
        if candidate < best:
            best = candidate
            choice = u
    return best, choice


@njit(parallel=True, cache=True)
def bellman_sweep(exit_index, exit_weight, segment_cost, is_destination, value, new_value, change):
    """One Jacobi sweep of value iteration; returns the largest decrease of the cost-to-go.

    value, new_value, change: (N,) float64 cost-to-go, s. Value iteration starts from an upper
    bound (0 at the destination nodes, a large finite ``UNKNOWN`` at the other reachable nodes:
    the paper's "values not yet known"; inf at unreachable nodes, which no finite transition
    touches after ``interpolate_known_values_only``) and each sweep keeps ``min(old, update)``,
    so values only decrease, as the paper describes. is_destination: (N,) bool, held at 0.
    Deterministic whatever the thread count: each node writes only its own entries.
    """
    nodes = value.shape[0]
    for node in prange(nodes):
        best = value[node]
        if not is_destination[node]:
            best = min(best, _bellman(exit_index, exit_weight, segment_cost, value, node)[0])
        new_value[node] = best
        change[node] = 0.0 if best == value[node] else value[node] - best
    largest = 0.0
    for node in range(nodes):
        if change[node] > largest:
            largest = change[node]
    return largest


@njit(parallel=True, cache=True)
def best_controls(exit_index, exit_weight, segment_cost, value, best_control):
    """The minimising control sample index of every node (the first on ties; 0 where every
    sample costs inf). best_control: (N,) int64 out."""
    for node in prange(value.shape[0]):
        best_control[node] = _bellman(exit_index, exit_weight, segment_cost, value, node)[1]


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
