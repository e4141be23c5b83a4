"""Luxo the lamp's plots (van de Panne, Fiume & Vranesic 1990, §7), drawn from a script's
trajectory with ``figure_motion`` and ``contacts`` (``mosys.io.trajectory``):

- ``plot_motion_strip``: Figure 22, one motion (a backflip, say) as a strip of the lamp's poses
  every few hundredths of a second over the terrain.
- ``write_show_gif``: an animated GIF of the whole trajectory, the motion and what drives it named.
- ``plot_torques_and_forces``: the joint torques and the ground's forces over time, the motions
  marked.

The lamp is drawn from ``figure_motion``: the base (rod 0) thick, the arms thinner, and the head
a lamp shade whose mouth is at the far end of the rod named ``upper`` (the last rod if none is),
where the head's contact point is; the terrain polyline filled grey below. Metres in the world
frame, y up, equal aspect. Luxo faces -x, so the base's proximal end (fraction 0) is its front
edge. A motion is one of ``mosys.animation.motion_measures.motions``: from a motor program's
start to the next one's, the landing included.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize, to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon
from matplotlib.transforms import blended_transform_factory

from mosys.animation.motion_measures import Motion, motions
from mosys.errors import InputError
from mosys.io.trajectory import Trajectory, read_trajectory
from mosys.plots.style import (
    ASPECT_RANGE,
    GIF_DPI,
    GIF_FPS,
    MARGIN_LEFT,
    POSE_TIMES,
    TERRAIN_EDGE,
    TERRAIN_FACE,
    PlotInputError,
    add_legend,
    animation_frames,
    arrange,
    check_animation_options,
    controller_colors,
    draw_terrain,
    fit_aspect,
    frame_indices,
    frame_samples,
    new_figure,
    number_text,
    pan,
    plot_style,
    save_figure,
    scene_figure,
    scene_limits,
    script_file_name,
    write_real_time_gif,
)

HEAD_ROD = "upper"  # the rod whose far end carries the head
BASE_WIDTH = 6.0  # pt, the base's line
ARM_WIDTH = 2.6  # pt, the arms' lines
HEAD_LENGTH = 0.06  # m, the lamp shade from its neck to its mouth, along the upper rod
HEAD_MOUTH = 0.032  # m, half the shade's mouth
HEAD_NECK = 0.008  # m, half the shade's neck
COM_COLOR = "#d62728"  # the centre of mass's path in the strip
TIMELINE_LABEL_SIZE, TIMELINE_LABEL_MIN = 8.5, 6.0  # pt, a motion's name on the timeline
CHAR_WIDTH = 0.6  # ems: a character's width, about, in the plots' sans-serif font
STRIP_EVERY = 0.1  # s between the poses of a strip (at 0.05 a backflip in place was a pile)
STILL_DISTANCE = 0.005  # m: a strip leaves out a pose no end of which moved this far
STRIP_WIDTH = 7.5  # inches, the strip's data area
GIF_WIDTH = 6.0  # inches, the animation's data area
SHOW_MAX_FRAMES = 600  # frames of the show GIF at most: a longer show gets a wider step
FOLLOW_WIDTH = 3.0  # m: a lamp ranging wider in x is followed by a view this wide (at least)
SERIES_WIDTH = 7.2  # inches, the data area of the time series
SIDE_LEGEND = 2.0  # inches right of the time series for their legends
WEIGHT_COLOR = "0.35"
# line colours of the time series, apart from the motions' colours (tab10) of the timeline
TORQUE_COLORS = ("black", "#7570b3", "#66a61e")
CONTACT_COLORS = ("#1b9e77", "#e7298a", "#a6761d", "#e6ab02", "#666666")
KIND_TEXT = {"motor": "motor program", "controller": "controller"}


# --------------------------------------------------------------------------- reading the inputs


def read_luxo_trajectory(path: str | Path, contacts: bool = False) -> Trajectory:
    """Read a trajectory with a ``figure_motion`` group sampled at ``/t`` (and a ``contacts``
    group if ``contacts``); PlotInputError naming the file and what is missing or malformed."""
    try:
        trajectory = read_trajectory(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    samples = len(trajectory.t)
    if samples == 0:
        raise PlotInputError(f"{path}: the trajectory has no samples")
    figure = trajectory.motion
    if figure is None:
        raise PlotInputError(f"{path}: no figure_motion group: not an articulated figure")
    if figure.endpoints.ndim != 4 or figure.endpoints.shape[0] != samples:
        raise PlotInputError(
            f"{path}: figure_motion/endpoints has shape {figure.endpoints.shape}, expected "
            f"({samples}, rods, 2, 2): one row per sample of /t"
        )
    if contacts:
        if trajectory.contacts is None:
            raise PlotInputError(f"{path}: no contacts group: the figure has no contact points")
        if trajectory.contacts.force.shape[0] != samples:
            raise PlotInputError(
                f"{path}: contacts/force has {trajectory.contacts.force.shape[0]} rows, "
                f"/t {samples}"
            )
    if trajectory.control.shape != (samples, len(trajectory.control_names)):
        raise PlotInputError(
            f"{path}: /control has shape {trajectory.control.shape}, expected ({samples}, "
            f"{len(trajectory.control_names)}) for {list(trajectory.control_names)}"
        )
    return trajectory


def find_motion(trajectory: Trajectory, name: str | None, path: str | Path = "") -> Motion:
    """The motion called ``name``: ``NAME`` its first run, ``NAME:K`` its K-th (a script that
    runs ``hop`` twice: ``hop:2``); None: the trajectory's first motion. ValueError (a
    PlotInputError) listing the motions there are, with how often each runs, when there is
    none such."""
    found = motions(trajectory)
    if not found:
        raise PlotInputError(f"{path}: no motion to draw: it runs no motor program")
    if name is None:
        return found[0]
    wanted, _, count = name.partition(":")
    runs = [motion for motion in found if motion.name == wanted]
    if not count:
        count = "1"
    if count.isdecimal() and 1 <= int(count) <= len(runs):
        return runs[int(count) - 1]
    times = Counter(motion.name for motion in found)
    there = ", ".join(
        motion if n == 1 else f"{motion} (runs {n} times: {motion}:1..{motion}:{n})"
        for motion, n in times.items()
    )
    raise PlotInputError(f"{path}: no motion called {name!r} (--motion); its motions: {there}")


def head_rod(names: Sequence[str]) -> int:
    """The index of the rod carrying the head: ``upper``, else the last rod."""
    return names.index(HEAD_ROD) if HEAD_ROD in names else len(names) - 1


def net_rotation(trajectory: Trajectory, motion: Motion) -> float:
    """The base's net rotation over ``motion``, deg, counter-clockwise positive (a backflip:
    about -360): the state column ``base`` at the motion's last sample minus its first, else
    the base rod's angle, unwrapped."""
    first, last = motion.start, motion.end - 1
    if "base" in trajectory.state_order:
        base = trajectory.state[:, trajectory.state_order.index("base")]
        return float(base[last] - base[first])
    ends = trajectory.motion.endpoints[first : last + 1, 0]
    along = ends[:, 1] - ends[:, 0]
    angle = np.unwrap(np.arctan2(along[:, 1], along[:, 0]))
    return float(np.degrees(angle[-1] - angle[0]))


