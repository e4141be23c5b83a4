"""Open-loop simulation of a figure under a motor program: procedural torques over time."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from mosys.kernels.integrate import DERIVATIVE_INTO, INDICES, VECTOR, rk4_scratch, rk4_step
from mosys.kernels.soundness import blown_up, state_is_sound

LIMP = 0  # the actuator applies no torque
TORQUE = 1  # a constant torque, N m
SERVO = 2  # a servo towards a moving target: kp (target - angle) + kd (target rate - rate)

MATRIX = types.float64[:, ::1]

MOTOR_SIGNATURE = types.int64(
    DERIVATIVE_INTO,  # derivative_into
    types.int64[:, ::1],  # mode
    MATRIX,  # value
    MATRIX,  # rate
    MATRIX,  # kp
    MATRIX,  # kd
    VECTOR,  # limit
    VECTOR,  # slew_step
    VECTOR,  # previous (in/out)
    INDICES,  # coordinate
    types.int64,  # input_size
    VECTOR,  # state (in/out)
    types.float64,  # dt
    MATRIX,  # record_state
    MATRIX,  # record_control
)


@njit(MOTOR_SIGNATURE, cache=True)
def run_motor_program(
    derivative_into,
    mode,
    value,
    rate,
    kp,
    kd,
    limit,
    slew_step,
    previous,
    coordinate,
    input_size,
    state,
    dt,
    record_state,
    record_control,
):
    """Simulate a motor program, laid out one row per step, with RK4 steps of dt seconds.

    In step s, actuator a (driving coordinate ``coordinate[a]`` of the model, input slot
    ``coordinate[a]`` of ``input_size``) applies, per ``mode[s, a]``: LIMP, 0; TORQUE,
    ``value[s, a]`` N m; SERVO, ``kp (value - q) + kd (rate - qd)`` towards the target angle
    ``value[s, a]`` rad moving at ``rate[s, a]`` rad/s, with the gains ``kp[s, a]`` N m/rad,
    ``kd[s, a]`` N m s/rad; each evaluated at the step's start and held over it. The torque is
    clamped to ``±limit[a]`` (inf: no cap), then to within ``slew_step[a]`` N m of the
    actuator's torque on the step before (``previous[a]``; inf: no slew limit), and becomes
    ``previous[a]``. SI units throughout.
    mode, value, rate, kp, kd: (steps, A); limit, slew_step: (A,) float64; previous: (A,)
    float64, N m, the torques before the first step, left holding the last step's.
    state: (S,) the model's state q‖qd, advanced in place. Records, one row per step, taken at
    the step's start: record_state (steps, S), record_control (steps, A) N m.
    Returns the steps taken, all of them, or ``soundness.blown_up(step)`` (< 0) when the state is
    not sound (``soundness.state_is_sound``: NaN, inf, huge) before step ``step`` or after the
    last: the records are filled for the steps before, ``state`` holds the unsound state.
    """
    size = state.shape[0]
    n = size // 2
    inputs = np.zeros(input_size)
    scratch = rk4_scratch(size)
    for step in range(mode.shape[0]):
        if not state_is_sound(state):
            return blown_up(step)
        for i in range(size):
            record_state[step, i] = state[i]
        for i in range(input_size):
            inputs[i] = 0.0
        for a in range(coordinate.shape[0]):
            c = coordinate[a]
            torque = 0.0
            if mode[step, a] == TORQUE:
                torque = value[step, a]
            elif mode[step, a] == SERVO:
                torque = kp[step, a] * (value[step, a] - state[c]) + kd[step, a] * (
                    rate[step, a] - state[n + c]
                )
            torque = min(max(torque, -limit[a]), limit[a])
            torque = min(max(torque, previous[a] - slew_step[a]), previous[a] + slew_step[a])
            previous[a] = torque
            record_control[step, a] = torque
            inputs[c] += torque
        rk4_step(derivative_into, state, inputs, dt, scratch)
    if not state_is_sound(state):
        return blown_up(mode.shape[0])
    return mode.shape[0]
