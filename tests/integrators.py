"""Plain integrators the dynamics tests share: they drive a generated module's ``qdd_into``
with zero torques, compiled with numba (they take ``qdd_into`` as a first-class function)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit
def conservation_drift(qdd_into, energy, momentum, q, qd, dt, steps):
    """Classical RK4 on (q, qd) with tau = 0; returns the worst relative drift of energy, linear
    momentum and angular momentum over the run."""
    n = q.shape[0]
    tau = np.zeros(n)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    qs = np.empty(n)
    qds = np.empty(n)
    energy0 = energy(q, qd)
    momentum0 = momentum(q, qd)
    linear0 = math.hypot(momentum0[0], momentum0[1])
    worst = np.zeros(3)
    for _ in range(steps):
        qdd_into(q, qd, tau, k1)
        for i in range(n):
            qs[i] = q[i] + 0.5 * dt * qd[i]
            qds[i] = qd[i] + 0.5 * dt * k1[i]
        v2 = qds.copy()
        qdd_into(qs, qds, tau, k2)
        for i in range(n):
            qs[i] = q[i] + 0.5 * dt * v2[i]
            qds[i] = qd[i] + 0.5 * dt * k2[i]
        v3 = qds.copy()
        qdd_into(qs, qds, tau, k3)
        for i in range(n):
            qs[i] = q[i] + dt * v3[i]
            qds[i] = qd[i] + dt * k3[i]
        v4 = qds.copy()
        qdd_into(qs, qds, tau, k4)
        for i in range(n):
            q[i] += dt / 6.0 * (qd[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
            qd[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        now = momentum(q, qd)
        drift_linear = math.hypot(now[0] - momentum0[0], now[1] - momentum0[1]) / linear0
        drifts = (
            abs(energy(q, qd) - energy0) / abs(energy0),
            drift_linear,
            abs(now[2] - momentum0[2]) / abs(momentum0[2]),
        )
        for k in range(3):
            worst[k] = max(worst[k], drifts[k])
    return worst


@njit
def settle(qdd_into, q, qd, dt, steps):
    """Semi-implicit Euler with tau = 0 (contact springs are stiff: a small dt)."""
    n = q.shape[0]
    tau = np.zeros(n)
    acceleration = np.empty(n)
    for _ in range(steps):
        qdd_into(q, qd, tau, acceleration)
        for i in range(n):
            qd[i] += dt * acceleration[i]
            q[i] += dt * qd[i]
