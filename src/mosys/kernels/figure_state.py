"""A controller's state inside a model's full state vector (shared by the DP and the
simulator)."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def load_state(controller_state, state_slot, base_state, state):
    """The full state (S,) from a controller's state (d,): ``base_state`` (S,) with the slots the
    controller covers (``state_slot``, (d,) indices into the full state) overwritten."""
    for i in range(state.shape[0]):
        state[i] = base_state[i]
    for k in range(state_slot.shape[0]):
        state[state_slot[k]] = controller_state[k]


@njit(cache=True)
def read_state(state, state_slot, out):
    """The controller's state (d,) out of the full state (S,)."""
    for k in range(state_slot.shape[0]):
        out[k] = state[state_slot[k]]