def contact_labels(
    rods: Sequence[str], fraction: Sequence[float], base: str = "base", head: str = HEAD_ROD
) -> list[str]:
    """A label per contact point from its rod and where along it (0 proximal, 1 distal). Luxo
    faces -x: the ``base`` rod's proximal end is its front edge, its distal end its back edge;
    the ``head`` rod's distal end is the head."""
    labels = []
    for rod, where in zip(rods, fraction, strict=True):
        if rod == base and where in (0.0, 1.0):
            labels.append(f"{rod} {'front' if where == 0.0 else 'back'} edge")
        elif rod == head and where == 1.0:
            labels.append("head")
        else:
            labels.append(f"{rod} at {where:g} of its length")
    return labels


def strip_samples(
    t: np.ndarray, endpoints: np.ndarray, first: int, last: int, every: float
) -> np.ndarray:
    """The samples a strip draws between ``first`` and ``last`` (both drawn): one every
    ``every`` seconds (see ``frame_indices``), leaving out each pose none of
    whose rod ends moved STILL_DISTANCE m or more from the last pose kept (a lamp at rest is
    drawn once). t: (N,) s; endpoints: (N, rods, 2, 2) m."""
    candidates = np.append(frame_indices(t[first : last + 1], every) + first, last)
    kept = [int(candidates[0])]
    for sample in candidates[1:-1]:
        moved = np.abs(endpoints[sample] - endpoints[kept[-1]]).max()
        if moved >= STILL_DISTANCE:
            kept.append(int(sample))
    if last != kept[-1]:
        kept.append(last)
    return np.asarray(kept, dtype=np.int64)


