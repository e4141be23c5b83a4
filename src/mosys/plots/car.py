"""The self-parking car's manoeuvres drawn (van de Panne, Fiume & Vranesic 1990, §6, Figure 19).

- ``plot_parking_frames``: one panel per manoeuvre, to scale, the car's outline every
  ``interval`` seconds over the obstacles and the destination (Figure 19).
- ``write_parking_gif``: an animated GIF of one manoeuvre, wheels and all.

The start grid's plots are ``mosys.plots.car_starts``'s; the scene both draw (obstacles, domain,
destination, panels) ``mosys.plots.car_scene``'s.

Everything is drawn in metres in the world frame, equal aspect. Car states are in spec units and
located by name through ``state_order``: x, y (m) of the reference point midway between the front
wheels; heading (deg, 0 along +x, counter-clockwise); steer (deg, the road wheels' angle, positive
left); speed (m/s). A trajectory that hits an obstacle is drawn only up to and including its first
colliding sample, that outline in red, and its title says FAILED in red.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon

from mosys.errors import InputError
from mosys.io.attributes import string_attr
from mosys.io.car_scene import CarScene
from mosys.io.trajectory import read_trajectory
from mosys.plots.car_scene import (
    COLUMNS,
    FAILURE_COLOR,
    OBSTACLE_EDGE,
    OBSTACLE_FACE,
    PANEL_WIDTH,
    SCENE_ATTRS,
    SINGLE_PANEL_WIDTH,
    STATE_UNITS,
    TITLE_SIZE,
    check_present,
    describe_value,
    domain_entries,
    draw_scene,
    panel_figure,
    panel_title,
    place_outline,
    read_scene,
    scene_points,
    state_columns,
    suptitle,
    view_limits,
)
from mosys.plots.style import (
    DESTINATION_COLOR,
    GIF_DPI,
    GIF_HOLD_MS,
    REAL_TIME_MAX_FRAMES,
    PlotInputError,
    add_legend,
    animation_frames,
    choose_interval,
    frame_indices,
    frame_step,
    minus_signs,
    plot_style,
    samples_to_the_end,
    save_figure,
    write_gif,
)

FRAME_INTERVAL = 0.3  # s between the outlines drawn in a parking panel
OUTLINES_MAX = 150  # outlines a panel draws at most (a 2,000 s run drew 6,667, in 15 s)
PARKING_GIF_FPS = 20  # frames per second of motion time in a parking GIF
DEFAULT_WHEEL_RADIUS = 0.3  # m, when a trajectory records no wheel_radius
TRACK_FRACTION = 0.82  # track / body width, when a trajectory records no track
POSE_NAMES = ("x", "y", "heading", "steer")  # state variables every car file must carry
RUN_ATTRS = (
    *SCENE_ATTRS,
    "wheelbase",
    "collision_index",
    "collided_with",
    "parked",
    "parking_seconds",
    "simulated_seconds",
)
PATH_COLOR = "0.2"
TIME_SHADES = matplotlib.colormaps["Blues"]  # outlines, light (start) to dark (end)
SHADE_RANGE = (0.3, 0.95)  # the part of TIME_SHADES used


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


def read_car_trajectory(path: str | Path) -> CarTrajectory:
    """Read a car trajectory (the trajectory contract plus the car's root attributes, see the
    module docstring); PlotInputError naming the file and what is missing or malformed."""
    try:
        trajectory = read_trajectory(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    attrs = trajectory.attrs
    check_present(path, "car trajectory (root attributes)", RUN_ATTRS, attrs)
    column = state_columns(path, trajectory.state_order, POSE_NAMES)
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
    scene = read_scene(path, attrs)
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


def _start_summary(runs: Sequence[CarTrajectory]) -> list[list[str]]:
    """Per run, its start state in brief, as parts to join with commas: the variables in which
    the runs' starts differ (position, heading, steer, speed; when none differ, as for one run:
    position, heading, and steer and speed where not 0), e.g. ``["steer −30°"]`` or
    ``["from (7.9, 3.5) m", "heading 0°", "steer −30°"]``."""
    names = [n for n in STATE_UNITS if all(n in run.start() for run in runs)]
    starts = np.array([[run.start()[n] for n in names] for run in runs])
    varying = {n for k, n in enumerate(names) if np.ptp(starts[:, k]) > 1e-6}
    if not varying:
        moving = ("steer", "speed")
        varying = {"x", "heading"} | {
            n for n in moving if n in names and abs(starts[0, names.index(n)]) > 1e-6
        }
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


# --------------------------------------------------------------------------- the plots


def plot_parking_frames(
    trajectory_paths: Sequence[str | Path],
    out_path: str | Path,
    interval: float = FRAME_INTERVAL,
) -> None:
    """Write ``parking_frames_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(parking_frames_figure(trajectory_paths, interval), out_path)


