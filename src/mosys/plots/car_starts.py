"""The self-parking car's start grids drawn (the 1990 paper's §6: "the animator can place the
car anywhere within the domain of the SSC"), from the files ``mosys starts`` writes:

- ``plot_success_map``: which start positions of a start grid park, collide, run out of time or
  cannot park at all (excluded from the success rate, with the reason).
- ``plot_consistency``: the start grid's parking times over the controller table's cost-to-go.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.colors import LinearSegmentedColormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.markers import MarkerStyle
from matplotlib.ticker import MaxNLocator

from mosys.errors import InputError
from mosys.io.attributes import string_attr
from mosys.io.car_scene import CarScene
from mosys.io.start_grid import (
    CONSISTENCY_BAND,
    DATASETS,
    NO_WAY,
    NOT_FREE,
    OUTSIDE_DOMAIN,
    StartGrid,
    consistency_summary,
    read_start_grid,
)
from mosys.plots.car_scene import (
    COLUMNS,
    FAILURE_COLOR,
    SCENE_ATTRS,
    SUPTITLE_SIZE,
    check_present,
    describe_value,
    domain_entries,
    draw_scene,
    panel_figure,
    panel_title,
    read_scene,
    scene_points,
    state_columns,
    suptitle,
    view_limits,
)
from mosys.plots.style import (
    DESTINATION_COLOR,
    SYMBOLS,
    PlotInputError,
    add_legend,
    new_figure,
    plot_style,
    save_figure,
)

GRID_ATTRS = (*SCENE_ATTRS, "controller", "simulated_seconds")  # beside io.start_grid's
TIMEOUT_COLOR = "#ff7f0e"
ARRIVAL_COLOR = "#1f4e9c"  # the consistency against the whole arrival box (outline)
PARKING_TIMES = LinearSegmentedColormap.from_list(
    "parking_times", matplotlib.colormaps["Greens"](np.linspace(0.35, 1.0, 256))
)
NOT_FREE_COLOR, NO_WAY_COLOR = "0.2", "0.3"  # the markers of the starts that cannot park
# a NOT_FREE start's + by what makes it so (the start grid's excluded_detail), in turn
NOT_FREE_DETAIL_COLORS = (NOT_FREE_COLOR, "#2c6fbb", "#8e44ad", "#a6611a", "#018571")
# past the last colour, the colours again with the next shape (a scene of a few obstacles has
# more kinds than colours: a garage of three walls and a bin, 8), so that no two kinds look alike,
# up to 25 kinds; unfilled like the + (the x is a collision's)
NOT_FREE_DETAIL_SHAPES = ("+", "1", "2", "3", "4")
MARKER_DIAMETER_RANGE = (3.5, 7.5)  # pt, a start-grid map's markers
MAP_LEGEND_COLUMNS = 3
CONSISTENCY_BIN = 0.05  # width of a consistency histogram bin
CONSISTENCY_CLIP = 3.0  # ratios above this are counted in the title, not drawn
CONSISTENCY_WIDTH, CONSISTENCY_HEIGHT = 7.5, 4.8  # inches


@dataclass(frozen=True)
class _Marker:
    """A start-grid map marker: matplotlib ``marker``, ``face`` and ``edge`` colours, edge
    ``width`` (pt) and ``scale`` (its size over the map's marker diameter)."""

    marker: str
    face: object
    edge: object
    width: float
    scale: float = 1.0

    def scatter(self, diameter: float, by_value: bool = False) -> dict:
        """``Axes.scatter`` keywords at ``diameter`` pt; ``by_value``: no face colour (the caller
        passes ``c`` and a colour map)."""
        keywords = {
            "marker": self.marker,
            "s": (self.scale * diameter) ** 2,
            "linewidths": self.width,
            "zorder": 6,
        }
        if MarkerStyle(self.marker).is_filled():  # an unfilled one (x, +) is drawn in its face
            keywords["edgecolors"] = self.edge
        if not by_value:
            keywords["facecolors"] = self.face
        return keywords

    def handle(self) -> Line2D:
        """The marker's legend handle, at the largest diameter."""
        return Line2D(
            [],
            [],
            marker=self.marker,
            linestyle="none",
            markersize=self.scale * MARKER_DIAMETER_RANGE[1],
            markerfacecolor=self.face,
            markeredgecolor=self.edge,
            markeredgewidth=self.width,
        )


PARKED = _Marker("o", PARKING_TIMES(0.6), "black", 0.5)
COLLIDED = _Marker("x", FAILURE_COLOR, FAILURE_COLOR, 1.6)
TIMED_OUT = _Marker("s", TIMEOUT_COLOR, "black", 0.5, 0.85)
# why a start cannot park at all (io.start_grid's excluded) -> its legend text and marker
EXCLUSIONS = {
    NOT_FREE: (
        "cannot park (start on an obstacle or off the domain)",
        _Marker("+", NOT_FREE_COLOR, NOT_FREE_COLOR, 1.0),
    ),
    NO_WAY: ("cannot park (no path found)", _Marker("D", "none", NO_WAY_COLOR, 1.0, 0.75)),
}


@dataclass(frozen=True)
class DrawnStartGrid:
    """A start grid checked for drawing (``read_drawn_start_grid``): its starts and outcomes
    (``io.start_grid.StartGrid``, arrays of the right shapes and types), the scene they were
    run in, the controller's name and how long each run was simulated (s)."""

    outcomes: StartGrid
    scene: CarScene
    controller: str
    simulated_seconds: float


def read_drawn_start_grid(path: str | Path) -> DrawnStartGrid:
    """Read ``results/car/start_grid.h5`` (see ``success_map_figure``); PlotInputError naming the
    file and what is missing or malformed: a dataset of the wrong shape, a parked start without
    a finite parking time, an exclusion reason other than ``NOT_FREE`` and ``NO_WAY``, an
    excluded start that was run."""
    try:
        grid = read_start_grid(path)
    except InputError as error:  # a dataset or state_order missing, texts that are not strings
        raise PlotInputError(str(error)) from None
    attrs = grid.attrs
    check_present(path, "start grid (root attributes)", GRID_ATTRS, attrs)
    start = np.asarray(grid.start, dtype=np.float64)
    per_start = {name: np.asarray(getattr(grid, name)) for name in DATASETS[1:]}
    for name in ("arrival_cost_to_go", "excluded_detail"):  # optional
        if getattr(grid, name) is not None:
            per_start[name] = np.asarray(getattr(grid, name))
    state_order = grid.state_order
    state_columns(path, state_order, ("x", "y"))
    if start.ndim != 2 or start.shape[1] != len(state_order) or len(start) == 0:
        raise PlotInputError(
            f"{path}: /start has shape {start.shape}, expected (n > 0, {len(state_order)}) for "
            f"state_order {list(state_order)}"
        )
    for name, values in per_start.items():
        if values.shape != (len(start),):
            raise PlotInputError(
                f"{path}: /{name} has shape {values.shape}, expected ({len(start)},)"
            )
    parked = per_start["parked"].astype(bool)
    collided = per_start["collided"].astype(bool)
    parking_seconds = per_start["parking_seconds"].astype(np.float64)
    excluded = per_start["excluded"]
    unknown = ~np.isin(excluded, ["", *EXCLUSIONS])
    if unknown.any():
        first = int(np.flatnonzero(unknown)[0])
        raise PlotInputError(
            f"{path}: start {first} is excluded for an unknown reason {excluded[first]!r} "
            f"(known: {', '.join(repr(reason) for reason in EXCLUSIONS)})"
        )
    run = (parked | collided) & (excluded != "")
    if run.any():
        first = int(np.flatnonzero(run)[0])
        raise PlotInputError(
            f"{path}: start {first} is excluded ({excluded[first]}) but has an outcome: "
            f"parked {parked[first]}, collided {collided[first]}"
        )
    bad_time = parked & ~collided & ~np.isfinite(parking_seconds)
    if bad_time.any():
        first = int(np.flatnonzero(bad_time)[0])
        raise PlotInputError(
            f"{path}: start {first} parked but its parking_seconds is {parking_seconds[first]}"
        )
    outcomes = replace(
        grid,
        start=start,
        parked=parked,
        collided=collided,
        parking_seconds=parking_seconds,
        cost_to_go=per_start["cost_to_go"].astype(np.float64),
        path_length=per_start["path_length"].astype(np.float64),
        arrival_cost_to_go=per_start["arrival_cost_to_go"].astype(np.float64)
        if "arrival_cost_to_go" in per_start
        else None,
    )
    return DrawnStartGrid(
        outcomes=outcomes,
        scene=read_scene(path, attrs),
        controller=string_attr(attrs["controller"]),
        simulated_seconds=float(attrs["simulated_seconds"]),
    )


@dataclass(frozen=True)
class _StartPanels:
    """The start grid's panels: per panel its title and the (n_k,) row indices of its starts;
    the start variables common to all starts in brief; the columns of the panel grid."""

    titles: list[str]
    groups: list[np.ndarray]
    common: list[str]
    columns: int


def _group_starts(grid: StartGrid) -> _StartPanels:
    """The grid's starts grouped by every start variable other than x and y, one panel per
    distinct combination. When two or more variables vary and every combination is present, the
    panels form a table: one column per value of the last varying variable (steer, in the
    runtime's state order), one row per combination of the others (heading); otherwise up to
    COLUMNS panels a row."""
    others = [k for k, name in enumerate(grid.state_order) if name not in ("x", "y")]
    values = np.round(grid.start[:, others], 6)
    varying = [j for j in range(len(others)) if np.ptp(values[:, j]) > 0]
    keys = values[:, varying]
    distinct = np.unique(keys, axis=0) if varying else np.zeros((1, 0))
    titles, groups = [], []
    for key in distinct:
        rows = np.flatnonzero(np.all(keys == key, axis=1)) if varying else np.arange(len(values))
        groups.append(rows)
        parts = []
        for j, value in zip(varying, key, strict=True):
            name = grid.state_order[others[j]]
            symbol = SYMBOLS.get(name)
            parts.append(
                f"{name} {symbol} = {describe_value(name, value)}"
                if symbol
                else f"{name} = {describe_value(name, value)}"
            )
        titles.append(f"start {', '.join(parts)}" if parts else "")
    common = [
        f"{grid.state_order[others[j]]} {describe_value(grid.state_order[others[j]], values[0, j])}"
        for j in range(len(others))
        if j not in varying
    ]
    counts = [len(np.unique(keys[:, j])) for j in range(len(varying))]
    table = len(varying) >= 2 and len(distinct) == math.prod(counts)
    columns = counts[-1] if table else min(COLUMNS, len(distinct))
    return _StartPanels(titles, groups, common, columns)


def _marker_diameter(xy: np.ndarray, points_per_metre: float) -> float:
    """Marker diameter, pt, for starts at xy (n, 2) m: three quarters of the closest spacing of
    the grid's x or y values on the page, within MARKER_DIAMETER_RANGE."""
    spacings = [np.diff(np.unique(np.round(xy[:, k], 6))) for k in range(2)]
    steps = np.concatenate(spacings)
    low, high = MARKER_DIAMETER_RANGE
    if steps.size == 0:
        return high
    return float(np.clip(0.75 * steps.min() * points_per_metre, low, high))


def plot_success_map(start_grid_path: str | Path, out_path: str | Path) -> None:
    """Write ``success_map_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(success_map_figure(start_grid_path), out_path)


def success_map_figure(start_grid_path: str | Path) -> Figure:
    """Which start positions park: the start grid's obstacles and destination outline, and at
    each start's reference point (x, y) a marker: a green disc where it parked (coloured by the
    parking time, colour bar in s), a red × where it hit an obstacle, an orange square where it
    did not park within the simulated time; and for a start that cannot park at all (excluded,
    not run) a + where the start pose is not free (``NOT_FREE``; one colour per obstacle or set
    of obstacles it overlaps, and for a reference point off the domain, where the grid says
    which: ``excluded_detail``, else grey), a hollow grey diamond
    where the pose search found no path to the destination (``NO_WAY``). Markers are sized to
    the grid's spacing on the page. Starts that differ in any other variable (heading, steer,
    speed) get one panel per distinct combination: a table of panels when two vary (rows
    heading, columns steer). The title gives the success rate over the starts that count (not
    excluded) and how many were excluded; each marker's collection has its legend text as gid.

    The start grid (``results/car/start_grid.h5``, ``io.start_grid``): datasets ``start`` (n, d)
    spec units in the root attribute ``state_order``, ``parked`` and ``collided`` (n,) bool,
    ``parking_seconds`` (n,) s (NaN where not parked), ``excluded`` (n,) str, ``cost_to_go``
    (n,) s and ``path_length`` (n,) m; root attributes ``body_outline``, ``obstacles``,
    ``obstacle_names``, ``destination`` (JSON, as in a car trajectory), ``controller`` and
    ``simulated_seconds`` (s)."""
    drawn = read_drawn_start_grid(start_grid_path)
    grid = drawn.outcomes
    column = {name: k for k, name in enumerate(grid.state_order)}
    xy = grid.start[:, [column["x"], column["y"]]]
    panels = _group_starts(grid)
    limits = view_limits(np.concatenate([xy, scene_points(drawn.scene)]), drawn.scene.obstacles)
    parked, counted = grid.succeeded, grid.counted
    times = grid.parking_seconds[parked]
    if len(times):
        low, high = float(times.min()), float(times.max())
        norm = Normalize(low - 0.5, high + 0.5) if high - low < 1e-9 else Normalize(low, high)
    else:
        norm = Normalize(0.0, 1.0)
    count, total = int(parked.sum()), int(counted.sum())
    rate = f" ({100 * count / total:.1f} %)" if total else ""
    headline = f"Controller {drawn.controller}: parks from {count} of {total} starts{rate}"
    if total < len(counted):
        headline += f"; {len(counted) - total} more cannot park at all, not counted"
    details = f"every start: {', '.join(panels.common)}; " if panels.common else ""
    details += f"each run simulated for up to {drawn.simulated_seconds:g} s"
    kinds = [  # (legend text, marker, which starts)
        ("parked", PARKED, parked),
        ("collision", COLLIDED, grid.collided),
        (
            f"not parked in {drawn.simulated_seconds:g} s",
            TIMED_OUT,
            counted & ~parked & ~grid.collided,
        ),
        *_exclusion_kinds(grid),
    ]
    legend = [(marker.handle(), label) for label, marker, _ in kinds]
    legend.append(
        (
            Line2D([], [], color=DESTINATION_COLOR, linestyle=":", linewidth=1.4),
            "destination (car outline)",
        )
    )
    legend += domain_entries([drawn.scene])
    with plot_style():
        layout = panel_figure(
            len(panels.groups),
            limits,
            suptitle_lines=2,
            title_lines=1 if any(panels.titles) else 0,
            legend_rows=-(-len(legend) // MAP_LEGEND_COLUMNS),
            colorbar=bool(len(times)),
            columns=panels.columns,
        )
        panel_inches = layout.panels[0].get_position().width * layout.figure.get_size_inches()[0]
        diameter = _marker_diameter(xy, panel_inches * 72 / (limits[1, 0] - limits[0, 0]))
        mappable = None
        for ax, title, rows in zip(layout.panels, panels.titles, panels.groups, strict=True):
            draw_scene(ax, drawn.scene, limits)
            for label, marker, which in kinds:
                chosen = rows[which[rows]]
                if marker is PARKED:  # coloured by the parking time; none: no colour scale
                    if len(chosen):
                        mappable = ax.scatter(
                            xy[chosen, 0],
                            xy[chosen, 1],
                            c=grid.parking_seconds[chosen],
                            cmap=PARKING_TIMES,
                            norm=norm,
                            gid=label,
                            **marker.scatter(diameter, by_value=True),
                        )
                else:
                    ax.scatter(xy[chosen, 0], xy[chosen, 1], gid=label, **marker.scatter(diameter))
            if title:
                panel_title(ax, title)
        if layout.colorbar is not None and mappable is not None:
            layout.figure.colorbar(mappable, cax=layout.colorbar, label="parking time (s)")
        suptitle(layout.figure, f"{headline}\n{details}")
        add_legend(layout.figure, legend, ncols=MAP_LEGEND_COLUMNS)
    return layout.figure


def _exclusion_kinds(grid: StartGrid) -> list[tuple[str, _Marker, np.ndarray]]:
    """The start-grid map's kinds of starts that cannot park, (legend text, marker, which
    starts (n,) bool), each reason present once; the ``NOT_FREE`` starts of a grid that says
    what makes them so (``excluded_detail``) a kind per detail instead, each a + of its own
    colour (NOT_FREE_DETAIL_COLORS in turn: the overlaps in alphabetical order, then
    ``OUTSIDE_DOMAIN``; past the last colour, the colours again with the next of
    NOT_FREE_DETAIL_SHAPES, so that no two kinds share a marker)."""
    kinds = []
    for reason, (label, marker) in EXCLUSIONS.items():
        which = grid.excluded == reason
        if not which.any():
            continue
        if reason != NOT_FREE or grid.excluded_detail is None:
            kinds.append((label, marker, which))
            continue
        details = grid.excluded_detail.astype(str)
        present = sorted(set(details[which]), key=lambda text: (text == OUTSIDE_DOMAIN, text))
        for k, detail in enumerate(present):
            color = NOT_FREE_DETAIL_COLORS[k % len(NOT_FREE_DETAIL_COLORS)]
            shape = NOT_FREE_DETAIL_SHAPES[
                k // len(NOT_FREE_DETAIL_COLORS) % len(NOT_FREE_DETAIL_SHAPES)
            ]
            kinds.append(
                (
                    f"cannot park: start{'’s' if detail == OUTSIDE_DOMAIN else ''} {detail}"
                    if detail
                    else label,
                    replace(marker, marker=shape, face=color, edge=color),
                    which & (details == detail),
                )
            )
    return kinds


def plot_consistency(start_grid_path: str | Path, out_path: str | Path) -> None:
    """Write ``consistency_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(consistency_figure(start_grid_path), out_path)