# --------------------------------------------------------------------------- drawing the lamp


def head_outline(proximal: np.ndarray, distal: np.ndarray) -> np.ndarray:
    """The lamp shade of a pose: a trapezoid from a narrow neck HEAD_LENGTH back along the
    upper rod to its mouth, centred on the rod's distal end. proximal, distal: (..., 2) m, the
    upper rod's ends; returns (..., 4, 2) m."""
    proximal = np.asarray(proximal, dtype=np.float64)
    distal = np.asarray(distal, dtype=np.float64)
    along = distal - proximal
    length = np.linalg.norm(along, axis=-1, keepdims=True)
    unit = along / np.where(length > 0, length, 1.0)
    normal = np.stack([-unit[..., 1], unit[..., 0]], axis=-1)
    neck = distal - HEAD_LENGTH * unit
    corners = (
        neck + HEAD_NECK * normal,
        distal + HEAD_MOUTH * normal,
        distal - HEAD_MOUTH * normal,
        neck - HEAD_NECK * normal,
    )
    return np.stack(corners, axis=-2)


class _Lamp:
    """The lamp's artists: its rods (a line collection, the base thick) and its head."""

    def __init__(self, ax: Axes, rods: int, head: int, color, zorder: float):
        self.head_index = head
        self.rods = LineCollection(
            np.zeros((rods, 2, 2)),
            linewidths=[BASE_WIDTH] + [ARM_WIDTH] * (rods - 1),
            colors=[color],
            capstyle="round",
            zorder=zorder,
        )
        ax.add_collection(self.rods, autolim=False)
        self.head = Polygon(
            np.zeros((4, 2)),
            closed=True,
            facecolor=color,
            edgecolor="0.15",
            linewidth=0.5,
            zorder=zorder + 0.01,
        )
        ax.add_patch(self.head)

    @property
    def artists(self) -> list:
        return [self.rods, self.head]

    def place(self, endpoints: np.ndarray) -> None:
        """Put the lamp at one pose, endpoints (rods, 2, 2) m."""
        self.rods.set_segments(endpoints)
        upper = endpoints[self.head_index]
        self.head.set_xy(head_outline(upper[0], upper[1]))

    def paint(self, color) -> None:
        self.rods.set_color(color)
        self.head.set_facecolor(color)


# --------------------------------------------------------------------------- the plots