def _collision_entries(runs: Sequence[CarTrajectory]) -> list[tuple[object, str]]:
    """The legend entry of a collision's red outline, if any run collides."""
    if not any(run.collided for run in runs):
        return []
    patch = Patch(facecolor=(1, 0, 0, 0.25), edgecolor=FAILURE_COLOR, linewidth=2.0)
    return [(patch, "first collision")]


def parking_frames_figure(
    trajectory_paths: Sequence[str | Path], interval: float = FRAME_INTERVAL
) -> Figure:
    """Figure 19: one panel per car trajectory (2 rows × 3 columns for six; any count works),
    each to scale in metres over the same x/y limits: the obstacles (grey), the destination
    (the car's outline at the goal, dotted), the car's outline every ``interval`` seconds
    (light to dark with time, the start and final outlines thick; for a run so long that it
    would draw more than OUTLINES_MAX, every round interval that draws 100 to 150) and the
    reference point's path.
    A run that hits an obstacle is drawn up to its first colliding sample, that outline red. Each
    panel's title: the file stem, its start state, and the outcome (a failure in red)."""
    if not trajectory_paths:
        raise PlotInputError("plot_parking_frames: no trajectories given")
    runs = [read_car_trajectory(path) for path in trajectory_paths]
    longest = max(float(run.t[-1] - run.t[0]) for run in runs)
    if longest / interval + 1 > OUTLINES_MAX:  # a long run: fewer outlines, a round interval
        interval = choose_interval(longest, (OUTLINES_MAX * 2 // 3, OUTLINES_MAX))
    samples = [drawn_samples(run.t, interval, run.collision_index) for run in runs]
    car_points = []
    for run, drawn in zip(runs, samples, strict=True):
        car_points.append(
            place_outline(run.scene.body_outline, run.x[drawn], run.y[drawn], run.heading[drawn])
        )
        car_points.append(np.column_stack([run.x[: drawn[-1] + 1], run.y[: drawn[-1] + 1]]))
        car_points.append(scene_points(run.scene))
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
        *_collision_entries(runs),
        *domain_entries([run.scene for run in runs]),
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
        layout = panel_figure(len(runs), limits, 1, title_lines, legend_rows=rows)
        for ax, run, drawn, head in zip(layout.panels, runs, samples, heads, strict=True):
            draw_scene(ax, run.scene, limits)
            _draw_manoeuvre(ax, run, drawn)
            panel_title(ax, head, outcome_text(run), run.failed)
        suptitle(layout.figure, f"The car parking under controller {_controller_names(runs)}")
        add_legend(layout.figure, legend, ncols=columns)
    return layout.figure


def write_parking_gif(
    trajectory_path: str | Path, out_path: str | Path, fps: int = PARKING_GIF_FPS
) -> None:
    """An animated GIF of one manoeuvre, to scale in metres: obstacles, the destination outline,
    the car's outline with its four wheels (short thick segments, the front pair turned by the
    steer angle), the path so far, the time and the speed. ``fps`` frames per second of motion time
    (the sample at or after each frame time, and the last, see ``samples_to_the_end``), each
    frame round(1000 / fps) ms (a run longer than REAL_TIME_MAX_FRAMES frames: a wider step,
    ``frame_step``, each frame as long, so that it still plays in real time); a run that
    collides stops at its first colliding sample, drawn red; the last frame is held GIF_HOLD_MS
    ms; loops. Frames are blitted (``animation_frames``) and written with one shared palette
    (``write_gif``)."""
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    run = read_car_trajectory(trajectory_path)
    last = len(run.t) - 1 if run.collision_index < 0 else run.collision_index
    step = frame_step(float(run.t[last] - run.t[0]), fps, REAL_TIME_MAX_FRAMES)
    samples = samples_to_the_end(run.t[: last + 1], step)
    every = np.arange(last + 1)
    limits = view_limits(
        np.concatenate(
            [
                place_outline(
                    run.scene.body_outline, run.x[every], run.y[every], run.heading[every]
                ).reshape(-1, 2),
                scene_points(run.scene),
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
        layout = panel_figure(1, limits, 0, title_lines, legend_rows=0, dpi=GIF_DPI)
        figure, ax = layout.figure, layout.panels[0]
        draw_scene(ax, run.scene, limits)
        panel_title(ax, head, outcome_text(run), failed)
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
    write_gif(frames, out_path, [round(1000 * step)] * (len(frames) - 1) + [GIF_HOLD_MS])
