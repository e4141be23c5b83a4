"""The self-parking car's plots (van de Panne, Fiume & Vranesic 1990, §6, Figure 19).

- ``plot_parking_frames``: one panel per manoeuvre, to scale, the car's outline every
  ``interval`` seconds over the obstacles and the destination (Figure 19).
- ``write_parking_gif``: an animated GIF of one manoeuvre, wheels and all.
- ``plot_success_map``: which start positions of a start grid park, collide, run out of time or
  cannot park at all (excluded from the success rate, with the reason).
- ``plot_consistency``: the start grid's parking times over the controller table's cost-to-go.

Everything is drawn in metres in the world frame, equal aspect. Car states are in spec units and
located by name through ``state_order``: x, y (m) of the reference point midway between the front
wheels; heading (deg, 0 along +x, counter-clockwise); steer (deg, the road wheels' angle, positive
left); speed (m/s). A trajectory that hits an obstacle is drawn only up to and including its first
colliding sample, that outline in red, and its title says FAILED in red.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.colors import LinearSegmentedColormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.markers import MarkerStyle
from matplotlib.patches import Patch, Polygon
from matplotlib.ticker import MaxNLocator
from numpy.typing import ArrayLike

from mosys.errors import InputError
from mosys.io.attributes import string_attr
from mosys.io.car_scene import CarScene, read_car_scene
from mosys.io.start_grid import (
    CONSISTENCY_BAND,
    DATASETS,
    NO_WAY,
    NOT_FREE,
    OUTSIDE_DOMAIN,
    StartGrid,
    consistency_summary,
)
from mosys.io.start_grid import read_start_grid as read_start_grid_file
from mosys.io.trajectory import read_trajectory
from mosys.plots.style import (
    DESTINATION_COLOR,
    GIF_DPI,
    GIF_HOLD_MS,
    LEGEND_ROW,
    MARGIN_BOTTOM,
    MARGIN_RIGHT,
    SYMBOLS,
    PlotInputError,
    add_legend,
    animation_frames,
    fit_aspect,
    frame_indices,
    minus_signs,
    new_figure,
    plot_style,
    samples_to_the_end,
    save_figure,
    write_gif,
)

FRAME_INTERVAL = 0.3  # s between the outlines drawn in a parking panel
PARKING_GIF_FPS = 20  # frames per second of motion time in a parking GIF
COLUMNS = 3  # panels per row
PANEL_WIDTH = 3.3  # inches of one panel's data area in a multi-panel figure
SINGLE_PANEL_WIDTH = 6.0  # inches of the data area when there is one panel
PANEL_ASPECT_RANGE = (0.35, 1.25)  # height / width of a panel: its limits widen to stay inside
VIEW_MARGIN = 1.5  # m: obstacles are shown this far beyond the region the cars use
EDGE_MARGIN = 0.4  # m: blank border around everything shown
DEFAULT_WHEEL_RADIUS = 0.3  # m, when a trajectory records no wheel_radius
TRACK_FRACTION = 0.82  # track / body width, when a trajectory records no track

STATE_UNITS = {"x": "m", "y": "m", "heading": "deg", "steer": "deg", "speed": "m/s"}
POSE_NAMES = ("x", "y", "heading", "steer")  # state variables every car file must carry
SCENE_ATTRS = ("body_outline", "obstacles", "obstacle_names", "destination")
RUN_ATTRS = (
    *SCENE_ATTRS,
    "wheelbase",
    "collision_index",
    "collided_with",
    "parked",
    "parking_seconds",
    "simulated_seconds",
)
GRID_ATTRS = (*SCENE_ATTRS, "controller", "simulated_seconds")  # beside io.start_grid's

OBSTACLE_FACE, OBSTACLE_EDGE = "0.72", "0.45"
DOMAIN_STYLE = {"edgecolor": "0.35", "linestyle": "--", "linewidth": 1.0}
FAILURE_COLOR = "#d62728"  # the collision outline, the FAILED titles, the collision markers
TIMEOUT_COLOR = "#ff7f0e"
PATH_COLOR = "0.2"
ARRIVAL_COLOR = "#1f4e9c"  # the consistency against the whole arrival box (outline)
TIME_SHADES = matplotlib.colormaps["Blues"]  # outlines, light (start) to dark (end)
SHADE_RANGE = (0.3, 0.95)  # the part of TIME_SHADES used
PARKING_TIMES = LinearSegmentedColormap.from_list(
    "parking_times", matplotlib.colormaps["Greens"](np.linspace(0.35, 1.0, 256))
)
NOT_FREE_COLOR, NO_WAY_COLOR = "0.2", "0.3"  # the markers of the starts that cannot park
# a NOT_FREE start's + by what makes it so (the start grid's excluded_detail), in turn
NOT_FREE_DETAIL_COLORS = (NOT_FREE_COLOR, "#2c6fbb", "#8e44ad", "#a6611a", "#018571")
MARKER_DIAMETER_RANGE = (3.5, 7.5)  # pt, a start-grid map's markers
MAP_LEGEND_COLUMNS = 3
CONSISTENCY_BIN = 0.05  # width of a consistency histogram bin
CONSISTENCY_CLIP = 3.0  # ratios above this are counted in the title, not drawn
CONSISTENCY_WIDTH, CONSISTENCY_HEIGHT = 7.5, 4.8  # inches
TITLE_SIZE = 10.0  # pt, panel titles
SUPTITLE_SIZE = 12.0  # pt
OBSTACLE_LABEL_SIZE = 8.0  # pt


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


# --------------------------------------------------------------------------- reading the inputs


@dataclass(frozen=True)
class CarTrajectory:
    """One simulated manoeuvre. t: (N,) s; x, y: (N,) m; heading, steer: (N,) deg; speed: (N,)
    m/s or None; collision_index: first sample whose outline meets an obstacle, -1 if none;
    parking_seconds: s (NaN if not parked); simulated_seconds: s; wheelbase, track and
    wheel_radius: m; name: the file's stem."""

    name: str
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    steer: np.ndarray
    speed: np.ndarray | None
    scene: CarScene
    controllers: tuple[str, ...]
    wheelbase: float
    track: float
    wheel_radius: float
    collision_index: int
    collided_with: str
    parked: bool
    parking_seconds: float
    simulated_seconds: float

    @property
    def collided(self) -> bool:
        return self.collision_index >= 0

    @property
    def failed(self) -> bool:
        """True unless the car parked without touching anything."""
        return self.collided or not self.parked

    def start(self) -> dict[str, float]:
        """The start state by name, spec units."""
        start = {"x": self.x[0], "y": self.y[0], "heading": self.heading[0], "steer": self.steer[0]}
        if self.speed is not None:
            start["speed"] = self.speed[0]
        return {name: float(value) for name, value in start.items()}