def plot_motion_strip(
    trajectory_path: str | Path,
    out_path: str | Path,
    motion: str | None,
    every: float = STRIP_EVERY,
) -> None:
    """Write ``motion_strip_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(motion_strip_figure(trajectory_path, motion, every), out_path)


def motion_strip_figure(
    trajectory_path: str | Path, motion: str | None, every: float = STRIP_EVERY
) -> Figure:
    """Figure 22 ("A Luxo back-flip"): the first motion called ``motion`` (None: the first
    motion) in one panel, to
    scale in metres: the terrain (filled grey), the lamp every ``every`` seconds from the
    motion's start to its last sample (the landing included; a pose that hardly moved from the
    last one drawn is left out, see ``strip_samples``), light to dark with the time since the
    motion began (colour bar, s), and the path of its centre of mass. The title gives the
    base's net rotation (deg, from the state column ``base``). ValueError (PlotInputError) if
    the trajectory has no such motion."""
    if not every > 0:
        raise ValueError(f"every must be a positive number of seconds, got {every!r}")
    trajectory = read_luxo_trajectory(trajectory_path)
    chosen = find_motion(trajectory, motion, trajectory_path)
    figure_motion = trajectory.motion
    t, endpoints = trajectory.t, figure_motion.endpoints
    first, last = chosen.start, chosen.end - 1
    samples = strip_samples(t, endpoints, first, last, every)
    elapsed = t[samples] - t[first]
    span = float(t[last] - t[first])
    norm = Normalize(0.0, span if span > 0 else 1.0)
    head = head_rod(figure_motion.rod_names)
    shades = head_outline(endpoints[samples, head, 0], endpoints[samples, head, 1])
    com = figure_motion.com[first : last + 1]
    limits = scene_limits(
        np.concatenate([endpoints[samples].reshape(-1, 2), shades.reshape(-1, 2), com]),
        figure_motion.terrain,
    )
    rotation = number_text(net_rotation(trajectory, chosen), ".0f")
    title = (
        f"Luxo: {chosen.name} (net base rotation {rotation}°)\n"
        f"poses every {every:g} s from t = {t[first]:.2f} s to {t[last]:.2f} s, "
        "the landing included"
    )
    legend = [
        (Patch(facecolor=TERRAIN_FACE, edgecolor=TERRAIN_EDGE), "ground"),
        (
            Line2D([], [], color=POSE_TIMES(0.6), linewidth=ARM_WIDTH),
            f"Luxo every {every:g} s (once when still), light → dark",
        ),
        (Line2D([], [], color=COM_COLOR, linestyle=":", linewidth=1.2), "centre of mass"),
    ]
    with plot_style():
        figure, ax, bar = scene_figure(limits, STRIP_WIDTH, 2, legend_rows=1, colorbar=True)
        draw_terrain(ax, figure_motion.terrain, limits[0, 1] - 1.0)
        ax.plot(com[:, 0], com[:, 1], color=COM_COLOR, linestyle=":", linewidth=1.2, zorder=2.5)
        rods = endpoints.shape[1]
        for k, sample in enumerate(samples):
            lamp = _Lamp(ax, rods, head, POSE_TIMES(norm(elapsed[k])), 3 + k / len(samples))
            lamp.place(endpoints[sample])
        figure.colorbar(
            ScalarMappable(norm, POSE_TIMES), cax=bar, label="time since the motion began (s)"
        )
        ax.set_title(title)
        add_legend(figure, legend, ncols=3)
    return figure


def _motion_at(found: Sequence[Motion], samples: np.ndarray) -> np.ndarray:
    """(K,) the index into ``found`` of the motion each sample belongs to, -1 for none."""
    index = np.full(len(samples), -1, dtype=np.int64)
    for k, motion in enumerate(found):
        index[(samples >= motion.start) & (samples < motion.end)] = k
    return index


def write_show_gif(
    trajectory_path: str | Path,
    out_path: str | Path,
    fps: int = GIF_FPS,
    max_frames: int = SHOW_MAX_FRAMES,
) -> None:
    """An animated GIF of the whole trajectory, to scale in metres: the terrain, the lamp
    coloured by what drives it (legend), and in the title the time, the motion (``k of n``) and
    the motor program or controller driving. One frame per 1/``fps`` s of motion time, played
    in real time; a longer trajectory gets a wider step to keep to ``max_frames`` frames. The
    view shows all the x the lamp covers, or, when that is wider than FOLLOW_WIDTH m (or the
    view's height over ASPECT_RANGE's largest, if more), a window that wide which pans to keep
    the lamp in its middle half (``pan``). The last frame is held GIF_HOLD_MS
    ms; loops. Written atomically."""
    check_animation_options(fps, max_frames)
    trajectory = read_luxo_trajectory(trajectory_path)
    figure_motion = trajectory.motion
    t, endpoints = trajectory.t, figure_motion.endpoints
    samples, step = frame_samples(t, int(fps), int(max_frames))
    head = head_rod(figure_motion.rod_names)
    kinds = [str(kind) for kind in trajectory.attrs.get("controller_kinds", [])]
    kinds += ["controller"] * (len(trajectory.controllers) - len(kinds))
    colors = controller_colors(trajectory.controllers)
    found = motions(trajectory)
    motion_index = _motion_at(found, samples)
    drivers = trajectory.controller[samples]
    shades = head_outline(endpoints[samples, head, 0], endpoints[samples, head, 1])
    limits = scene_limits(
        np.concatenate([endpoints[samples].reshape(-1, 2), shades.reshape(-1, 2)]),
        figure_motion.terrain,
    )
    ends = endpoints[samples, :, :, 0].reshape(len(samples), -1)
    centre = (ends.min(axis=1) + ends.max(axis=1)) / 2  # the middle of the lamp's x, m
    window = max(FOLLOW_WIDTH, (limits[1, 1] - limits[0, 1]) / ASPECT_RANGE[1])  # m
    follow = limits[1, 0] - limits[0, 0] > window
    if follow:
        limits[:, 0] = centre[0] + np.array([-0.5, 0.5]) * window
        limits = fit_aspect(limits)
    shown = list(dict.fromkeys(int(d) for d in drivers))
    legend = [
        (
            Line2D([], [], color=colors[trajectory.controllers[d]], linewidth=ARM_WIDTH + 1),
            f"{trajectory.controllers[d]} ({KIND_TEXT.get(kinds[d], kinds[d])})",
        )
        for d in shown
    ]
    ncols = min(2, len(legend))
    with plot_style():
        figure, ax, _ = scene_figure(
            limits, GIF_WIDTH, 3, legend_rows=-(-len(legend) // ncols), dpi=GIF_DPI
        )
        draw_terrain(ax, figure_motion.terrain, limits[0, 1] - 1.0)
        figure.suptitle(
            f"Luxo: {script_file_name(trajectory, trajectory_path)}",
            y=1 - 0.08 / figure.get_size_inches()[1],
            va="top",
        )
        title = ax.set_title(" \n ", fontsize=10)
        lamp = _Lamp(ax, endpoints.shape[1], head, "black", 3)
        add_legend(figure, legend, ncols=ncols)

        def update(frame: int) -> bool:
            sample = int(samples[frame])
            lamp.place(endpoints[sample])
            driver = int(drivers[frame])
            name = trajectory.controllers[driver]
            lamp.paint(colors[name])
            k = int(motion_index[frame])
            what = f"motion {k + 1} of {len(found)}: {found[k].name}" if k >= 0 else "no motion"
            title.set_text(
                f"t = {t[sample]:5.2f} s   {what}\n"
                f"driven by the {KIND_TEXT.get(kinds[driver], kinds[driver])} {name}"
            )
            view = pan(ax.get_xlim(), centre[frame]) if follow else None
            if view is None:
                return False
            ax.set_xlim(*view)
            return True

        frames = animation_frames(figure, [*lamp.artists, title], range(len(samples)), update)
    write_real_time_gif(frames, out_path, step)


def _program_end(trajectory: Trajectory, motion: Motion) -> int:
    """The sample where the motion's own program stops driving (its end if it never does)."""
    driver = trajectory.controller[motion.start : motion.end]
    changes = np.flatnonzero(driver != driver[0])
    return motion.start + (int(changes[0]) if changes.size else len(driver))


