"""Fixed-step RK4 over a dynamics module's first-order ``derivative_into``.

The dynamics arrive as a numba first-class function of type ``DERIVATIVE_INTO``: every dynamics
module (generated from a figure spec, or a built-in model) declares ``derivative_into(state,
inputs, out)`` with exactly this signature, so the kernels that take it are compiled once and
cached across processes, whatever the model.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types

# numba types of C-contiguous 1-D arrays, for the kernels' explicit signatures
VECTOR = types.float64[::1]
INDICES = types.int64[::1]
FLAGS = types.boolean[::1]
DERIVATIVE_INTO = types.FunctionType(types.void(VECTOR, VECTOR, VECTOR))


@njit(cache=True)
def rk4_scratch(size):
    """Work array for ``rk4_step`` on a state of ``size`` entries: (5, size) float64."""
    return np.empty((5, size))


@njit(cache=True)
def rk4_step(derivative_into, state, inputs, dt, scratch):
    """Advance ``state`` (S,) SI in place by one RK4 step of dt seconds, ``inputs`` held
    constant. scratch: from ``rk4_scratch(S)``."""
    k1 = scratch[0]
    k2 = scratch[1]
    k3 = scratch[2]
    k4 = scratch[3]
    probe = scratch[4]
    size = state.shape[0]
    derivative_into(state, inputs, k1)
    for i in range(size):
        probe[i] = state[i] + 0.5 * dt * k1[i]
    derivative_into(probe, inputs, k2)
    for i in range(size):
        probe[i] = state[i] + 0.5 * dt * k2[i]
    derivative_into(probe, inputs, k3)
    for i in range(size):
        probe[i] = state[i] + dt * k3[i]
    derivative_into(probe, inputs, k4)
    for i in range(size):
        state[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