@dataclass(frozen=True)
class DrawnStartGrid:
    """A start grid checked for drawing (``read_start_grid``): its starts and outcomes
    (``io.start_grid.StartGrid``, arrays of the right shapes and types), the scene they were
    run in, the controller's name and how long each run was simulated (s)."""

    outcomes: StartGrid
    scene: CarScene
    controller: str
    simulated_seconds: float


def _missing(path, kind: str, names: Sequence[str], present) -> None:
    absent = [name for name in names if name not in present]
    if absent:
        raise PlotInputError(f"{path}: not a {kind}: missing {', '.join(absent)}")


def _read_scene(path, attrs) -> CarScene:
    """The body outline, obstacles and destination from a file's root attributes."""
    try:
        return read_car_scene(attrs, str(path))
    except InputError as error:
        raise PlotInputError(str(error)) from None


def _columns(path, state_order: Sequence[str], required: Sequence[str]) -> dict[str, int]:
    """Column index of each state variable by name; PlotInputError naming the absent ones."""
    absent = [name for name in required if name not in state_order]
    if absent:
        raise PlotInputError(
            f"{path}: state_order {list(state_order)} lacks {', '.join(absent)}: not a car state"
        )
    return {name: k for k, name in enumerate(state_order)}


def read_car_trajectory(path: str | Path) -> CarTrajectory:
    """Read a car trajectory (the trajectory contract plus the car's root attributes, see the
    module docstring); PlotInputError naming the file and what is missing or malformed."""
    try:
        trajectory = read_trajectory(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    attrs = trajectory.attrs
    _missing(path, "car trajectory (root attributes)", RUN_ATTRS, attrs)
    column = _columns(path, trajectory.state_order, POSE_NAMES)
    state, t = np.asarray(trajectory.state, dtype=np.float64), np.asarray(trajectory.t, np.float64)
    if t.ndim != 1 or len(t) == 0:
        raise PlotInputError(f"{path}: the trajectory has no samples")
    if state.shape != (len(t), len(trajectory.state_order)):
        raise PlotInputError(
            f"{path}: /state has shape {state.shape}, expected ({len(t)}, "
            f"{len(trajectory.state_order)}) for {len(t)} samples of {trajectory.state_order}"
        )
    for name in POSE_NAMES:
        if not np.all(np.isfinite(state[:, column[name]])):
            bad = int(np.flatnonzero(~np.isfinite(state[:, column[name]]))[0])
            raise PlotInputError(f"{path}: {name} is {state[bad, column[name]]} at sample {bad}")
    if not np.all(np.diff(t) >= 0):
        raise PlotInputError(f"{path}: /t decreases at sample {int(np.argmin(np.diff(t))) + 1}")
    scene = _read_scene(path, attrs)
    collision_index = int(attrs["collision_index"])
    if not -1 <= collision_index < len(t):
        raise PlotInputError(
            f"{path}: collision_index {collision_index} is outside the {len(t)} samples"
        )
    parked = bool(attrs["parked"])
    parking_seconds = float(attrs["parking_seconds"])
    if parked and not math.isfinite(parking_seconds):
        raise PlotInputError(f"{path}: parked is true but parking_seconds is {parking_seconds}")
    wheelbase = float(attrs["wheelbase"])
    if not wheelbase > 0:
        raise PlotInputError(f"{path}: wheelbase must be positive, got {wheelbase}")
    half_width = float(np.abs(scene.body_outline[:, 1]).max())
    return CarTrajectory(
        name=Path(path).stem,
        t=t,
        x=state[:, column["x"]],
        y=state[:, column["y"]],
        heading=state[:, column["heading"]],
        steer=state[:, column["steer"]],
        speed=state[:, column["speed"]] if "speed" in column else None,
        scene=scene,
        controllers=trajectory.controllers,
        wheelbase=wheelbase,
        track=float(attrs.get("track", TRACK_FRACTION * 2 * half_width)),
        wheel_radius=float(attrs.get("wheel_radius", DEFAULT_WHEEL_RADIUS)),
        collision_index=collision_index,
        collided_with=string_attr(attrs["collided_with"]),
        parked=parked,
        parking_seconds=parking_seconds,
        simulated_seconds=float(attrs["simulated_seconds"]),
    )


def read_start_grid(path: str | Path) -> DrawnStartGrid:
    """Read ``results/car/start_grid.h5`` (see ``success_map_figure``); PlotInputError naming the
    file and what is missing or malformed: a dataset of the wrong shape, a parked start without
    a finite parking time, an exclusion reason other than ``NOT_FREE`` and ``NO_WAY``, an
    excluded start that was run."""
    try:
        grid = read_start_grid_file(path)
    except InputError as error:  # a dataset or state_order missing, texts that are not strings
        raise PlotInputError(str(error)) from None
    attrs = grid.attrs
    _missing(path, "start grid (root attributes)", GRID_ATTRS, attrs)
    start = np.asarray(grid.start, dtype=np.float64)
    per_start = {name: np.asarray(getattr(grid, name)) for name in DATASETS[1:]}
    for name in ("arrival_cost_to_go", "excluded_detail"):  # optional
        if getattr(grid, name) is not None:
            per_start[name] = np.asarray(getattr(grid, name))
    state_order = grid.state_order
    _columns(path, state_order, ("x", "y"))
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
        scene=_read_scene(path, attrs),
        controller=string_attr(attrs["controller"]),
        simulated_seconds=float(attrs["simulated_seconds"]),
    )


