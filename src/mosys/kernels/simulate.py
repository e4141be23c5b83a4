"""Closed-loop simulation of a figure under a state-space controller table."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from mosys.kernels.figure_state import read_state
from mosys.kernels.integrate import QDD_INTO, rk4_scratch, rk4_step
from mosys.kernels.interpolate import (
    clamp_to_domain,
    grid_strides,
    interpolate_with,
    interpolation_scratch,
)

F1 = types.float64[::1]
I1 = types.int64[::1]
B1 = types.boolean[::1]
SIMULATE_SIGNATURE = types.void(
    QDD_INTO,  # qdd_into
    F1,  # axis_min
    F1,  # axis_step
    I1,  # axis_count
    B1,  # wrap
    types.float64[:, ::1],  # torque_table
    F1,  # control_min
    F1,  # control_max
    I1,  # state_slot
    I1,  # control_slot
    F1,  # state (in/out)
    types.float64,  # dt
    types.float64[:, ::1],  # record_state
    types.float64[:, ::1],  # record_control
    B1,  # record_outside
)


@njit(SIMULATE_SIGNATURE, cache=True)
def simulate_controlled(
    qdd_into,
    axis_min,
    axis_step,
    axis_count,
    wrap,
    torque_table,
    control_min,
    control_max,
    state_slot,
    control_slot,
    state,
    dt,
    record_state,
    record_control,
    record_outside,
):
    """Simulate ``record_state.shape[0]`` RK4 steps of dt seconds under a controller.

    At every step the controller's state is read from the figure state, clamped into the table's
    domain (non-wrap axes; ``record_outside`` marks the steps where it had to be), the torques are
    n-linearly interpolated from ``torque_table`` (N, m), clamped to [control_min, control_max]
    (m,) and held for the step (zero-order hold). SI units throughout; grids as in
    ``kernels.interpolate``.
    state: (2n,) figure state q‖qd, advanced in place. Records, one row per step, taken at the
    step's start: record_state (S, 2n), record_control (S, m), record_outside (S,).
    """
    n = state.shape[0] // 2
    d = axis_min.shape[0]
    m = control_slot.shape[0]
    q = np.empty(n)
    qd = np.empty(n)
    tau = np.zeros(n)
    scratch = rk4_scratch(n)
    controller_state = np.empty(d)
    clamped = np.empty(d)
    control = np.empty(m)
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    interpolation = interpolation_scratch(d)
    for i in range(n):
        q[i] = state[i]
        qd[i] = state[n + i]
    for step in range(record_state.shape[0]):
        for i in range(n):
            record_state[step, i] = q[i]
            record_state[step, n + i] = qd[i]
        read_state(q, qd, state_slot, controller_state)
        inside = clamp_to_domain(axis_min, axis_step, axis_count, wrap, controller_state, clamped)
        record_outside[step] = not inside
        interpolate_with(
            axis_min,
            axis_step,
            axis_count,
            wrap,
            strides,
            torque_table,
            clamped,
            interpolation,
            control,
        )
        for i in range(n):
            tau[i] = 0.0
        for j in range(m):
            value = min(max(control[j], control_min[j]), control_max[j])
            record_control[step, j] = value
            tau[control_slot[j]] += value
        rk4_step(qdd_into, q, qd, tau, dt, scratch)
    for i in range(n):
        state[i] = q[i]
        state[n + i] = qd[i]
