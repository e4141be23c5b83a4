"""How well a controller does its job: from a fixed set of start states, does it bring the figure
into its destination box, how soon, and (periodic controllers) does it come back again and again.

The destination box is the grid cells that share the destination node: within one grid step of
the destination on every axis the ``dest`` line names (axes it leaves free are unconstrained); wrap
axes are compared modulo their period. One step, not half a step, because at the paper's resolution
a stationary destination that needs a holding torque between two torque samples (A: 4.9 N·m
against samples 4 and 6) is held a fraction of a cell away from the node by the interpolated table.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from mosys.ssc.controller import CLOSED_LOOP_DT, Controller

#: The fixed start states of the quality test, (angle deg, omega deg/s): a 8 × 5 grid over the
#: pendulum's domain.
PENDULUM_STARTS = tuple(
    itertools.product(
        (-180.0, -135.0, -90.0, -45.0, 0.0, 45.0, 90.0, 135.0), (-400.0, -200.0, 0.0, 200.0, 400.0)
    )
)


def in_destination_box(controller: Controller, states: np.ndarray) -> np.ndarray:
    """(S,) bool: which controller states (S, d), spec units, lie in the destination box."""
    inside = np.ones(len(states), dtype=bool)
    for name, target in controller.table.dest.items():
        k = controller.state_order.index(name)
        axis = controller.table.axes[k]
        step = (axis[-1] - axis[0]) / (len(axis) - 1)
        difference = states[:, k] - target
        if controller.table.wrap[k]:
            period = step * len(axis)
            difference = (difference + period / 2) % period - period / 2
        inside &= np.abs(difference) <= step + 1e-9
    return inside


@dataclass(frozen=True)
class Arrivals:
    """Per start: first time in the destination box (s, nan if never) and how many separate
    times the path entered the box (a start inside the box counts as one entry)."""

    starts: np.ndarray  # (S, d) spec units
    first_arrival: np.ndarray  # (S,) s
    entries: np.ndarray  # (S,) int


def arrivals(
    controller: Controller, starts: np.ndarray, seconds: float, dt: float = CLOSED_LOOP_DT
) -> Arrivals:
    """Simulate every start (S, d) for ``seconds`` under ``controller`` and time its arrivals."""
    first = np.full(len(starts), np.nan)
    entries = np.zeros(len(starts), dtype=np.int64)
    for i, start in enumerate(starts):
        run = controller.simulate(controller.figure_state(start), seconds, dt)
        inside = in_destination_box(controller, controller.controller_states(run.states))
        if inside.any():
            first[i] = np.argmax(inside) * dt
        entries[i] = int(inside[0]) + int(np.count_nonzero(inside[1:] & ~inside[:-1]))
    return Arrivals(np.asarray(starts, dtype=np.float64), first, entries)