# --------------------------------------------------------------------------- pure helpers


def drawn_samples(t: np.ndarray, interval: float, collision_index: int = -1) -> np.ndarray:
    """The samples whose outline a parking panel draws: every ``interval`` seconds (see
    ``frame_indices``) and the last sample, but nothing after the first colliding sample
    ``collision_index`` (-1: no collision), which is itself drawn (and is then the last)."""
    index = frame_indices(t, interval)
    last = len(t) - 1 if collision_index < 0 else int(collision_index)
    if last < 0:
        return index
    return np.unique(np.append(index[index <= last], last)).astype(np.int64)


def outcome_text(trajectory: CarTrajectory) -> str:
    """The outcome line of a manoeuvre's title: ``parked in 12.3 s``, ``FAILED: hits
    front_car at 4.2 s`` or ``FAILED: not parked in 20 s``. A collision is a failure even when
    the file also says parked."""
    if trajectory.collided:
        where = trajectory.collided_with or "an obstacle"
        return f"FAILED: hits {where} at {trajectory.t[trajectory.collision_index]:.1f} s"
    if trajectory.parked:
        return f"parked in {trajectory.parking_seconds:.1f} s"
    return f"FAILED: not parked in {trajectory.simulated_seconds:g} s"


def place_outline(
    outline: np.ndarray, x: ArrayLike, y: ArrayLike, heading: ArrayLike
) -> np.ndarray:
    """An outline (V, 2) m in the car's frame placed at poses x, y (m), heading (deg), scalars
    or (K,) arrays: (V, 2) or (K, V, 2) m in the world frame."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    angle = np.radians(np.asarray(heading, dtype=np.float64))
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    u, v = outline[:, 0], outline[:, 1]
    return np.stack([x[..., None] + c * u - s * v, y[..., None] + s * u + c * v], axis=-1)


def wheel_segments(trajectory: CarTrajectory, sample: int) -> np.ndarray:
    """The four wheels at ``sample`` as (4, 2, 2) m segments (front left, front right, rear
    left, rear right; each its two ends): centred on the axles, half a track out, one wheel
    diameter long, the front pair turned by the steer angle."""
    heading = math.radians(trajectory.heading[sample])
    steer = math.radians(trajectory.steer[sample])
    x, y = trajectory.x[sample], trajectory.y[sample]
    forward = np.array([math.cos(heading), math.sin(heading)])
    left = np.array([-forward[1], forward[0]])
    half = trajectory.wheel_radius
    segments = []
    for axle, turn in ((0.0, steer), (-trajectory.wheelbase, 0.0)):
        along = np.array([math.cos(heading + turn), math.sin(heading + turn)]) * half
        for side in (1.0, -1.0):
            centre = np.array([x, y]) + axle * forward + side * trajectory.track / 2 * left
            segments.append([centre - along, centre + along])
    return np.array(segments)


def describe_value(name: str, value: float) -> str:
    """A state value for a title: ``−30°``, ``3.5 m``, ``0.0 m/s`` (a true minus sign)."""
    unit = STATE_UNITS.get(name, "")
    whole = unit == "deg" and abs(value - round(value)) < 0.05
    value = round(value, 0 if whole else 1) + 0.0  # + 0.0: no "-0"
    text = f"{value:.0f}°" if whole else f"{value:.1f}°" if unit == "deg" else f"{value:.1f} {unit}"
    return minus_signs(text.rstrip())


def _start_summary(runs: Sequence[CarTrajectory]) -> list[list[str]]:
    """Per run, its start state in brief, as parts to join with commas: the variables in which
    the runs' starts differ (position, heading, steer, speed; position and heading when none
    differ), e.g. ``["steer −30°"]`` or ``["from (7.9, 3.5) m", "heading 0°"]``."""
    names = [n for n in STATE_UNITS if all(n in run.start() for run in runs)]
    starts = np.array([[run.start()[n] for n in names] for run in runs])
    varying = {n for k, n in enumerate(names) if np.ptp(starts[:, k]) > 1e-6}
    if not varying:
        varying = {"x", "heading"}
    summaries = []
    for run in runs:
        start, parts = run.start(), []
        if varying & {"x", "y"}:
            position = f"from ({start['x']:.3g}, {start['y']:.3g}) m"  # 3.25 read 3.2
            parts.append(minus_signs(position))
        for name in ("heading", "steer", "speed"):
            if name in varying:
                parts.append(f"{name} {describe_value(name, start[name])}")
        summaries.append(parts)
    return summaries


def _wrap(head: str, parts: Sequence[str], width: int) -> str:
    """``head`` then ``parts`` joined with commas, broken into lines of about ``width``
    characters, only between parts."""
    lines = [head]
    for k, part in enumerate(parts):
        piece = part + ("," if k < len(parts) - 1 else "")
        if len(lines[-1]) + 1 + len(piece) > width and lines[-1] != head:
            lines.append(piece)
        else:
            lines[-1] += " " + piece
    return "\n".join(lines)


def _title_chars(panel_width: float) -> int:
    """About how many characters of a panel title fit across ``panel_width`` inches."""
    return int(panel_width * 72 / (0.62 * TITLE_SIZE))


# --------------------------------------------------------------------------- layout and drawing


def _bounds(points: np.ndarray) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] of points (..., 2)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return np.array([points.min(axis=0), points.max(axis=0)])


def view_limits(car_points: np.ndarray, obstacles: Sequence[np.ndarray]) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] m of the view: the region the cars use (``car_points``
    (..., 2) m: outlines, path, destination) united with the obstacles' extents clipped to that
    region widened by VIEW_MARGIN, plus EDGE_MARGIN all round, then widened in x or y to keep
    the view's height / width within PANEL_ASPECT_RANGE (``fit_aspect``)."""
    cars = _bounds(car_points)
    window = cars + [[-VIEW_MARGIN], [VIEW_MARGIN]]
    limits = cars.copy()
    for polygon in obstacles:
        box = _bounds(polygon)
        low, high = np.maximum(box[0], window[0]), np.minimum(box[1], window[1])
        if np.all(high >= low):
            limits = np.array([np.minimum(limits[0], low), np.maximum(limits[1], high)])
    limits += [[-EDGE_MARGIN], [EDGE_MARGIN]]
    return fit_aspect(limits, PANEL_ASPECT_RANGE)


