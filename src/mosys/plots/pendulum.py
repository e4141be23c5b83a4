"""The pendulum plots of the 1990 paper (§5.2), regenerated: ``mosys plot KIND INPUTS -o OUT``.

- ``portrait``: state-space paths under one controller from a spread of start states (Figure 14);
  for a table with several destinations, each destination's basin (the nodes whose
  ``/destination_index`` names it) is tinted behind the paths.
- ``torque``: a controller's torque table as a heat map, with cost-to-go contours.
- ``script``: an animation script's path through state space, controller by controller (Figure 16).
- ``gif``: the pendulum swinging through a script, drawn from the trajectory's ``figure_motion``.

State-space plots put the table's first state variable (the angle θ, deg) across and the second
(the rate ω, deg/s) up. A wrap axis is cylindrical, as in the paper: its left and right edges are
the same angle, and a path that crosses them leaves at one edge and comes back at the other.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import matplotlib
import numpy as np
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import MultipleLocator
from matplotlib.transforms import Bbox
from matplotlib.typing import ColorType

from mosys.io.attributes import string_tuple
from mosys.io.controller_table import ControllerTable, read_controller_table
from mosys.io.trajectory import Trajectory, read_trajectory
from mosys.plots.style import (
    DESTINATION_COLOR,
    GIF_DPI,
    GIF_FPS,
    MARGIN_TOP,
    SYMBOLS,
    TITLE_LINE,
    PlotInputError,
    add_legend,
    animation_frames,
    axis_label,
    controller_colors,
    counted,
    destination_handle,
    mark_destination,
    mark_start,
    new_figure,
    plot_style,
    save_figure,
    start_style,
    write_gif,
)

PORTRAIT_STARTS = 8  # start states per portrait
PORTRAIT_SECONDS = 3.0  # s simulated from each start
UNKNOWN_COLOR = "0.55"  # a node without a cost-to-go on the torque map
MAX_TICKED_SPAN = {"deg": 720.0, "deg/s": 1500.0}  # widest axes ticked every 60 deg, 100 deg/s
LABEL_GAP_INCHES = 0.45  # contour labels at least this far apart and from the destination
CYCLE_SECONDS = (3.0, 5.0)  # s: a periodic destination's cycle is drawn over this window
# pale tints of the basins of a table with several destinations, one per destination in order
# (ColorBrewer's Paired, light members), drawn at BASIN_ALPHA behind the paths
BASIN_COLORS = ("#a6cee3", "#fdbf6f", "#b2df8a", "#cab2d6", "#fb9a99", "#ffff99")
BASIN_ALPHA = 0.45


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
            f"{path}: a pendulum plot needs a 2-D controller table, this one has state "
            f"{', '.join(table.state_order)}" + _car_hint(table.state_order, table.figure)
        )
    return state_axes(table)


def _car_hint(state_order: Sequence[str], figure: str = "") -> str:
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


def phase_planes(axes: Sequence[StateAxis]) -> list[tuple[int, int]]:
    """The pairs of state columns (x, y) a state-space path is drawn in: a 2-D state's one
    plane; for a state of 2k variables whose last k are the rates of the first k (unit + "/s",
    the dynamics' order q, q̇: a double pendulum's shoulder, elbow, shoulder_rate, elbow_rate),
    each coordinate against its rate. PlotInputError for any other state."""
    count = len(axes)
    if count == 2:
        return [(0, 1)]
    half = count // 2
    rates = all(axes[i + half].unit == f"{axes[i].unit}/s" for i in range(half))
    if count and count % 2 == 0 and rates:
        return [(i, i + half) for i in range(half)]
    names = [axis.name for axis in axes]
    raise PlotInputError(
        "a state-space path is drawn for a 2-D state, or for coordinates followed by their "
        f"rates (units U then U/s); this state is {', '.join(names)} in "
        f"{', '.join(axis.unit or '(no unit)' for axis in axes)}" + _car_hint(names)
    )


def trajectory_axes(trajectory: Trajectory) -> tuple[StateAxis, ...]:
    """Plot axes for a trajectory read without its controller tables, by the columns' units
    (a file without them: a 2-D state read as an angle in deg and its rate in deg/s): an angle
    (deg) is periodic over 360 (the range of the data: [-180, 180) or [0, 360)); a rate in
    deg/s spans at least [-500, 500] (the paper's scale); any other column its data."""
    state, names = trajectory.state, trajectory.state_order
    units = trajectory.state_units
    if units is None:
        if state.ndim != 2 or state.shape[1] != 2:
            raise PlotInputError(f"a pendulum plot needs a 2-D state, got {trajectory.state_order}")
        units = ("deg", "deg/s")
    axes = []
    for name, unit, column in zip(names, units, state.T, strict=True):
        if unit == "deg":
            low = -180.0 if column.min() >= -180.0 and column.max() < 180.0 else 0.0
            axes.append(StateAxis(name, unit, low, low + 360.0, 360.0))
        elif unit == "deg/s":
            reach = max(500.0, float(np.abs(column).max()) * 1.05)
            axes.append(StateAxis(name, unit, -reach, reach, None))
        else:
            low, high = float(column.min()), float(column.max())
            if high - low < 1e-9:
                low, high = low - 1.0, high + 1.0
            axes.append(StateAxis(name, unit, low, high, None))
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


def _format_value(value: float) -> str:
    return f"{value:g}"


def describe_state(values: dict[str, float], units: dict[str, str]) -> str:
    """``θ = 120 deg, ω = 0 deg/s`` for a dict of named state values (spec units)."""
    return ", ".join(
        f"{SYMBOLS.get(name, name)} = {_format_value(value)} {units.get(name, '')}".rstrip()
        for name, value in values.items()
    )


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


def _mark_table_destination(
    ax: Axes, table: ControllerTable, axes, color=DESTINATION_COLOR, destination=None
):
    """Mark the destination (a line if it leaves one plotted variable free); returns its legend
    handle, or None if it names neither plotted variable. ``destination``: as in
    ``destination_point``."""
    x, y = destination_point(table, axes, destination)
    if x is not None and y is not None:
        mark_destination(ax, x, y, color=color)
        return destination_handle(color)
    if x is None and y is None:
        return None
    line = ax.axvline(x) if x is not None else ax.axhline(y)
    line.set(color=color, linestyle="--", linewidth=1.4, zorder=5)
    return line


def _mark_table_destinations(ax: Axes, table: ControllerTable, axes) -> list:
    """Mark every destination of the table (``_mark_table_destination``); the legend entry
    (none if no destination names a plotted variable)."""
    handle = None
    for destination in table.all_destinations:
        handle = _mark_table_destination(ax, table, axes, destination=destination) or handle
    if handle is None:
        return []
    return [(handle, "destination" + ("s" if len(table.all_destinations) > 1 else ""))]


def _destinations_heading(table: ControllerTable) -> str:
    """The title's words for the table's destination, or how many it has."""
    if len(table.all_destinations) == 1:
        units = dict(zip(table.state_order, table.axis_units, strict=True))
        return f"destination {describe_state(table.dest, units)}"
    return f"{len(table.all_destinations)} destinations, the cheapest from each state"


def _destination_is_periodic(table: ControllerTable, destination: dict | None = None) -> bool:
    """A destination with a non-zero rate is passed through, not held: a periodic motion.
    ``destination``: as in ``destination_point``."""
    destination = table.dest if destination is None else destination
    units = dict(zip(table.state_order, table.axis_units, strict=True))
    return any(units.get(name, "").endswith("/s") and value for name, value in destination.items())


def _node_edges(grid: np.ndarray, axis: StateAxis) -> np.ndarray:
    """The edges of the cells centred on the nodes of ``grid`` (n,), halfway between nodes;
    on a periodic axis one more cell, the first node's a period on, so that the cells cover
    the plotted period."""
    step = (grid[-1] - grid[0]) / (len(grid) - 1)
    count = len(grid) + (1 if axis.period else 0)
    return grid[0] - step / 2 + step * np.arange(count + 1)


def draw_basins(
    ax: Axes, table: ControllerTable, axes: Sequence[StateAxis], units: dict[str, str]
) -> list[tuple[Patch, str]]:
    """Tint each node's cell with its destination's colour (``BASIN_COLORS``, from the
    table's ``/destination_index``; nodes with -1 stay clear) behind everything else; returns
    a legend entry per destination, ``basin → θ = 90 deg, ω = 0 deg/s``."""
    index = np.asarray(table.destination_index)
    destinations = table.all_destinations
    colors = [BASIN_COLORS[k % len(BASIN_COLORS)] for k in range(len(destinations))]
    shown = np.ma.masked_less(index.astype(np.float64), 0.0)
    if axes[0].period:
        shown = np.ma.concatenate([shown, shown[:1]], axis=0)
    if axes[1].period:
        shown = np.ma.concatenate([shown, shown[:, :1]], axis=1)
    ax.pcolormesh(
        _node_edges(table.axes[0], axes[0]),
        _node_edges(table.axes[1], axes[1]),
        shown.T,
        cmap=ListedColormap(colors),
        vmin=-0.5,
        vmax=len(destinations) - 0.5,
        alpha=BASIN_ALPHA,
        shading="flat",
        linewidth=0,
        zorder=0,
    )
    return [
        (
            Patch(facecolor=color, alpha=BASIN_ALPHA, edgecolor="0.55", linewidth=0.6),
            f"basin → {describe_state(destination, units)}",
        )
        for color, destination in zip(colors, destinations, strict=True)
    ]


def _halton(index: int, base: int) -> float:
    fraction, result = 1.0, 0.0
    while index > 0:
        fraction /= base
        result += fraction * (index % base)
        index //= base
    return result


def portrait_starts(axes: Sequence[StateAxis], count: int = PORTRAIT_STARTS) -> np.ndarray:
    """``count`` start states (count, 2), spec units, spread evenly and deterministically over
    the plot: the Halton sequence in bases 2 and 3, kept 10 % inside the non-periodic edges."""
    starts = np.empty((count, 2))
    for i in range(count):
        for k, (axis, base) in enumerate(zip(axes, (2, 3), strict=True)):
            fraction = _halton(i + 1, base)
            if not axis.period:
                fraction = 0.1 + 0.8 * fraction
            starts[i, k] = axis.low + fraction * (axis.high - axis.low)
    return starts


# --------------------------------------------------------------------------- the four plots


def plot_portrait(
    table_path: str | Path,
    dynamics: ModuleType,
    out_path: str | Path,
    seconds: float = PORTRAIT_SECONDS,
    starts: int = PORTRAIT_STARTS,
) -> None:
    """Write ``portrait_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(portrait_figure(table_path, dynamics, seconds, starts), out_path)


def portrait_figure(
    table_path: str | Path,
    dynamics: ModuleType,
    seconds: float = PORTRAIT_SECONDS,
    starts: int = PORTRAIT_STARTS,
) -> Figure:
    """Figure 14: closed-loop paths in state space under the controller in ``table_path``, from
    ``starts`` start states (small squares) for ``seconds`` each, to the destination (encircled
    X). A periodic destination's cycle (the path from the destination itself, between
    ``CYCLE_SECONDS``) is drawn as a thick grey line. A table with several destinations has
    every one marked and each one's basin tinted (``draw_basins``), the legend naming them."""
    from mosys.ssc.controller import CLOSED_LOOP_DT, Controller

    controller = Controller.load(table_path, dynamics)
    table = controller.table
    axes = table_axes(table, table_path)
    dt = CLOSED_LOOP_DT
    units = dict(zip(table.state_order, table.axis_units, strict=True))
    palette = matplotlib.colormaps["tab10"]
    destinations = table.all_destinations
    with plot_style():
        figure = new_figure(7.0, 5.8)
        ax = figure.add_subplot()
        legend = []
        drawn = []
        periodic = [d for d in destinations if _destination_is_periodic(table, d)]
        for destination in periodic:
            dest_state = np.array([destination.get(name, 0.0) for name in table.state_order])
            first, last = (int(round(s / dt)) for s in CYCLE_SECONDS)
            run = controller.simulate(controller.figure_state(dest_state), last * dt, dt)
            cycle = controller.controller_states(run.states[first:])
            cycle_style = {"color": "0.45", "linewidth": 5.0, "alpha": 0.5}
            plot_state_path(ax, cycle, axes, zorder=1, solid_capstyle="round", **cycle_style)
            drawn.append(cycle)
        if periodic:
            label = "cycle through the destination" + ("s" if len(periodic) > 1 else "")
            legend.append((Line2D([], [], **cycle_style), label))
        for k, start in enumerate(portrait_starts(axes, starts)):
            run = controller.simulate(controller.figure_state(start), seconds, dt)
            path = controller.controller_states(run.states)
            color = palette(k % palette.N)
            plot_state_path(ax, path, axes, color=color, linewidth=1.3, zorder=3)
            mark_start(ax, start[0], start[1], color)
            drawn.append(path)
        legend.append((Line2D([], [], **start_style("white")), "start state (one colour per path)"))
        legend.extend(_mark_table_destinations(ax, table, axes))
        legend += format_state_axes(ax, axes, np.concatenate(drawn))
        ax.set_title(
            f"Controller {controller.name}: {_destinations_heading(table)}\n"
            f"closed-loop paths, {seconds:g} s from each of {starts} start states"
        )
        if table.destination_index is not None:
            legend.extend(draw_basins(ax, table, axes, units))
            add_legend(figure, legend, ncols=2)
        else:
            add_legend(figure, legend)
    return figure