def consistency_figure(start_grid_path: str | Path) -> Figure:
    """Does the controller table predict how long parking takes? A histogram, over the starts of
    the start grid that count and parked, of parking time (s) / the table's cost-to-go at the
    start (s), bins CONSISTENCY_BIN wide from 0, each closed on the left: 1 is as predicted, the
    shaded band between the dashed lines at 1 ± CONSISTENCY_BAND (0.75 and 1.25) is within
    25 %. The title gives how many starts parked, the share of them within the band, the median
    and the 90th percentile (linear interpolation) of the ratio (``consistency_summary``), both
    also drawn; ratios that are not finite (no cost-to-go known at the start) count as outside
    the band and are left off the histogram, as are ratios above CONSISTENCY_CLIP; the title
    says how many. A grid with the cost-to-go to the whole arrival box
    (``StartGrid.arrival_consistency``) adds the ratios against it as an outlined histogram
    and a title line (share within the band and median). Reads the start grid as
    ``success_map_figure`` does."""
    drawn = read_drawn_start_grid(start_grid_path)
    grid = drawn.outcomes
    ratios = grid.consistency
    median, p90, within = consistency_summary(ratios)
    finite = ratios[np.isfinite(ratios)]
    arrival = grid.arrival_consistency if len(ratios) else None
    arrival_finite = np.zeros(0) if arrival is None else arrival[np.isfinite(arrival)]
    headline = (
        f"Controller {drawn.controller}: parking time / cost-to-go at the start, "
        f"{len(ratios)} starts that parked"
    )
    if len(ratios):
        inside = int(np.sum(np.abs(ratios - 1.0) <= CONSISTENCY_BAND))
        details = (
            f"within ±{100 * CONSISTENCY_BAND:.0f} %: {inside} of {len(ratios)} "
            f"({100 * within:.1f} %); median {median:.2f}, 90th percentile {p90:.2f}"
        )
        left_off = []
        if len(finite) < len(ratios):
            left_off.append(f"{len(ratios) - len(finite)} with no cost-to-go at the start")
        if np.any(finite > CONSISTENCY_CLIP):
            left_off.append(f"{int(np.sum(finite > CONSISTENCY_CLIP))} above {CONSISTENCY_CLIP:g}")
        if arrival is not None:
            arrival_median, _, arrival_within = consistency_summary(arrival)
            arrival_inside = int(np.sum(np.abs(arrival - 1.0) <= CONSISTENCY_BAND))
            details += (
                f"\nagainst the cost-to-go to the whole arrival box: within "
                f"±{100 * CONSISTENCY_BAND:.0f} %: {arrival_inside} "
                f"({100 * arrival_within:.1f} %); median {arrival_median:.2f}"
            )
            if np.any(arrival_finite > CONSISTENCY_CLIP):
                above = int(np.sum(arrival_finite > CONSISTENCY_CLIP))
                left_off.append(f"{above} above {CONSISTENCY_CLIP:g} against the whole box")
        if left_off:
            details += f"\nnot drawn: {', '.join(left_off)}"
        finite = finite[finite <= CONSISTENCY_CLIP]
        arrival_finite = arrival_finite[arrival_finite <= CONSISTENCY_CLIP]
    else:
        details = "no start parked: nothing to compare"
    drawn = np.concatenate([finite, arrival_finite])
    upper = max(1.0 + 2 * CONSISTENCY_BAND, float(drawn.max()) if len(drawn) else 0.0)
    bins = np.round(CONSISTENCY_BIN * np.arange(math.floor(upper / CONSISTENCY_BIN) + 2), 9)
    with plot_style():
        figure = new_figure(CONSISTENCY_WIDTH, CONSISTENCY_HEIGHT)
        ax = figure.add_subplot()
        ax.axvspan(
            1 - CONSISTENCY_BAND,
            1 + CONSISTENCY_BAND,
            color=PARKING_TIMES(0.1),
            alpha=0.35,
            zorder=0,
            label=f"within ±{100 * CONSISTENCY_BAND:.0f} % of the cost-to-go",
        )
        counts, _, _ = ax.hist(
            finite,
            bins=bins,
            color=PARKING_TIMES(0.7),
            edgecolor="black",
            linewidth=0.5,
            zorder=2,
            **({} if arrival is None else {"label": "against the cost-to-go (/value)"}),
        )
        if arrival is not None:
            arrival_counts, _, _ = ax.hist(
                arrival_finite,
                bins=bins,
                histtype="step",
                color=ARRIVAL_COLOR,
                linewidth=1.6,
                zorder=5,
                label="against the cost-to-go to the whole arrival box",
            )
            counts = np.maximum(counts, arrival_counts)
        for edge in (1 - CONSISTENCY_BAND, 1 + CONSISTENCY_BAND):
            ax.axvline(edge, color="black", linestyle="--", linewidth=1.0, zorder=3)
        ax.axvline(1.0, color="black", linewidth=0.8, zorder=3, label="as the table predicts")
        if len(ratios):
            for value, style, name in ((median, "-", "median"), (p90, ":", "90th percentile")):
                ax.axvline(
                    value,
                    color=TIMEOUT_COLOR,
                    linestyle=style,
                    linewidth=1.8,
                    zorder=4,
                    label=f"{name} {value:.2f}",
                )
        ax.set_xlim(0.0, bins[-1] + CONSISTENCY_BIN)
        ax.set_ylim(0.0, 1.1 * max(1.0, float(counts.max())))
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("parking time / cost-to-go at the start (1: as the table predicts)")
        ax.set_ylabel("starts (count)")
        figure.suptitle(f"{headline}\n{details}", fontsize=SUPTITLE_SIZE)
        add_legend(figure, list(zip(*ax.get_legend_handles_labels(), strict=True)), ncols=2)
        lines = 2 + details.count("\n")
        figure.subplots_adjust(
            top=1 - (0.25 + lines * SUPTITLE_SIZE * 1.5 / 72) / CONSISTENCY_HEIGHT
        )
    return figure
