"""A controller's state inside a figure's full state q‖qd (shared by the DP and the simulator)."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def load_state(node_state, state_slot, base_state, q, qd):
    """Full figure state (q, qd) from the controller's state: base_state with the controlled
    slots (indices into the concatenation q‖qd) overwritten."""
    n = q.shape[0]
    for i in range(n):
        q[i] = base_state[i]
        qd[i] = base_state[n + i]
    for k in range(state_slot.shape[0]):
        slot = state_slot[k]
        if slot < n:
            q[slot] = node_state[k]
        else:
            qd[slot - n] = node_state[k]


@njit(cache=True)
def read_state(q, qd, state_slot, out):
    """The controller's state (d,) out of the full figure state."""
    n = q.shape[0]
    for k in range(state_slot.shape[0]):
        slot = state_slot[k]
        out[k] = q[slot] if slot < n else qd[slot - n]
