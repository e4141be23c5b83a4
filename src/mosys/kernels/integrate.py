"""Fixed-step RK4 over a generated dynamics module's ``qdd_into``.

The dynamics function arrives as a numba first-class function of type ``QDD_INTO`` (the generated
module declares ``qdd_into`` with exactly this signature), so the kernels that take it are compiled
once and cached across processes, whatever the figure.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types

VECTOR = types.float64[::1]
QDD_INTO = types.FunctionType(types.void(VECTOR, VECTOR, VECTOR, VECTOR))


@njit(cache=True)
def rk4_scratch(n):
    """Work array for ``rk4_step`` with n coordinates: (10, n) float64, C-contiguous."""
    return np.empty((10, n))


@njit(cache=True)
def rk4_step(qdd_into, q, qd, tau, dt, scratch):
    """Advance (q, qd) in place by one RK4 step of dt seconds, tau held constant.

    q, qd: (n,) SI (m or rad, m/s or rad/s); tau: (n,) generalized forces; scratch: from
    ``rk4_scratch(n)``.
    """
    n = q.shape[0]
    qa = scratch[0]
    va = scratch[1]
    k1q = scratch[2]
    k1v = scratch[3]
    k2q = scratch[4]
    k2v = scratch[5]
    k3q = scratch[6]
    k3v = scratch[7]
    k4q = scratch[8]
    k4v = scratch[9]
    for i in range(n):
        k1q[i] = qd[i]
    qdd_into(q, qd, tau, k1v)
    for i in range(n):
        qa[i] = q[i] + 0.5 * dt * k1q[i]
        va[i] = qd[i] + 0.5 * dt * k1v[i]
        k2q[i] = va[i]
    qdd_into(qa, va, tau, k2v)
    for i in range(n):
        qa[i] = q[i] + 0.5 * dt * k2q[i]
        va[i] = qd[i] + 0.5 * dt * k2v[i]
        k3q[i] = va[i]
    qdd_into(qa, va, tau, k3v)
    for i in range(n):
        qa[i] = q[i] + dt * k3q[i]
        va[i] = qd[i] + dt * k3v[i]
        k4q[i] = va[i]
    qdd_into(qa, va, tau, k4v)
    for i in range(n):
        q[i] += dt / 6.0 * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i])
        qd[i] += dt / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i])