def _fitted_label(name: str, width: float) -> tuple[str, float]:
    """A motion's name and font size (pt) for a timeline bar ``width`` points wide: the name
    at TIMELINE_LABEL_SIZE, smaller down to TIMELINE_LABEL_MIN if it is wider than the bar,
    and then broken at its underscores (at full size the last of the show's names ran off the
    axes as 'backflip_down_ste')."""

    def fits(text: str, size: float) -> bool:
        longest = max(len(line) for line in text.splitlines())
        return CHAR_WIDTH * size * longest + size <= width

    for text in (name, name.replace("_", "_\n")):
        for size in np.arange(TIMELINE_LABEL_SIZE, TIMELINE_LABEL_MIN - 0.01, -0.5):
            if fits(text, float(size)):
                return text, float(size)
    return name.replace("_", "_\n"), TIMELINE_LABEL_MIN


def _mark_motions(
    axes: Sequence[Axes], timeline: Axes, trajectory: Trajectory, found: Sequence[Motion]
) -> list[tuple[object, str]]:
    """Shade each motion's span on ``axes`` (alternate motions a light grey, a dashed line at
    each start) and on ``timeline`` a bar per motion in its program's colour, solid while the
    program drives and faded while a controller lands the figure, named in the middle.
    Returns legend entries for the timeline."""
    t = trajectory.t
    colors = controller_colors(trajectory.controllers)
    final = len(t) - 1
    points_per_second = SERIES_WIDTH * 72 / max(float(t[-1] - t[0]), 1e-9)  # the axes' xlim
    landing = []
    for k, motion in enumerate(found):
        start, stop = t[motion.start], t[min(motion.end, final)]
        switch = t[min(_program_end(trajectory, motion), final)]
        for ax in axes:
            if k % 2 == 0:
                ax.axvspan(start, stop, color="0.93", zorder=0, linewidth=0)
            ax.axvline(start, color="0.55", linestyle="--", linewidth=0.8, zorder=0.5)
        color = colors[motion.name]
        timeline.axvspan(start, switch, color=color, linewidth=0)
        timeline.axvspan(switch, stop, color=to_rgba(color, 0.3), linewidth=0)
        timeline.axvline(start, color="white", linewidth=1.5)
        label, size = _fitted_label(motion.name, (stop - start) * points_per_second)
        timeline.text(
            (start + stop) / 2,
            0.5,
            label,
            transform=blended_transform_factory(timeline.transData, timeline.transAxes),
            ha="center",
            va="center",
            fontsize=size,
            linespacing=0.9,
            clip_on=True,
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.8, "lw": 0},
        )
        driven = trajectory.controller[motion.start : motion.end]
        landing += [trajectory.controllers[d] for d in np.unique(driven) if d != driven[0]]
    if not found:
        return []
    grey = "0.45"
    entries: list[tuple[object, str]] = [(Patch(color=grey), "motor program driving")]
    if landing:
        names = ", ".join(dict.fromkeys(landing))
        noun = "controller" if len(set(landing)) == 1 else "controllers"
        entries.append((Patch(color=to_rgba(grey, 0.3)), f"then {noun} {names}"))
    return entries