def plot_torque(table_path: str | Path, out_path: str | Path, contours: bool = True) -> None:
    """Write ``torque_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(torque_figure(table_path, contours), out_path)


def torque_figure(table_path: str | Path, contours: bool = True) -> Figure:
    """A controller's torque table as a heat map over its two state variables: one cell per
    table node (the value the DP stored there; between nodes the controller interpolates),
    a diverging colour scale centred on 0 N·m, the destination marked, and the cost-to-go as
    labelled contour lines (s). One panel per control."""
    table = read_controller_table(table_path)
    axes = table_axes(table, table_path)
    name = Path(table_path).stem
    centres = []
    for axis, grid in zip(axes, table.axes, strict=True):
        # a periodic axis repeats its first node at the far edge, so the plot closes up
        centres.append(np.append(grid, grid[0] + axis.period) if axis.period else grid)
    torque, value = table.torque, table.value
    if axes[0].period:
        torque = np.concatenate([torque, torque[:1]], axis=0)
        value = np.concatenate([value, value[:1]], axis=0)
    if axes[1].period:
        torque = np.concatenate([torque, torque[:, :1]], axis=1)
        value = np.concatenate([value, value[:, :1]], axis=1)
    edges = [_cell_edges(c) for c in centres]
    finite = np.isfinite(value)
    halo = [patheffects.withStroke(linewidth=2.4, foreground="white")]
    controls = len(table.control_names)
    with plot_style():
        figure = new_figure(7.0 * controls, 5.8)
        legend = []
        for c, control in enumerate(table.control_names):
            ax = figure.add_subplot(1, controls, c + 1)
            reach = float(max(abs(table.control_min[c]), abs(table.control_max[c]), 1e-12))
            mesh = ax.pcolormesh(
                edges[0],
                edges[1],
                torque[..., c].T,
                cmap="RdBu_r",
                vmin=-reach,
                vmax=reach,
                shading="flat",
                rasterized=True,
                zorder=0,
            )
            ax.grid(False)
            colorbar = figure.colorbar(mesh, ax=ax, pad=0.02)
            colorbar.set_label(f"{control} (N·m)")
            legend = []
            format_state_axes(ax, axes)  # the limits first: the contour labels' spacing needs them
            if not finite.all():  # drawn white, they read as 0 N·m
                ax.pcolormesh(
                    edges[0],
                    edges[1],
                    np.ma.masked_where(finite, np.zeros(value.shape)).T,
                    cmap=ListedColormap([UNKNOWN_COLOR]),
                    shading="flat",
                    rasterized=True,
                    zorder=0.5,
                )
                count = int(np.sum(~np.isfinite(table.value)))
                legend.append(
                    (
                        Patch(facecolor=UNKNOWN_COLOR),
                        f"no cost-to-go ({counted(count, 'unreachable node')})",
                    )
                )
            if contours and finite.sum() > 3 and np.ptp(value[finite]) > 0:
                lines = ax.contour(
                    centres[0],
                    centres[1],
                    np.ma.masked_invalid(value).T,
                    levels=_contour_levels(value[finite]),
                    colors="black",
                    linewidths=0.9,
                    zorder=2,
                )
                lines.set(path_effects=halo)
                labels = ax.clabel(lines, fmt=lambda v: f"{v:g} s", fontsize=8, inline=False)
                for text in labels:
                    text.set(path_effects=halo)
                _thin_labels(ax, labels, _destination_points(table, axes))
                legend.append(
                    (
                        Line2D([], [], color="black", linewidth=0.9),
                        "cost-to-go, contours labelled in s",
                    )
                )
            legend.extend(_mark_table_destinations(ax, table, axes))
            ax.set_title(
                f"Controller {name}: {control} table, "
                f"{' × '.join(str(len(g)) for g in table.axes)} nodes\n"
                f"{_destinations_heading(table)}"
            )
        add_legend(figure, legend)
    return figure


def _cell_edges(centres: np.ndarray) -> np.ndarray:
    """Edges of cells centred on uniformly spaced nodes."""
    step = (centres[-1] - centres[0]) / (len(centres) - 1) if len(centres) > 1 else 1.0
    return np.append(centres - step / 2, centres[-1] + step / 2)


def _destination_points(table: ControllerTable, axes) -> list[tuple[float, float]]:
    """Where the table's destinations are marked (those naming both plotted variables)."""
    points = [destination_point(table, axes, d) for d in table.all_destinations]
    return [(x, y) for x, y in points if x is not None and y is not None]