@dataclass(frozen=True)
class _Layout:
    figure: Figure
    panels: list[Axes]
    colorbar: Axes | None


def _panel_figure(
    count: int,
    limits: np.ndarray,
    suptitle_lines: int,
    title_lines: int,
    legend_rows: int,
    colorbar: bool = False,
    dpi: float | None = None,
    columns: int = COLUMNS,
) -> _Layout:
    """A figure of ``count`` equal-aspect panels on a grid of up to ``columns`` columns, sized in
    inches so that each panel's box has the aspect of ``limits``: y tick labels on the left
    column only (all panels share the limits), x labels under the lowest panel of each column,
    room above for the figure's title and each panel's title, below for a legend, and on the
    right for a colour bar."""
    columns = min(columns, count)
    rows = -(-count // columns)
    (x0, y0), (x1, y1) = limits
    width = SINGLE_PANEL_WIDTH if count == 1 else PANEL_WIDTH
    height = width * (y1 - y0) / (x1 - x0)
    title_space = title_lines * TITLE_SIZE * 1.45 / 72 + 0.1
    left, gap_x, gap_y = 0.75, 0.22, title_space + 0.42
    top = 0.12 + suptitle_lines * SUPTITLE_SIZE * 1.5 / 72 + title_space
    bottom = MARGIN_BOTTOM + (LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0)
    right = MARGIN_RIGHT + (1.05 if colorbar else 0.0)
    fig_width = left + columns * width + (columns - 1) * gap_x + right
    fig_height = top + rows * height + (rows - 1) * gap_y + bottom
    figure = new_figure(fig_width, fig_height)
    if dpi is not None:
        figure.set_dpi(dpi)
    panels = []
    for k in range(count):
        row, column = divmod(k, columns)
        x = left + column * (width + gap_x)
        y = fig_height - top - (row + 1) * height - row * gap_y
        ax = figure.add_axes(
            (x / fig_width, y / fig_height, width / fig_width, height / fig_height)
        )
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal", adjustable="box")
        if column == 0:
            ax.set_ylabel("y (m)")
        else:
            ax.tick_params(labelleft=False)
        if k + columns >= count:
            ax.set_xlabel("x (m)")
        panels.append(ax)
    bar = None
    if colorbar:
        x = left + columns * width + (columns - 1) * gap_x + 0.2
        y = bottom
        span = fig_height - top - bottom
        bar = figure.add_axes((x / fig_width, y / fig_height, 0.16 / fig_width, span / fig_height))
    return _Layout(figure, panels, bar)


def _suptitle(figure: Figure, text: str) -> None:
    height = figure.get_size_inches()[1]
    figure.suptitle(text, y=1 - 0.08 / height, va="top", fontsize=SUPTITLE_SIZE)


def _panel_title(ax: Axes, first_line: str, outcome: str | None = None, failed=False) -> None:
    """A panel's title: ``first_line`` in black over an ``outcome`` line, red when ``failed``
    (the outcome text carries the gid ``outcome``)."""
    if outcome is None:
        ax.set_title(first_line, fontsize=TITLE_SIZE)
        return
    ax.set_title(first_line, fontsize=TITLE_SIZE, pad=5 + 1.3 * TITLE_SIZE)
    ax.annotate(
        outcome,
        xy=(0.5, 1.0),
        xycoords="axes fraction",
        xytext=(0, 4),
        textcoords="offset points",
        ha="center",
        va="bottom",
        fontsize=TITLE_SIZE,
        color=FAILURE_COLOR if failed else "black",
        fontweight="bold" if failed else "normal",
        gid="outcome",
    )


def _domain_entries(scenes: Sequence[CarScene]) -> list[tuple[object, str]]:
    """The legend entry of the domain, if any scene has one."""
    if not any(len(scene.domain) >= 3 for scene in scenes):
        return []
    line = Line2D([], [], color=DOMAIN_STYLE["edgecolor"], linestyle="--", linewidth=1.0)
    return [(line, "domain (the front-axle midpoint stays in it)")]


def _draw_scene(ax: Axes, scene: CarScene, limits: np.ndarray) -> None:
    """Obstacles as grey polygons, each named where its name fits in the part in view, and the
    destination as the car's outline, dotted, at the destination pose. Call once the axes are
    placed: the name's size in metres comes from the axes' size in inches."""
    axes_inches = ax.get_position().width * ax.figure.get_size_inches()[0]
    metres_per_point = (limits[1, 0] - limits[0, 0]) / (axes_inches * 72)
    if len(scene.domain) >= 3:  # Figure 17's dashed region: where the reference point stays
        ax.add_patch(Polygon(scene.domain, closed=True, fill=False, zorder=1.2, **DOMAIN_STYLE))
    for name, polygon in zip(scene.obstacle_names, scene.obstacles, strict=True):
        ax.add_patch(
            Polygon(
                polygon,
                closed=True,
                facecolor=OBSTACLE_FACE,
                edgecolor=OBSTACLE_EDGE,
                linewidth=0.8,
                zorder=1,
            )
        )
        box = _bounds(polygon)
        low, high = np.maximum(box[0], limits[0]), np.minimum(box[1], limits[1])
        label = np.array([0.62 * len(name) + 1, 1.6]) * OBSTACLE_LABEL_SIZE * metres_per_point
        if np.all(high - low > label):
            centre = (low + high) / 2
            ax.text(
                *centre,
                name,
                ha="center",
                va="center",
                fontsize=OBSTACLE_LABEL_SIZE,
                color="0.15",
                clip_on=True,
                zorder=6.5,  # over the start map's markers (6), which hid it
                bbox={"boxstyle": "round,pad=0.2", "facecolor": OBSTACLE_FACE, "edgecolor": "none"},
            )
    destination = scene.destination
    goal = place_outline(
        scene.body_outline, destination["x"], destination["y"], destination["heading"]
    )
    ax.add_patch(
        Polygon(
            goal,
            closed=True,
            fill=False,
            edgecolor=DESTINATION_COLOR,
            linestyle=":",
            linewidth=1.4,
            zorder=4,
        )
    )


def _shade(fraction) -> np.ndarray:
    low, high = SHADE_RANGE
    return TIME_SHADES(low + (high - low) * np.asarray(fraction, dtype=np.float64))


def _draw_manoeuvre(ax: Axes, run: CarTrajectory, samples: np.ndarray) -> None:
    """The reference point's path and the car's outline at ``samples``, shaded light to dark
    with time; the start and final outlines thick, a colliding final outline red."""
    last = int(samples[-1])
    ax.plot(run.x[: last + 1], run.y[: last + 1], color=PATH_COLOR, linewidth=0.8, zorder=3)
    outlines = place_outline(
        run.scene.body_outline, run.x[samples], run.y[samples], run.heading[samples]
    )
    span = run.t[last] - run.t[0]
    colors = _shade((run.t[samples] - run.t[0]) / span if span > 0 else np.ones(len(samples)))
    ax.add_collection(
        PolyCollection(
            outlines[1:-1],
            closed=True,
            facecolors="none",
            edgecolors=colors[1:-1],
            linewidths=0.7,
            zorder=2,
        )
    )
    ax.add_patch(
        Polygon(outlines[0], closed=True, fill=False, edgecolor=colors[0], linewidth=2.0, zorder=3)
    )
    ax.plot(
        run.x[0],
        run.y[0],
        "o",
        color=colors[0],
        markeredgecolor="black",
        markeredgewidth=0.6,
        markersize=4,
        zorder=5,
    )
    if run.collided:
        ax.add_patch(
            Polygon(
                outlines[-1],
                closed=True,
                facecolor=FAILURE_COLOR,
                alpha=0.25,
                edgecolor="none",
                zorder=3,
            )
        )
        ax.add_patch(
            Polygon(
                outlines[-1],
                closed=True,
                fill=False,
                edgecolor=FAILURE_COLOR,
                linewidth=2.0,
                zorder=4,
            )
        )
    else:
        ax.add_patch(
            Polygon(
                outlines[-1], closed=True, fill=False, edgecolor=colors[-1], linewidth=2.0, zorder=3
            )
        )


def _controller_names(runs: Sequence[CarTrajectory]) -> str:
    names = list(dict.fromkeys(name for run in runs for name in run.controllers))
    return ", ".join(names) if names else "?"


def _scene_points(scene: CarScene) -> np.ndarray:
    d = scene.destination
    return place_outline(scene.body_outline, d["x"], d["y"], d["heading"])


# --------------------------------------------------------------------------- the plots


def plot_parking_frames(
    trajectory_paths: Sequence[str | Path],
    out_path: str | Path,
    interval: float = FRAME_INTERVAL,
) -> None:
    """Write ``parking_frames_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(parking_frames_figure(trajectory_paths, interval), out_path)


def parking_frames_figure(
    trajectory_paths: Sequence[str | Path], interval: float = FRAME_INTERVAL
) -> Figure:
    """Figure 19: one panel per car trajectory (2 rows × 3 columns for six; any count works),
    each to scale in metres over the same x/y limits: the obstacles (grey), the destination
    (the car's outline at the goal, dotted), the car's outline every ``interval`` seconds
    (light to dark with time, the start and final outlines thick) and the reference point's path.
    A run that hits an obstacle is drawn up to its first colliding sample, that outline red. Each
    panel's title: the file stem, its start state, and the outcome (a failure in red)."""
    if not trajectory_paths:
        raise PlotInputError("plot_parking_frames: no trajectories given")
    runs = [read_car_trajectory(path) for path in trajectory_paths]
    samples = [drawn_samples(run.t, interval, run.collision_index) for run in runs]
    car_points = []
    for run, drawn in zip(runs, samples, strict=True):
        car_points.append(
            place_outline(run.scene.body_outline, run.x[drawn], run.y[drawn], run.heading[drawn])
        )
        car_points.append(np.column_stack([run.x[: drawn[-1] + 1], run.y[: drawn[-1] + 1]]))
        car_points.append(_scene_points(run.scene))
    limits = view_limits(
        np.concatenate([p.reshape(-1, 2) for p in car_points]),
        [polygon for run in runs for polygon in run.scene.obstacles],
    )
    legend = [
        (Patch(facecolor=OBSTACLE_FACE, edgecolor=OBSTACLE_EDGE), "obstacle"),
        (
            Line2D([], [], color=DESTINATION_COLOR, linestyle=":", linewidth=1.4),
            "destination (car outline)",
        ),
        (
            Line2D([], [], color=_shade(0.5), linewidth=0.7),
            f"car every {interval:g} s, light → dark",
        ),
        (
            Line2D(
                [],
                [],
                color=_shade(0.0),
                linewidth=2.0,
                marker="o",
                markersize=4,
                markeredgecolor="black",
                markeredgewidth=0.6,
            ),
            "start outline and its front-axle midpoint",
        ),
        (Line2D([], [], color=_shade(1.0), linewidth=2.0), "final outline"),
        (Line2D([], [], color=PATH_COLOR, linewidth=0.8), "path of the front-axle midpoint"),
        (
            Patch(facecolor=(1, 0, 0, 0.25), edgecolor=FAILURE_COLOR, linewidth=2.0),
            "first collision",
        ),
        *_domain_entries([run.scene for run in runs]),
    ]
    width = _title_chars(SINGLE_PANEL_WIDTH if len(runs) == 1 else PANEL_WIDTH)
    summaries = _start_summary(runs)
    heads = [
        _wrap(f"{run.name}:", parts, width) for run, parts in zip(runs, summaries, strict=True)
    ]
    title_lines = 1 + max(head.count("\n") + 1 for head in heads)
    with plot_style():
        # four legend columns fit under a row of three panels; one or two panels take two
        columns = 4 if len(runs) >= COLUMNS else 2
        rows = -(-len(legend) // columns)
        layout = _panel_figure(len(runs), limits, 1, title_lines, legend_rows=rows)
        for ax, run, drawn, head in zip(layout.panels, runs, samples, heads, strict=True):
            _draw_scene(ax, run.scene, limits)
            _draw_manoeuvre(ax, run, drawn)
            _panel_title(ax, head, outcome_text(run), run.failed)
        _suptitle(layout.figure, f"The car parking under controller {_controller_names(runs)}")
        add_legend(layout.figure, legend, ncols=columns)
    return layout.figure


def write_parking_gif(
    trajectory_path: str | Path, out_path: str | Path, fps: int = PARKING_GIF_FPS
) -> None:
    """An animated GIF of one manoeuvre, to scale in metres: obstacles, the destination outline,
    the car's outline with its four wheels (short thick segments, the front pair turned by the
    steer angle), the path so far, the time and the speed. ``fps`` frames per second of motion time
    (the sample at or after each frame time, and the last, see ``samples_to_the_end``), each
    frame round(1000 / fps) ms; a run that collides stops at its first colliding sample, drawn
    red; the last frame is held GIF_HOLD_MS ms; loops. Frames are blitted
    (``animation_frames``) and written with one shared palette (``write_gif``)."""
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    run = read_car_trajectory(trajectory_path)
    last = len(run.t) - 1 if run.collision_index < 0 else run.collision_index
    samples = samples_to_the_end(run.t[: last + 1], 1.0 / fps)
    every = np.arange(last + 1)
    limits = view_limits(
        np.concatenate(
            [
                place_outline(
                    run.scene.body_outline, run.x[every], run.y[every], run.heading[every]
                ).reshape(-1, 2),
                _scene_points(run.scene),
            ]
        ),
        run.scene.obstacles,
    )
    failed = run.failed
    with plot_style():
        head = _wrap(
            f"{run.name}, controller {_controller_names([run])}:",
            _start_summary([run])[0],
            _title_chars(SINGLE_PANEL_WIDTH),
        )
        title_lines = head.count("\n") + 2
        layout = _panel_figure(1, limits, 0, title_lines, legend_rows=0, dpi=GIF_DPI)
        figure, ax = layout.figure, layout.panels[0]
        _draw_scene(ax, run.scene, limits)
        _panel_title(ax, head, outcome_text(run), failed)
        body = Polygon(
            run.scene.body_outline,
            closed=True,
            facecolor=_shade(0.15),
            edgecolor=_shade(1.0),
            linewidth=1.8,
            zorder=5,
        )
        ax.add_patch(body)
        wheels = [
            ax.plot([], [], color="0.1", linewidth=4, solid_capstyle="butt", zorder=6)[0]
            for _ in range(4)
        ]
        path = ax.plot([], [], color=PATH_COLOR, linewidth=1.0, zorder=4)[0]
        caption = ax.text(
            0.02,
            0.97,
            "",
            transform=ax.transAxes,
            family="monospace",
            fontsize=9,
            ha="left",
            va="top",
            zorder=7,
            bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.6"},
        )

        def update(frame: int) -> bool:
            s = int(samples[frame])
            path.set_data(run.x[: s + 1], run.y[: s + 1])
            body.set_xy(place_outline(run.scene.body_outline, run.x[s], run.y[s], run.heading[s]))
            hit = run.collided and s == run.collision_index
            body.set_edgecolor(FAILURE_COLOR if hit else _shade(1.0))
            body.set_facecolor((1.0, 0.0, 0.0, 0.3) if hit else _shade(0.15))
            for wheel, segment in zip(wheels, wheel_segments(run, s), strict=True):
                wheel.set_data(segment[:, 0], segment[:, 1])
            text = f"t = {run.t[s]:5.2f} s"  # short: text is most of a frame's drawing time
            if run.speed is not None:
                text += f"  v = {round(float(run.speed[s]), 1) + 0.0:+.1f} m/s"  # + 0.0: no -0
            caption.set_text(minus_signs(text))
            return False

        moving = [path, body, *wheels, caption]  # in drawing (z) order
        frames = animation_frames(figure, moving, range(len(samples)), update)
    write_gif(frames, out_path, [round(1000 / fps)] * (len(frames) - 1) + [GIF_HOLD_MS])


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
    drawn = read_start_grid(start_grid_path)
    grid = drawn.outcomes
    column = {name: k for k, name in enumerate(grid.state_order)}
    xy = grid.start[:, [column["x"], column["y"]]]
    panels = _group_starts(grid)
    limits = view_limits(np.concatenate([xy, _scene_points(drawn.scene)]), drawn.scene.obstacles)
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
    legend += _domain_entries([drawn.scene])
    with plot_style():
        layout = _panel_figure(
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
            _draw_scene(ax, drawn.scene, limits)
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
                _panel_title(ax, title)
        if layout.colorbar is not None and mappable is not None:
            layout.figure.colorbar(mappable, cax=layout.colorbar, label="parking time (s)")
        _suptitle(layout.figure, f"{headline}\n{details}")
        add_legend(layout.figure, legend, ncols=MAP_LEGEND_COLUMNS)
    return layout.figure


def _exclusion_kinds(grid: StartGrid) -> list[tuple[str, _Marker, np.ndarray]]:
    """The start-grid map's kinds of starts that cannot park, (legend text, marker, which
    starts (n,) bool), each reason present once; the ``NOT_FREE`` starts of a grid that says
    what makes them so (``excluded_detail``) a kind per detail instead, each a + of its own
    colour (NOT_FREE_DETAIL_COLORS in turn: the overlaps in alphabetical order, then
    ``OUTSIDE_DOMAIN``)."""
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
            kinds.append(
                (
                    f"cannot park: start{'’s' if detail == OUTSIDE_DOMAIN else ''} {detail}"
                    if detail
                    else label,
                    replace(marker, face=color, edge=color),
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
    drawn = read_start_grid(start_grid_path)
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