def plot_torques_and_forces(trajectory_path: str | Path, out_path: str | Path) -> None:
    """Write ``torques_and_forces_figure`` as a PNG to ``out_path``."""
    with plot_style():
        save_figure(torques_and_forces_figure(trajectory_path), out_path)


def torques_and_forces_figure(trajectory_path: str | Path) -> Figure:
    """The lamp's actuation and ground contact over the whole trajectory, three panels on one
    time axis (s): a timeline of the motions (a bar each, named, solid while its motor
    program drives, faded while the landing controller does); the joint torques (each
    ``/control`` column, N·m); and the magnitude of the ground's force on each contact point
    (N, on a scale linear to 10 N and logarithmic above, with the lamp's weight for
    reference), labelled base front edge, base back edge and head. The motions' spans are
    shaded on both data panels."""
    trajectory = read_luxo_trajectory(trajectory_path, contacts=True)
    t = trajectory.t
    contacts = trajectory.contacts
    figure_motion = trajectory.motion
    found = motions(trajectory)
    force = np.linalg.norm(contacts.force, axis=2)
    labels = contact_labels(
        contacts.rods,
        contacts.fraction,
        figure_motion.rod_names[0],
        figure_motion.rod_names[head_rod(figure_motion.rod_names)],
    )
    weight = float(np.sum(figure_motion.rod_mass) * figure_motion.gravity)
    with plot_style():
        figure = new_figure(MARGIN_LEFT + SERIES_WIDTH + SIDE_LEGEND, 7.0)
        timeline, torques, forces = figure.subplots(
            3, 1, sharex=True, gridspec_kw={"height_ratios": [0.1, 1, 1], "hspace": 0.12}
        )
        entries = _mark_motions([torques, forces], timeline, trajectory, found)
        timeline.set_ylim(0, 1)
        timeline.set_yticks([])
        timeline.grid(False)
        timeline.set_ylabel("motion", rotation=0, ha="right", va="center")
        script = script_file_name(trajectory, trajectory_path)
        timeline.set_title(f"Luxo's joint torques and ground forces: {script}")
        if entries:
            timeline.legend(
                *zip(*entries, strict=True),
                loc="center left",
                bbox_to_anchor=(1.01, 0.5),
                frameon=False,
            )
        else:
            timeline.text(
                0.5,
                0.5,
                "no motor program runs",
                transform=timeline.transAxes,
                ha="center",
                va="center",
                fontsize=8.5,
            )
        for j, name in enumerate(trajectory.control_names):
            color = TORQUE_COLORS[j % len(TORQUE_COLORS)]
            torques.plot(t, trajectory.control[:, j], color=color, linewidth=1.0, label=name)
        torques.axhline(0.0, color="0.3", linewidth=0.6, zorder=1)
        torques.set_ylabel("joint torque (N·m)")
        torques.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), title="actuator")
        for c, label in enumerate(labels):
            color = CONTACT_COLORS[c % len(CONTACT_COLORS)]
            forces.plot(t, force[:, c], color=color, linewidth=1.0, label=label)
        forces.axhline(
            weight,
            color=WEIGHT_COLOR,
            linestyle=":",
            linewidth=1.2,
            label=f"Luxo's weight, {weight:.1f} N",
        )
        forces.set_yscale("symlog", linthresh=10.0, linscale=1.0)
        forces.set_ylim(bottom=0.0)
        forces.set_ylabel("ground force |F| (N)\nlinear to 10, log above")
        forces.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), title="contact point")
        forces.set_xlabel("time t (s)")
        forces.set_xlim(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0)
        arrange(figure)
        width, height = figure.get_size_inches()
        figure.subplots_adjust(
            left=(MARGIN_LEFT + 0.3) / width, right=1 - SIDE_LEGEND / width, top=1 - 0.45 / height
        )
    return figure
