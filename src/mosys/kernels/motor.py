"""Open-loop simulation of a figure under a motor program: procedural torques over time."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from mosys.kernels.integrate import DERIVATIVE_INTO, INDICES, VECTOR, rk4_scratch, rk4_step

LIMP = 0  # the actuator applies no torque
TORQUE = 1  # a constant torque, N m
SERVO = 2  # a servo towards a target angle: kp (target - angle) - kd rate

MATRIX = types.float64[:, ::1]

MOTOR_SIGNATURE = types.void(
    DERIVATIVE_INTO,  # derivative_into
    INDICES,  # phase_steps
    types.int64[:, ::1],  # mode
    MATRIX,  # value
    MATRIX,  # kp
    MATRIX,  # kd
    VECTOR,  # limit
    INDICES,  # coordinate
    types.int64,  # input_size
    VECTOR,  # state (in/out)
    types.float64,  # dt
    MATRIX,  # record_state
    MATRIX,  # record_control
    INDICES,  # record_phase
)


@njit(MOTOR_SIGNATURE, cache=True)
def run_motor_program(
    derivative_into,
    phase_steps,
    mode,
    value,
    kp,
    kd,
    limit,
    coordinate,
    input_size,
    state,
    dt,
    record_state,
    record_control,
    record_phase,
):
    """Simulate a motor program's phases one after another with RK4 steps of dt seconds.

    Phase p lasts ``phase_steps[p]`` steps. In it, actuator a (driving coordinate
    ``coordinate[a]`` of the model, input slot ``coordinate[a]`` of ``input_size``) applies, per
    ``mode[p, a]``: LIMP, 0; TORQUE, ``value[p, a]`` N m; SERVO, ``kp (value - q) - kd qd`` with
    the target ``value[p, a]`` rad and the gains ``kp[p, a]`` N m/rad, ``kd[p, a]`` N m s/rad,
    evaluated at the step's start and held over it. Every torque is clamped to
    ``±limit[a]`` (inf: no cap). SI units throughout.
    state: (S,) the model's state q‖qd, advanced in place. Records, one row per step, taken at
    the step's start: record_state (steps, S), record_control (steps, A) N m, record_phase
    (steps,) the phase index; steps = phase_steps.sum().
    """
    size = state.shape[0]
    n = size // 2
    inputs = np.zeros(input_size)
    scratch = rk4_scratch(size)
    step = 0
    for p in range(phase_steps.shape[0]):
        for _ in range(phase_steps[p]):
            for i in range(size):
                record_state[step, i] = state[i]
            for i in range(input_size):
                inputs[i] = 0.0
            for a in range(coordinate.shape[0]):
                c = coordinate[a]
                torque = 0.0
                if mode[p, a] == TORQUE:
                    torque = value[p, a]
                elif mode[p, a] == SERVO:
                    torque = kp[p, a] * (value[p, a] - state[c]) - kd[p, a] * state[n + c]
                torque = min(max(torque, -limit[a]), limit[a])
                record_control[step, a] = torque
                inputs[c] += torque
            record_phase[step] = p
            rk4_step(derivative_into, state, inputs, dt, scratch)
            step += 1
