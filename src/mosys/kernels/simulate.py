"""Closed-loop simulation of a figure under a state-space controller table."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from mosys.kernels.figure_state import read_state
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
    grid_strides,
    interpolate_with,
    interpolation_scratch,
)
from mosys.kernels.regions import crossed_a_region_border, region_membership
from mosys.kernels.soundness import blown_up, state_is_sound

SIMULATE_SIGNATURE = types.int64(
    DERIVATIVE_INTO,  # derivative_into
    VECTOR,  # axis_min
    VECTOR,  # axis_step
    INDICES,  # axis_count
    FLAGS,  # wrap
    types.float64[:, ::1],  # torque_table
    FLAGS,  # known
    VECTOR,  # control_min
    VECTOR,  # control_max
    VECTOR,  # slew_step
    VECTOR,  # previous (in/out)
    INDICES,  # state_slot
    INDICES,  # control_slot
    types.int64,  # input_size
    VECTOR,  # state (in/out)
    types.float64,  # dt
    types.float64[:, ::1],  # record_state
    types.float64[:, ::1],  # record_control
    FLAGS,  # record_outside
    types.float64[:, ::1],  # region_lower
    types.float64[:, ::1],  # region_upper
    VECTOR,  # region_period
)


@njit(SIMULATE_SIGNATURE, cache=True)
def simulate_controlled(
    derivative_into,
    axis_min,
    axis_step,
    axis_count,
    wrap,
    torque_table,
    known,
    control_min,
    control_max,
    slew_step,
    previous,
    state_slot,
    control_slot,
    input_size,
    state,
    dt,
    record_state,
    record_control,
    record_outside,
    region_lower,
    region_upper,
    region_period,
):
    """Simulate up to ``record_state.shape[0]`` RK4 steps of dt seconds under a controller;
    return how many were taken, or ``blown_up(step)`` (< 0) when the state is not sound
    (``state_is_sound``: NaN, inf or beyond ±STATE_LIMIT) before step ``step`` or after the
    last: the records are filled for the steps before, ``state`` holds the unsound state.

    Regions (state-space breakpoints and arrival boxes): boxes ``[region_lower[k],
    region_upper[k]]`` ((K, S) SI, ±inf for unbounded entries) over the model's full state,
    angles compared modulo ``region_period`` ((S,): 2π for an angle, else 0; ``inside_region``).
    The run stops before the first step whose starting state lies in a different set of boxes
    than the run's first state (K = 0: never), so the caller can hand over to another
    controller there.

    At every step the controller's state is read from the model's state, clamped into the
    table's domain (non-wrap axes; ``record_outside`` marks the steps where it had to be), the
    controls are n-linearly interpolated from ``torque_table`` (N, m) over the ``known`` (N,)
    nodes (those with a finite cost-to-go; ``interpolate_with``), clamped to
    [control_min, control_max] (m,) and held for the step (zero-order hold) on the model's
    inputs (``control_slot`` (m,) of ``input_size``). SI units throughout; grids as in
    ``kernels.interpolate``.
    state: (S,) the model's state, advanced in place. Records, one row per step, taken at the
    step's start: record_state (steps, S), record_control (steps, m), record_outside (steps,).
    """
    size = state.shape[0]
    d = axis_min.shape[0]
    m = control_slot.shape[0]
    inputs = np.zeros(input_size)
    scratch = rk4_scratch(size)
    controller_state = np.empty(d)
    clamped = np.empty(d)
    control = np.empty(m)
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    interpolation = interpolation_scratch(d)
    regions = region_lower.shape[0]
    start_membership = np.empty(regions, np.bool_)
    membership = np.empty(regions, np.bool_)
    region_membership(state, region_lower, region_upper, region_period, start_membership)
    for step in range(record_state.shape[0]):
        if not state_is_sound(state):
            return blown_up(step)
        if crossed_a_region_border(
            state, region_lower, region_upper, region_period, start_membership, membership
        ):
            return step
        for i in range(size):
            record_state[step, i] = state[i]
        read_state(state, state_slot, controller_state)
        inside = clamp_to_domain(axis_min, axis_step, axis_count, wrap, controller_state, clamped)
        record_outside[step] = not inside
        interpolate_with(
            axis_min,
            axis_step,
            axis_count,
            wrap,
            strides,
            torque_table,
            known,
            clamped,
            interpolation,
            control,
        )
        for i in range(input_size):
            inputs[i] = 0.0
        for j in range(m):
            value = min(max(control[j], control_min[j]), control_max[j])
            value = min(max(value, previous[j] - slew_step[j]), previous[j] + slew_step[j])
            previous[j] = value
            record_control[step, j] = value
            inputs[control_slot[j]] += value
        rk4_step(derivative_into, state, inputs, dt, scratch)
    if not state_is_sound(state):
        return blown_up(record_state.shape[0])
    return record_state.shape[0]