def _thin_labels(ax: Axes, labels: list, clear: list, gap: float = LABEL_GAP_INCHES) -> None:
    """Remove each contour label that lies within ``gap`` inches of a label kept before it or
    of a point of ``clear`` (data units; the destination's mark): where contours converge on
    the destination their labels piled on each other and on the mark."""
    size = ax.get_position().size * ax.figure.get_size_inches()
    kept = [ax.transLimits.transform(point) * size for point in clear]
    for text in labels:
        here = ax.transLimits.transform(text.get_position()) * size
        if any(np.hypot(*(here - other)) < gap for other in kept):
            text.remove()
        else:
            kept.append(here)


def _contour_levels(values: np.ndarray) -> np.ndarray:
    """Six to a dozen round contour levels (steps of 1, 2, 2.5 or 5 times a power of ten)
    strictly inside the range (0, max] of the finite cost-to-go."""
    top = float(values.max())
    raw = top / 6
    magnitude = 10 ** math.floor(math.log10(raw))
    step = max(m * magnitude for m in (1, 2, 2.5, 5) if m * magnitude <= raw)
    return np.arange(step, top, step)


def _switches(trajectory: Trajectory) -> list[tuple[int, str]]:
    """(sample index, controller name) at each controller invocation: from the root attrs
    ``switch_times``/``switch_controllers`` when present, else wherever ``/controller``
    changes."""
    attrs = trajectory.attrs
    if "switch_times" in attrs and "switch_controllers" in attrs:
        times = np.atleast_1d(np.asarray(attrs["switch_times"], dtype=np.float64))
        names = string_tuple(attrs["switch_controllers"])
        index = np.searchsorted(trajectory.t, times - 1e-9)
        last = len(trajectory.t) - 1
        return [(min(int(i), last), n) for i, n in zip(index, names, strict=True)]
    changes = np.flatnonzero(np.diff(trajectory.controller)) + 1
    starts = [0, *changes.tolist()] if len(trajectory.t) else []
    return [(i, trajectory.controllers[trajectory.controller[i]]) for i in starts]


