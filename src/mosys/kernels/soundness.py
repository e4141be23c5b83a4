"""Whether a figure's state is sound, and how a kernel that integrates it says it was not.

Kept apart from the simulators so that every kernel that checks a state (the DP's exit
transitions, the BSR and motor-program runs) can import the check without loading (or, on a cold
cache, compiling) a simulator it does not use.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# The largest |entry| of a state the integrators step from: beyond it (or NaN), the state has
# blown up, and the next step could overflow to inf and NaN.
STATE_LIMIT = 1e150


@njit(cache=True)
def state_is_sound(state):
    """True when every entry of ``state`` (S,) is finite and within ±STATE_LIMIT; the kernels
    that integrate check it before every step and after the last, and return
    ``blown_up(step)`` where it fails."""
    for i in range(state.shape[0]):  # noqa: SIM110 (a loop numba compiles, no generator)
        if not abs(state[i]) <= STATE_LIMIT:  # NaN fails too
            return False
    return True


@njit(cache=True)
def blown_up(step):
    """The return code of a kernel that found the state unsound (``state_is_sound``) before
    step ``step`` (0-based; the step count itself: after the last step), its records filled
    for the steps before it: -(step + 1) < 0. ``steps_before_blow_up`` inverts it."""
    return -(step + 1)


def steps_before_blow_up(code: int) -> int:
    """The steps a kernel took before the state became unsound, from its negative return code
    (``blown_up``)."""
    return -code - 1


def unsoundness(state: np.ndarray) -> str:
    """How a state (S,) SI that is not sound (``state_is_sound``) fails, as its error message
    says it: ``lies beyond ±1e+150 (SI)`` when every entry is finite, else ``became
    non-finite``."""
    return f"lies beyond ±{STATE_LIMIT:g} (SI)" if np.isfinite(state).all() else "became non-finite"
