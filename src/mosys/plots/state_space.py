"""State-space plots' axes and paths, shared by a controller's plots (``mosys.plots.controller``),
a script's (``mosys.plots.script``) and the free swing's (``mosys.plots.free_swing``).

State-space plots put the table's first state variable (the angle θ, deg) across and the second
(the rate ω, deg/s) up. A wrap axis is cylindrical, as in the paper: its left and right edges are
the same angle, and a path that crosses them leaves at one edge and comes back at the other.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from mosys.io.controller_table import ControllerTable
from mosys.plots.style import (
    SYMBOLS,
    PlotInputError,
    axis_label,
)

MAX_TICKED_SPAN = {"deg": 720.0, "deg/s": 1500.0}  # widest axes ticked every 60 deg, 100 deg/s


@dataclass(frozen=True)
class StateAxis:
    """One axis of a state-space plot: the state variable, its spec unit, the plotted range
    [low, high] (spec units) and its wrap period (None: not periodic)."""

    name: str
    unit: str
    low: float
    high: float
    period: float | None


# --------------------------------------------------------------------------- cylindrical paths


def _wrap_breaks(angle: np.ndarray, period: float) -> np.ndarray:
    """Indices i where |angle[i] - angle[i-1]| > period / 2."""
    return np.flatnonzero(np.abs(np.diff(angle)) > period / 2) + 1


def _slices(breaks, count: int) -> list[slice]:
    bounds = [0, *sorted(int(b) for b in breaks), count]
    return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]


def _unwrap_near(point: np.ndarray, reference: np.ndarray, axes: Sequence[StateAxis]):
    """``point`` shifted by whole periods along the wrap axes to lie nearest ``reference``."""
    shifted = np.array(point, dtype=np.float64)
    for k, axis in enumerate(axes):
        if axis.period:
            shifted[k] += axis.period * np.round((reference[k] - shifted[k]) / axis.period)
    return shifted


def cylinder_pieces(points: np.ndarray, axes: Sequence[StateAxis]) -> list[np.ndarray]:
    """Split a path (N, 2) at every wrap of a periodic axis into pieces (M_k, 2) to plot one by
    one. Each piece is extended by its neighbour sample, shifted by a period, so that it runs
    on to the plot's edge (where the axes clip it) instead of stopping one sample short."""
    points = np.asarray(points, dtype=np.float64)
    breaks: set[int] = set()
    for k, axis in enumerate(axes):
        if axis.period:
            breaks.update(_wrap_breaks(points[:, k], axis.period).tolist())
    pieces = []
    for piece in _slices(breaks, len(points)):
        rows = [points[piece]]
        if piece.start > 0:
            rows.insert(0, _unwrap_near(points[piece.start - 1], points[piece.start], axes)[None])
        if piece.stop < len(points):
            rows.append(_unwrap_near(points[piece.stop], points[piece.stop - 1], axes)[None])
        pieces.append(np.concatenate(rows))
    return pieces


def plot_state_path(
    ax: Axes, points: np.ndarray, axes: Sequence[StateAxis], **style: object
) -> None:
    """Plot a path on cylindrical axes; ``label`` (if any) goes on the first piece only."""
    for piece in cylinder_pieces(points, axes):
        ax.plot(piece[:, 0], piece[:, 1], **style)
        style.pop("label", None)


# --------------------------------------------------------------------------- axes and labels


def table_axes(table: ControllerTable, path: str | Path = "") -> tuple[StateAxis, StateAxis]:
    """The two plot axes of a 2-D controller table; PlotInputError for any other dimension."""
    if len(table.state_order) != 2:
        raise PlotInputError(
            f"{path}: a controller's portrait and torque map need a table of 2 state "
            f"dimensions (a coordinate and its rate), this one has {len(table.state_order)}: "
            f"{', '.join(table.state_order)}" + car_hint(table.state_order, table.figure)
        )
    return state_axes(table)


def car_hint(state_order: Sequence[str], figure: str = "") -> str:
    """What to add to a refusal of a car's table or trajectory (named by ``figure`` or known by
    its heading and steer axes): the verb that draws it; "" for any other."""
    if figure == "car" or {"heading", "steer"} <= set(state_order):
        return " (a car's runs are drawn by mosys plot car)"
    return ""


def state_axes(table: ControllerTable) -> tuple[StateAxis, ...]:
    """A plot axis for each of the table's state variables, in its state order: the range of
    its nodes, or one period for a wrap axis."""
    axes = []
    for name, grid, unit, wrap in zip(
        table.state_order, table.axes, table.axis_units, table.wrap, strict=True
    ):
        if wrap:
            period = len(grid) * (grid[-1] - grid[0]) / (len(grid) - 1)
            axes.append(StateAxis(name, unit, float(grid[0]), float(grid[0] + period), period))
        else:
            axes.append(StateAxis(name, unit, float(grid[0]), float(grid[-1]), None))
    return tuple(axes)


def format_state_axes(
    ax: Axes, axes: Sequence[StateAxis], data: np.ndarray | None = None
) -> list[tuple[object, str]]:
    """Limits, labels and ticks of a state-space plot. A periodic axis spans exactly one period;
    a non-periodic one its range (widened to ``data`` (N, 2) if that strays outside, the
    range's edges then dashed) plus a 2 % margin so that lines along the edge stay visible.
    Returns the legend entry of the dashed edges (none if none is drawn)."""
    edge_style = {"color": "0.4", "linestyle": "--", "linewidth": 0.8}
    widened = []
    for k, (axis, limits, ticker) in enumerate(
        zip(axes, (ax.set_xlim, ax.set_ylim), (ax.xaxis, ax.yaxis), strict=True)
    ):
        low, high = axis.low, axis.high
        if not axis.period:
            if data is not None and len(data):
                low, high = min(low, float(data[:, k].min())), max(high, float(data[:, k].max()))
                if (low, high) != (axis.low, axis.high):
                    widened.append(axis.name)
                    line = ax.axvline if k == 0 else ax.axhline
                    for edge in (axis.low, axis.high):
                        line(edge, zorder=2, **edge_style)
            margin = 0.02 * (high - low)
            low, high = low - margin, high + margin
        limits(low, high)
        # the paper's ticks where they make a dozen or so; wider ranges (a backflip's 3,000
        # deg/s) keep matplotlib's, which choose their own step
        if axis.unit == "deg" and high - low <= MAX_TICKED_SPAN["deg"]:
            ticker.set_major_locator(MultipleLocator(60.0 if high - low > 200 else 30.0))
        elif axis.unit == "deg/s" and 500 <= high - low <= MAX_TICKED_SPAN["deg/s"]:
            ticker.set_major_locator(MultipleLocator(100.0))
    labels = [axis_label(a.name, a.unit) + (" — cylindrical" if a.period else "") for a in axes]
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    if not widened:
        return []
    names = " and ".join(SYMBOLS.get(name, name) for name in widened)
    return [
        (Line2D([], [], **edge_style), f"ends of the table's {names} range (the path leaves it)")
    ]


def destination_point(
    table: ControllerTable, axes: Sequence[StateAxis], destination: dict | None = None
) -> list[float | None]:
    """The destination's coordinate along each plot axis (None: the destination leaves that
    state variable free), wrapped into the plotted range. ``destination``: one of the table's
    destinations ({name: value}, spec units); None: its ``dest`` (the first)."""
    destination = table.dest if destination is None else destination
    point: list[float | None] = []
    for axis in axes:
        value = destination.get(axis.name)
        if value is not None and axis.period:
            value = axis.low + (value - axis.low) % axis.period
        point.append(None if value is None else float(value))
    return point