def _controller_runs(trajectory: Trajectory) -> list[tuple[int, int, str]]:
    """(first sample, last sample + 1, controller name) of each stretch under one controller;
    each stretch also takes the next stretch's first sample, so the drawn path is unbroken."""
    index = trajectory.controller
    bounds = [0, *(np.flatnonzero(np.diff(index)) + 1).tolist(), len(index)]
    return [
        (a, min(b + 1, len(index)), trajectory.controllers[index[a]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True)
        if b > a
    ]


LABEL_OFFSETS = ((6, 6), (6, -16), (-26, 6), (-26, -16), (10, -5), (-30, -5), (-9, 10), (-9, -22))
"""Candidate places (points from the anchor) of a point label, in order of preference."""


def place_labels(
    figure: Figure,
    ax: Axes,
    labels: Sequence[tuple[float, float, str, ColorType]],
    obstacles: Sequence[tuple[float, float, float]],
) -> None:
    """Annotate points without letting labels overlap each other or the markers: each label,
    in turn, takes the first of ``LABEL_OFFSETS`` whose text box meets nothing already placed
    and stays inside the axes (else the one with the least overlap). ``labels``: (x, y, text,
    color) in data units; ``obstacles``: (x, y, radius in points) of markers to keep clear."""
    figure.draw_without_rendering()  # fixes the layout, hence the data-to-pixel transform
    renderer = figure.canvas.get_renderer()
    pixels_per_point = figure.dpi / 72.0
    inside = ax.get_window_extent(renderer)
    taken = []
    for x, y, radius in obstacles:
        centre = ax.transData.transform((x, y))
        r = radius * pixels_per_point
        taken.append(Bbox.from_extents(*(centre - r), *(centre + r)))
    box_style = {
        "boxstyle": "round,pad=0.12",
        "facecolor": "white",
        "alpha": 0.8,
        "edgecolor": "none",
    }
    for x, y, text, color in labels:
        best = None
        for offset in LABEL_OFFSETS:
            note = ax.annotate(
                text,
                (x, y),
                xytext=offset,
                textcoords="offset points",
                fontsize=9.5,
                fontweight="bold",
                color=color,
                bbox=box_style,
                zorder=7,
                annotation_clip=False,
            )
            note.set_in_layout(False)
            box = note.get_window_extent(renderer).expanded(1.1, 1.15)
            clash = sum(_overlap(box, other) for other in taken)
            clash += box.width * box.height - _overlap(box, inside)  # the part outside the axes
            if best is None or clash < best[0]:
                if best is not None:
                    best[1].remove()
                best = (clash, note, box)
            else:
                note.remove()
            if clash == 0:
                break
        taken.append(best[2])


def _overlap(a: Bbox, b: Bbox) -> float:
    width = min(a.x1, b.x1) - max(a.x0, b.x0)
    height = min(a.y1, b.y1) - max(a.y0, b.y0)
    return max(width, 0.0) * max(height, 0.0)


def plot_script(
    trajectory_path: str | Path,
    table_paths: Sequence[str | Path],
    out_path: str | Path,
) -> None:
    """Write ``script_path_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(script_path_figure(trajectory_path, table_paths), out_path)


def script_path_figure(trajectory_path: str | Path, table_paths: Sequence[str | Path]) -> Figure:
    """Figure 16: an animation script's path in state space, each controller's stretch in its
    own colour; ``sX`` marks where controller X is invoked (a motor program's start is marked
    with its name) and ``dX`` its destination (read
    from the controller tables in ``table_paths``, matched to the script's controllers by file
    stem; without them no destinations are drawn, and the axes come from the trajectory: see
    ``trajectory_axes``; tables of which none drives the script are refused). A state of
    coordinates and their rates (a double pendulum's) is drawn one panel per coordinate, against
    its rate (``phase_planes``)."""
    trajectory = read_trajectory(trajectory_path)
    if len(trajectory.t) == 0:
        raise PlotInputError(f"{trajectory_path}: the trajectory has no samples")
    paths = {Path(p).stem: p for p in table_paths}
    tables = {name: read_controller_table(path) for name, path in paths.items()}
    used = [n for n in dict.fromkeys(trajectory.controllers) if n in tables]
    if tables and not used:  # a mistake: they would draw no destination, and say nothing
        raise PlotInputError(
            f"{trajectory_path}: none of the tables given ({', '.join(tables)}) is one of the "
            f"script's controllers ({', '.join(dict.fromkeys(trajectory.controllers))})"
        )
    axes, where = trajectory_plot_axes(trajectory, trajectory_path, tables, used, paths)
    try:
        planes = phase_planes(axes)
    except PlotInputError as error:
        raise PlotInputError(f"{where}: {error}") from None
    state = trajectory.state.copy()
    for k, axis in enumerate(axes):  # a motor program's stretch keeps the angle unwrapped
        if axis.period:
            state[:, k] = axis.low + np.mod(state[:, k] - axis.low, axis.period)
    drawing = _ScriptDrawing(
        trajectory,
        controller_colors(trajectory.controllers),
        _source_kinds(trajectory),
        _switches(trajectory),
        [tables[name] for name in used],
        used,
    )
    script = str(trajectory.attrs.get("script", Path(trajectory_path).name))
    programs = sum(name in drawing.motor for _, name in drawing.switches)
    invoked = counted(len(drawing.switches) - programs, "controller invocation")
    if programs:
        invoked += f" and {counted(programs, 'motor program')}"
    title = (
        f"State-space path of the animation script {Path(script).name}\n"
        f"{invoked} over {trajectory.t[-1] - trajectory.t[0]:.2f} s"
    )
    columns = min(len(planes), 2)
    rows = -(-len(planes) // columns)
    with plot_style():
        figure = new_figure(7.6 if columns == 1 else 6.4 * columns, 1.0 + 5.4 * rows)
        legend: dict[str, object] = {}
        panels = []
        for panel, (x, y) in enumerate(planes):
            ax = figure.add_subplot(rows, columns, panel + 1)
            entries, labels, obstacles = drawing.panel(ax, state[:, [x, y]], (axes[x], axes[y]))
            for handle, label in entries:
                legend.setdefault(label, handle)
            panels.append((ax, labels, obstacles))
        end = legend.pop(END_LABEL.format(trajectory.t[-1]))  # the end last
        legend[END_LABEL.format(trajectory.t[-1])] = end
        if len(planes) == 1:
            panels[0][0].set_title(title)
        entries = [(handle, label) for label, handle in legend.items()]
        add_legend(figure, entries, ncols=3 if len(entries) > 4 else 4)
        if len(planes) > 1:  # one title over the panels, below the figure's top edge
            height = figure.get_size_inches()[1]
            figure.suptitle(title, y=1 - MARGIN_TOP / height, va="top")
            figure.subplots_adjust(top=1 - (MARGIN_TOP + 3 * TITLE_LINE) / height, wspace=0.25)
        for ax, labels, obstacles in panels:
            place_labels(figure, ax, labels, obstacles)
    return figure


def trajectory_plot_axes(
    trajectory: Trajectory,
    trajectory_path: str | Path,
    tables: dict[str, ControllerTable],
    used: Sequence[str],
    paths: dict[str, str | Path],
) -> tuple[tuple[StateAxis, ...], str | Path]:
    """The plot axes of a script's state, and the file they come from: its first controller's
    table's, where the trajectory's state is that table's; the trajectory's own
    (``trajectory_axes``) where it has no table, or where it is the figure's whole state of which
    the table covers some variables (a script with motor programs: Luxo's landing table covers
    four of his ten). Any other state order is refused."""
    if not used:
        try:
            return trajectory_axes(trajectory), trajectory_path
        except PlotInputError as error:
            raise PlotInputError(f"{trajectory_path}: {error}") from None
    table_axes = state_axes(tables[used[0]])
    names = tuple(axis.name for axis in table_axes)
    if names == tuple(trajectory.state_order):
        return table_axes, paths[used[0]]
    if set(names) <= set(trajectory.state_order) and trajectory.state_units is not None:
        return trajectory_axes(trajectory), trajectory_path
    raise PlotInputError(
        f"{trajectory_path}: state order {trajectory.state_order} differs from that of its "
        f"controller {used[0]}, {names}"
    )


END_LABEL = "end, t = {:.2f} s"
END_STYLE = {"marker": "o", "markersize": 5, "color": "black", "markeredgecolor": "white"}


@dataclass(frozen=True)
class _ScriptDrawing:
    """What every panel of a script's path figure shares: the trajectory, each controller's
    colour and kind, the invocations (sample index, name) and the tables that drive it."""

    trajectory: Trajectory
    colors: dict
    kinds: dict
    switches: list[tuple[int, str]]
    tables: list[ControllerTable]
    used: list[str]

    @property
    def motor(self) -> set[str]:
        return {name for name, kind in self.kinds.items() if kind == "motor program"}

    def panel(self, ax: Axes, state: np.ndarray, axes: tuple[StateAxis, StateAxis]):
        """Draw the path in one plane: ``state`` (N, 2) the two columns in spec units, wrapped
        into ``axes``. Returns its legend entries, point labels and markers to keep clear."""
        trajectory, colors, motor = self.trajectory, self.colors, self.motor
        for first, stop, name in _controller_runs(trajectory):
            plot_state_path(
                ax, state[first:stop], axes, color=colors[name], linewidth=1.8, zorder=3
            )
        legend = [
            (Line2D([], [], color=colors[name], linewidth=2), f"{self.kinds[name]} {name}")
            for name in dict.fromkeys(trajectory.controllers)
        ]
        labels, obstacles = [], []
        for i, name in self.switches:
            mark_start(ax, state[i, 0], state[i, 1], colors[name], zorder=6.5)  # over dX
            label = name if name in motor else f"s{name}"  # 'sswing' read as a typo
            labels.append((state[i, 0], state[i, 1], label, colors[name]))
            obstacles.append((state[i, 0], state[i, 1], 4.0))
        started = "sX: controller X invoked"
        if motor:
            started += "; P: motor program P started"
        legend.append((Line2D([], [], **start_style("white")), started))
        for name, table in zip(self.used, self.tables, strict=True):
            x, y = destination_point(table, axes)
            if x is None or y is None:
                continue
            mark_destination(ax, x, y, color=colors[name])
            labels.append((x, y, f"d{name}", colors[name]))
            obstacles.append((x, y, 7.0))
        if self.used:
            legend.append((destination_handle(), "dX: destination of controller X"))
        legend += format_state_axes(ax, axes, state)
        legend += _shade_breakpoints(ax, trajectory, axes, colors)
        ax.plot(state[-1, 0], state[-1, 1], zorder=7, **END_STYLE)  # over an sX square there
        obstacles.append((state[-1, 0], state[-1, 1], 3.0))
        end = Line2D([], [], linestyle="none", **END_STYLE)
        legend.append((end, END_LABEL.format(trajectory.t[-1])))
        return legend, labels, obstacles


def _source_kinds(trajectory: Trajectory) -> dict[str, str]:
    """What drives the figure in each of the trajectory's stretches, by name: "controller" or
    "motor program" (root attr ``controller_kinds``; a file without it: controllers)."""
    kinds = string_tuple(trajectory.attrs.get("controller_kinds", ()))
    found = dict(zip(trajectory.controllers, kinds, strict=False))
    return {
        name: found.get(name, "controller").replace("motor", "motor program")
        for name in trajectory.controllers
    }


def _shade_breakpoints(
    ax: Axes, trajectory: Trajectory, axes: Sequence[StateAxis], colors: dict
) -> list[tuple[object, str]]:
    """Shade each state-space breakpoint's box (the trajectory's root attr ``breakpoints``) in
    its controller's colour, clipped to the plot's limits (set before this is called): bounds
    on variables other than the plot's two, and open bounds, span the plot. Returns the legend
    entries."""
    entries = []
    # Clipped here, not by Agg: a dashed edge is dashed along its whole length before clipping,
    # and an edge a million plot-widths long took 16 s to draw.
    view = (ax.get_xlim(), ax.get_ylim())
    for breakpoint_ in json.loads(str(trajectory.attrs.get("breakpoints", "[]"))):
        box = breakpoint_["box"]
        color = colors.get(breakpoint_["controller"], "0.5")
        limits = []
        for axis, (view_low, view_high) in zip(axes, view, strict=True):
            low, high = box.get(axis.name, (-math.inf, math.inf))
            limits.append((max(low, view_low), min(high, view_high)))
        (x0, x1), (y0, y1) = limits
        patch = Rectangle(
            (x0, y0),
            x1 - x0,
            y1 - y0,
            facecolor=color,
            alpha=0.18,
            edgecolor=color,
            linestyle="--",
            linewidth=1.0,
            zorder=1,
        )
        ax.add_patch(patch)
        bounds = ", ".join(f"{low:g} < {name} < {high:g}" for name, (low, high) in box.items())
        how = " (once)" if breakpoint_["once"] else ""
        handle = Rectangle((0, 0), 1, 1, facecolor=color, alpha=0.3, edgecolor=color)
        entries.append((handle, f"breakpoint: {bounds} → {breakpoint_['controller']}{how}"))
    return entries


def write_script_gif(trajectory_path: str | Path, out_path: str | Path, fps: int = GIF_FPS) -> None:
    """An animated GIF of the figure moving through the script, drawn only from the
    trajectory's ``figure_motion`` group: rods as thick lines coloured by the active controller,
    the pivot (rod 0's proximal end), the centre of mass and the terrain; fixed, equal-aspect
    limits from the data; a caption with the time and active controller. ``fps`` frames per
    second of motion time (the sample at or after each frame time, one frame more when the
    end is nearer the next frame time than the last; every frame round(1000 / fps) ms, the last
    not held); loops forever. Frames are blitted (``animation_frames``) and written with one
    palette for all (``write_gif``).
    """
    trajectory = read_trajectory(trajectory_path)
    motion = trajectory.motion
    if motion is None or len(motion.t) == 0:
        raise PlotInputError(f"{trajectory_path}: no figure_motion group to animate")
    frame_times = np.arange(motion.t[0], motion.t[-1] + 0.5 / fps, 1.0 / fps)
    samples = np.minimum(np.searchsorted(motion.t, frame_times - 1e-9), len(motion.t) - 1)
    sample_index = np.clip(np.searchsorted(trajectory.t, motion.t + 1e-9) - 1, 0, None)
    active = [trajectory.controllers[trajectory.controller[sample_index[s]]] for s in samples]
    colors = controller_colors(trajectory.controllers)
    kinds = _source_kinds(trajectory)
    endpoints, com = motion.endpoints, motion.com
    corners = np.concatenate([endpoints.reshape(-1, 2), com])
    centre = (corners.min(axis=0) + corners.max(axis=0)) / 2
    half = max(float(np.ptp(corners, axis=0).max()) / 2 * 1.15, 0.1)
    with plot_style():
        figure = new_figure(4.8, 5.4)
        figure.set_dpi(GIF_DPI)
        ax = figure.add_subplot()
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        script = str(trajectory.attrs.get("script", Path(trajectory_path).name))
        figure_name = str(trajectory.attrs.get("figure", "figure"))
        # the caption's line, under the title and above the axes: inside them it hid the
        # hanging pendulum's tip
        ax.set_title(f"{figure_name} through the script {Path(script).name}\n")
        if motion.terrain:
            ground = np.asarray(motion.terrain, dtype=np.float64)
            ax.plot(ground[:, 0], ground[:, 1], color="0.3", linewidth=1.5, zorder=1)
        rods = [
            ax.plot([], [], linewidth=7, solid_capstyle="round", zorder=3)[0]
            for _ in range(endpoints.shape[1])
        ]
        joints = ax.plot([], [], "o", color="0.2", markersize=4, zorder=4)[0]
        pivot_style = {"marker": "o", "color": "black", "markersize": 9, "linestyle": "none"}
        com_style = {
            "marker": "o",
            "markerfacecolor": "gold",
            "markeredgecolor": "black",
            "markersize": 7,
            "linestyle": "none",
        }
        pivot = ax.plot([], [], zorder=5, **pivot_style)[0]
        centre_of_mass = ax.plot([], [], zorder=6, **com_style)[0]
        caption = ax.text(
            0.5, 1.02, "", transform=ax.transAxes, ha="center", va="bottom", family="monospace"
        )
        legend = [
            (Line2D([], [], color=colors[n], linewidth=5), f"{kinds[n]} {n}")
            for n in dict.fromkeys(active)
        ]
        legend += [
            (Line2D([], [], **pivot_style), "pivot"),
            (Line2D([], [], **com_style), "centre of mass"),
        ]
        add_legend(figure, legend, ncols=3, fontsize=8)

        def update(frame: int) -> bool:
            s = samples[frame]
            for rod, ends in zip(rods, endpoints[s], strict=True):
                rod.set_data(ends[:, 0], ends[:, 1])
                rod.set_color(colors[active[frame]])
            joints.set_data(endpoints[s, :, 1, 0], endpoints[s, :, 1, 1])
            pivot.set_data([endpoints[s, 0, 0, 0]], [endpoints[s, 0, 0, 1]])
            centre_of_mass.set_data([com[s, 0]], [com[s, 1]])
            caption.set_text(f"t = {motion.t[s]:5.2f} s   {kinds[active[frame]]} {active[frame]}")
            return False

        moving = [*rods, joints, pivot, centre_of_mass, caption]  # in drawing (z) order
        frames = animation_frames(figure, moving, range(len(samples)), update)
    write_gif(frames, out_path, round(1000 / fps))
