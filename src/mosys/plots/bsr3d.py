"""3-D BSR searches' plots (Auslander et al. 1995, §4 "Initial Experiments with 3D Articulated
Figures": Figures 15 to 17), drawn from search results
``results/bsr/NAME/seedK.h5`` whose ``best/figure_motion`` is 3-D (DESIGN.md, "Figure motion"):

- ``plot_filmstrip``: Figures 15 to 17 (Cujo bounding, Rex's walk-turn-walk, Bob walking), the
  best motion of one search, or of a chain of searches drawn as one motion, as stick figures at
  regular times over a checkered floor, seen by one camera (``choose_camera``).
- ``write_motion_gif``: the same motion animated, the same camera.

Their learning curves (Figures 7 and 8) are ``mosys.plots.bsr3d_learning``'s, the figure at rest
``mosys.plots.figure_at_rest``'s. It builds on ``mosys.plots.bsr``, the 2-D family (reading and
checking result files, choosing seeds, the fitness terms' text), on ``mosys.plots.scene3d``
(the camera, the floor, the shadows) and on ``mosys.plots.style``.

A chain (Rex's walk, then his turn from where the walk ends, then his walk again) is given as
its files in order, one per search, each search's ``chain`` attribute naming the one before it
and ``chain_seed`` that one's seed; they must join up (``join_chain``). ``chain_paths`` picks a
chain's files from all the seeds of its searches.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import ListedColormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from mosys.io.bsr_result import BsrResult
from mosys.io.trajectory import FigureMotion
from mosys.plots.bsr_results import (
    KIND_TEXT,
    best_result_path,
    group_by_search,
    motion_fitness,
    read_result,
    root_attrs,
    search_name,
    terms_text,
    wrapped,
)
from mosys.plots.scene3d import (
    CAMERA_ELEVATION,
    FLOOR_MARGIN,
    KEY_SIZE,
    SHADOW_ALPHA,
    SHADOW_COLOR,
    Camera,
    camera_text,
    choose_camera,
    draw_axes_key,
    draw_floor,
    draw_shadows,
    drawn_pose,
    floor_cells,
    floor_corners,
    pose_size,
    project,
    shadow_segments,
)
from mosys.plots.style import (
    FOLLOW_POSES,
    GIF_DPI,
    GIF_FPS,
    GIF_MAX_FRAMES,
    JOINT_SIZE,
    LEGEND_SIZE,
    OUTLINE,
    ROD_WIDTH,
    VIEW_PADDING,
    PlotInputError,
    add_legend,
    animation_frames,
    check_animation_options,
    choose_interval,
    controller_colors,
    draw_pose,
    fit_aspect,
    frame_samples,
    lighten,
    mark_start,
    number_text,
    pan,
    plot_style,
    samples_to_the_end,
    save_figure,
    scene_figure,
    write_real_time_gif,
)

# fitness terms of the 3-D searches: (label, unit, format), in the order the captions give them
TERMS_3D = {
    "distance": ("distance", "m", "+.2f"),
    "sideways": ("sideways", "m", ".2f"),
    "heading_change": ("heading change", "deg", "+.1f"),
    "max_height": ("max height", "m", ".2f"),
    "heading_deviation": ("heading deviation", "deg", ".1f"),
    "feet_distance": ("feet distance", "m", "+.2f"),
    "foot_steps": ("foot steps", "", ".0f"),
    "min_height": ("min height", "m", ".2f"),
    "heading_sine": ("sin(heading change)", "", "+.2f"),
    "final_spin": ("final spin", "deg/s", ".0f"),
    "net_rotation": ("net rotation", "deg", ".1f"),
}
MAX_POSES = 500  # a filmstrip drawing more is a grey smear: an --interval that short is refused
LEGEND_WIDTH = 130  # characters of a filmstrip legend's line of terms
CHAIN_TOLERANCE = 1e-3  # m: a continuing search's first pose is its predecessor's last pose

# --------------------------------------------------------------------------- reading a chain


@dataclass(frozen=True)
class ChainMotion:
    """The best motions of a chain of searches (or of one search) joined into one: ``motion``
    the joined ``figure_motion`` (t (N,) s from 0, endpoints (N, rods, 2, 3) m, com (N, 3) m;
    the rest the first file's); ``segment`` (N,) int64 the search each sample belongs to (a
    sample where one search hands over to the next: the earlier); ``starts`` (S,) int64 the
    sample each search starts at; and per search its result, file and name."""

    motion: FigureMotion
    segment: np.ndarray
    starts: np.ndarray
    results: tuple[BsrResult, ...]
    paths: tuple[Path, ...]
    names: tuple[str, ...]


def join_chain(paths: Sequence[str | Path]) -> ChainMotion:
    """Read the best motions of a chain of searches, one file per search in order (a single
    file: one search), and join them. PlotInputError unless every file is a 3-D BSR result of
    the same figure, with a heading rod among its rods, each after the first continuing the one
    before it: its ``chain`` is that one's search name, its ``chain_seed`` that one's seed, and
    its first pose is that one's last (within CHAIN_TOLERANCE m at every rod end)."""
    if not paths:
        raise PlotInputError("no BSR result files given")
    results = [read_result(path, dimensions=3) for path in paths]
    names = [search_name(result.attrs, path) for result, path in zip(results, paths, strict=True)]
    first = results[0].motion
    if first.heading_rod not in first.rod_names:
        raise PlotInputError(
            f"{paths[0]}: best/figure_motion's heading_rod {first.heading_rod!r} is not one of "
            f"its rods {', '.join(first.rod_names)}"
        )
    times, endpoints, coms, segments, starts = [], [], [], [], []
    end = 0.0
    for k, (result, path) in enumerate(zip(results, paths, strict=True)):
        motion = result.motion
        skip = 0
        if k:
            _check_continues(result, path, results[k - 1], paths[k - 1], names[k - 1])
            skip = 1  # its first sample is the last of the one before
        if motion.rod_names != first.rod_names:
            raise PlotInputError(
                f"{path}: its figure's rods {', '.join(motion.rod_names)} are not those of "
                f"{paths[0]} ({', '.join(first.rod_names)})"
            )
        starts.append(sum(len(t) for t in times) - skip)
        times.append(motion.t[skip:] - motion.t[0] + end)
        endpoints.append(motion.endpoints[skip:])
        coms.append(motion.com[skip:])
        segments.append(np.full(len(motion.t) - skip, k, dtype=np.int64))
        end = float(times[-1][-1]) if len(times[-1]) else end
    joined = dataclasses.replace(
        first,
        t=np.concatenate(times),
        endpoints=np.concatenate(endpoints),
        com=np.concatenate(coms),
    )
    return ChainMotion(
        joined,
        np.concatenate(segments),
        np.array(starts, dtype=np.int64),
        tuple(results),
        tuple(Path(path) for path in paths),
        tuple(names),
    )


def _check_continues(
    result: BsrResult, path: str | Path, before: BsrResult, before_path: str | Path, name: str
) -> None:
    """PlotInputError unless ``result`` continues ``before`` (search ``name``)."""
    chain = str(result.attrs.get("chain", ""))
    this = search_name(result.attrs, path)
    if chain != name:
        continues = f"continues {chain!r}" if chain else "continues no search"
        raise PlotInputError(
            f"{path}: search {this} {continues}, so it cannot follow {before_path} (search "
            f"{name}): give a chain's files in order, each search after the one it continues"
        )
    seed, before_seed = int(result.attrs.get("chain_seed", 0)), int(before.attrs["seed"])
    if seed != before_seed:
        raise PlotInputError(
            f"{path}: search {this} continues seed {seed} of {name}, not seed {before_seed} "
            f"({before_path})"
        )
    gap = np.linalg.norm(result.motion.endpoints[0] - before.motion.endpoints[-1], axis=-1)
    if gap.max() > CHAIN_TOLERANCE:
        raise PlotInputError(
            f"{path}: its first pose is {gap.max():.3g} m from the last pose of {before_path} "
            f"(at most {CHAIN_TOLERANCE:g} m: a chained search starts where the one it "
            "continues ends)"
        )


def chain_paths(paths: Sequence[str | Path]) -> list[Path]:
    """The files of a chain, one per search, from the seed files of its searches (grouped by
    search name, the searches in the order first met): the last search's best seed
    (``best_result_path``), and before each chosen file the seed it continues (its
    ``chain_seed``) of the search before, if it continues that search; else that search's best
    seed (``join_chain`` then reports the break)."""
    if not paths:
        raise PlotInputError("no BSR result files given")
    groups = list(group_by_search(paths).items())
    chosen = [best_result_path(groups[-1][1])]
    for name, files in reversed(groups[:-1]):
        after = root_attrs(chosen[0])
        if str(after.get("chain", "")) != name:
            chosen.insert(0, best_result_path(files))
            continue
        seed = int(after.get("chain_seed", 0))
        matches = [path for path in files if int(root_attrs(path).get("seed", -1)) == seed]
        if not matches:
            raise PlotInputError(
                f"{chosen[0]}: continues seed {seed} of {name}, which is not among its files "
                f"given: {', '.join(str(path) for path in files)}"
            )
        chosen.insert(0, matches[0])
    return chosen


def headings(motion: FigureMotion) -> np.ndarray:
    """The figure's heading at each sample, (N,) deg, unwrapped: the direction of its
    ``heading_rod``'s horizontal (x, z) projection, proximal to distal, plus its
    ``heading_offset``, counter-clockwise seen from above (+x 0, -z +90)."""
    rod = motion.rod_names.index(motion.heading_rod)
    along = motion.endpoints[:, rod, 1] - motion.endpoints[:, rod, 0]
    angle = np.unwrap(np.arctan2(-along[:, 2], along[:, 0]))
    return np.degrees(angle) + motion.heading_offset


# --------------------------------------------------------------------------- the filmstrip

SCENE_WIDTH = 9.0  # inches: the filmstrip's scene
PATH_WIDTH = 2.4  # pt: the centre of mass's path on the floor
ARROW_SIZE = 0.4  # of the largest pose's size: the heading arrows' length
ARROW_COLOR = "black"
POSE_COUNT = (6, 14)  # a filmstrip's poses: the fewest and the most (``pose_count``)
POSES_PER_SIZE = 3.0  # poses per distance the figure covers as long as its size
LIGHTEST = 0.6  # a search's first pose: its colour mixed this much with white; its last pure


def search_colors(chain: ChainMotion) -> list[tuple[float, float, float, float]]:
    """One colour per search of the chain (``controller_colors`` of their names)."""
    colors = controller_colors(list(dict.fromkeys(chain.names)))
    return [colors[name] for name in chain.names]


def pose_colors(chain: ChainMotion) -> list[tuple[float, float, float, float]]:
    """The colour of the pose at each sample (N): its search's colour, mixed LIGHTEST with
    white at the search's start, pure at its end."""
    t = chain.motion.t
    ends = np.array([*chain.starts[1:], len(t) - 1])
    start, end = t[chain.starts][chain.segment], t[ends][chain.segment]
    span = np.where(end > start, end - start, 1.0)
    fraction = np.clip((t - start) / span, 0.0, 1.0)
    colors = search_colors(chain)
    return [
        lighten(colors[k], LIGHTEST * (1.0 - f))
        for k, f in zip(chain.segment, fraction, strict=True)
    ]


def time_colormap(chain: ChainMotion, steps: int = 256) -> ListedColormap:
    """The pose colours (``pose_colors``) as a colour map over the time of the joined motion,
    from 0 to its end, for a colour bar of time."""
    t = chain.motion.t
    times = np.linspace(t[0], t[-1], steps)
    samples = np.minimum(np.searchsorted(t, times), len(t) - 1)
    colors = pose_colors(chain)
    return ListedColormap([colors[s] for s in samples])


def _chain_title(chain: ChainMotion) -> str:
    """The first title line: the figure and its searches."""
    figure_name = str(chain.results[0].attrs.get("figure", "")) or "the figure"
    if len(chain.names) == 1:
        return f"{figure_name}: the best motion of BSR search {chain.names[0]}"
    return f"{figure_name}: the chained BSR searches {' → '.join(chain.names)}"


def _segment_label(chain: ChainMotion, k: int) -> str:
    """A search's legend entry: its name, controller, seed, time span (s) in the joined
    motion, best fitness and measured terms."""
    result = chain.results[k]
    kind = str(result.attrs["controller_kind"])
    t = chain.motion.t
    start = float(t[chain.starts[k]])
    end = float(t[chain.starts[k + 1]] if k + 1 < len(chain.starts) else t[-1])
    fitness = number_text(motion_fitness(result.attrs), ".4g")
    label = (
        f"{chain.names[k]}: {KIND_TEXT.get(kind, kind)} controller, seed "
        f"{int(result.attrs['seed'])}, t {start:g}–{end:.3g} s, fitness {fitness}"
    )
    if "fitness_terms" not in result.attrs:
        return label
    terms = wrapped(terms_text(result.fitness_terms, TERMS_3D), LEGEND_WIDTH)
    return f"{label}\n    " + terms.replace("\n", "\n    ")


def pose_count(chain: ChainMotion) -> int:
    """How many poses a filmstrip of ``chain`` draws: one, and POSES_PER_SIZE more for each
    ``pose_size`` the figure covers, between POSE_COUNT. What it covers, m: the length of its
    centre of mass's path on the floor (sampled every 0.1 s, so that the sway of each step
    counts little) and, for each search, half its size times the net change of its heading,
    rad (a turn on the spot sweeps its ends round)."""
    motion = chain.motion
    size = pose_size(motion.endpoints)
    samples = samples_to_the_end(motion.t, 0.1)
    floor = motion.com[samples][:, [0, 2]]
    path = float(np.linalg.norm(np.diff(floor, axis=0), axis=1).sum())
    heading = headings(motion)
    ends = [*chain.starts[1:], len(motion.t) - 1]
    turned = sum(
        abs(heading[end] - heading[start]) for start, end in zip(chain.starts, ends, strict=True)
    )
    covered = path + size / 2 * math.radians(turned)
    least, most = POSE_COUNT
    return int(np.clip(round(1 + POSES_PER_SIZE * covered / size), least, most))


def _arrow(ax: Axes, base: np.ndarray, heading: float, length: float, camera: Camera) -> None:
    """An arrow on the floor from ``base`` (3,) m, ``length`` m along ``heading`` deg."""
    angle = math.radians(heading)
    tip = base + length * np.array([math.cos(angle), 0.0, -math.sin(angle)])
    ends = project(np.array([base, tip]), camera)[:, :2]
    ax.annotate(
        "",
        xy=ends[1],
        xytext=ends[0],
        arrowprops={
            "arrowstyle": "-|>",
            "color": ARROW_COLOR,
            "linewidth": 1.5,
            "mutation_scale": 13,
            "shrinkA": 0,
            "shrinkB": 0,
        },
        zorder=1.4,  # under the path of the centre of mass: a head shows past it
    )


def plot_filmstrip(
    result_paths: Sequence[str | Path],
    path: str | Path,
    interval: float | None = None,
    camera: Camera | None = None,
    elevation: float = CAMERA_ELEVATION,
) -> None:
    """Write ``filmstrip_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(filmstrip_figure(result_paths, interval, camera, elevation), path)


def default_interval(chain: ChainMotion) -> float:
    """A filmstrip's interval between poses, s, where none is given: a round one
    (``choose_interval``) giving about ``pose_count`` poses."""
    count = pose_count(chain)
    duration = float(chain.motion.t[-1] - chain.motion.t[0])
    return choose_interval(duration, (max(count - 2, 2), count + 2))


def filmstrip_figure(
    result_paths: Sequence[str | Path],
    interval: float | None = None,
    camera: Camera | None = None,
    elevation: float = CAMERA_ELEVATION,
) -> Figure:
    """Figures 15 to 17: the best motion of a 3-D search, or of a chain of them in order
    (``join_chain``) drawn as one, seen by ``camera``: the figure's rods (lines with round
    ends, the nearer drawn over the farther) every ``interval`` s and at the end (None: a
    round interval, ``choose_interval``, giving about ``pose_count`` poses), coloured by
    search, light to dark through each (``pose_colors``; the colour bar maps them to time, s,
    a line across it where one search hands over to the next), their shadows straight down,
    the path of the centre of mass on the floor coloured by search, a square at its start and
    a dot at each hand-over, an arrow of the heading at each search's start and at the end,
    over a checkered floor covering the motion (its squares' side in the subtitle), a key of
    the world axes in the corner. The title names the figure and the searches; the legend
    gives each search's controller, seed, time span, fitness and measured terms. camera None:
    ``choose_camera`` for the poses drawn, ``elevation`` deg above the floor."""
    chain = join_chain(result_paths)
    motion = chain.motion
    t = motion.t
    duration = float(t[-1] - t[0])
    if interval is None:
        interval = default_interval(chain)
    if not interval > 0:
        raise ValueError(f"interval must be a positive number of seconds, got {interval!r}")
    if duration / interval > MAX_POSES:  # before a time is listed for each pose
        raise PlotInputError(
            f"{result_paths[-1]}: poses every {interval:g} s over {duration:g} s make more than "
            f"{MAX_POSES} poses; expected an interval of at least {duration / MAX_POSES:g} s"
        )
    samples = samples_to_the_end(t, interval)
    poses = motion.endpoints[samples]
    size = pose_size(motion.endpoints)
    if camera is None:
        camera = choose_camera(motion.com[samples], size, elevation)
    cell, x_edges, z_edges = floor_cells(motion.endpoints, FLOOR_MARGIN * size, size)
    seen = project(np.concatenate([poses.reshape(-1, 3), floor_corners(x_edges, z_edges)]), camera)
    limits = fit_aspect(
        np.array([seen[:, :2].min(axis=0) - VIEW_PADDING, seen[:, :2].max(axis=0) + VIEW_PADDING])
    )
    colors = search_colors(chain)
    entries = [
        (Line2D([], [], color=colors[k], linewidth=PATH_WIDTH), _segment_label(chain, k))
        for k in range(len(chain.names))
    ]
    chained = len(chain.names) > 1
    title = (
        f"{_chain_title(chain)}\n"
        f"poses every {interval:g} s from 0 s to {t[-1]:.3g} s"
        f"{', coloured by search' if chained else ''}, light → dark, with their shadows; "
        "the centre of mass's path on the floor "
        f"{'(■ start, ● hand-over)' if chained else '(■ its start)'}\n"
        f"arrows: the heading at the start{' of each search' if chained else ''} and at the "
        f"end; floor squares {cell:g} m\n{camera_text(camera)}"
    )
    legend_rows = sum(label.count("\n") + 1 for _, label in entries)
    norm = Normalize(0.0, duration if duration > 0 else 1.0)
    shades = pose_colors(chain)
    with plot_style():
        figure, ax, bar = scene_figure(
            limits,
            SCENE_WIDTH,
            title.count("\n") + 1,
            legend_rows,
            colorbar=True,
            axes_drawn=False,
        )
        ax.set_axis_off()
        height = figure.get_size_inches()[1]
        figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=10)
        draw_floor(ax, x_edges, z_edges, camera)
        draw_shadows(ax, poses, camera)
        floor_com = motion.com * np.array([1.0, 0.0, 1.0])
        ends = [*chain.starts[1:], len(t) - 1]
        heading = headings(motion)
        for sample in [*chain.starts, len(t) - 1]:
            _arrow(ax, floor_com[sample], heading[sample], ARROW_SIZE * size, camera)
        for k, color in enumerate(colors):
            piece = project(floor_com[chain.starts[k] : ends[k] + 1], camera)
            ax.plot(piece[:, 0], piece[:, 1], color=color, linewidth=PATH_WIDTH, zorder=1.5)
            if k:  # where this search takes over
                ax.plot(*piece[0, :2], "o", color=color, mec="white", ms=7, mew=1.2, zorder=1.7)
        start = project(floor_com[0], camera)
        mark_start(ax, start[0], start[1], colors[0], size=7.0, zorder=1.7)
        depth = project(motion.com[samples], camera)[:, 2]
        for rank, j in enumerate(np.argsort(depth, kind="stable")):  # the farthest first
            draw_pose(ax, drawn_pose(poses[j], camera), shades[samples[j]], 3 + rank / len(samples))
        add_legend(figure, entries, ncols=1, fontsize=LEGEND_SIZE)
        figure.colorbar(ScalarMappable(norm, time_colormap(chain)), cax=bar, label="time t (s)")
        for sample in chain.starts[1:]:
            bar.axhline(t[sample], color="black", linewidth=1.4)
        box = ax.get_position()
        width = figure.get_size_inches()[0]
        draw_axes_key(
            figure,
            (box.x0, box.y1 - KEY_SIZE / height, KEY_SIZE / width, KEY_SIZE / height),
            camera,
        )
    return figure


# --------------------------------------------------------------------------- the animation

GIF_WIDTH = 6.0  # inches, the scene's data area
FOLLOW_HEIGHT = 0.6  # height / width of a view that pans
FAR_LIGHTER = 0.5  # the farthest rod of a pose is mixed this much with white, the nearest not


def write_motion_gif(
    result_paths: Sequence[str | Path],
    path: str | Path,
    fps: int = GIF_FPS,
    max_frames: int = GIF_MAX_FRAMES,
    camera: Camera | None = None,
    elevation: float = CAMERA_ELEVATION,
) -> None:
    """An animated GIF of the best motion of a 3-D search, or of a chain of them in order
    (``join_chain``), seen by ``camera`` as in ``filmstrip_figure``: the checkered floor, the
    centre of mass's path on it coloured by search, the figure's shadow and its rods coloured
    by search (the farther rods of a pose lighter, FAR_LIGHTER at most, drawn first), and in
    the corners the time (s) and the search's name. One frame per 1/``fps`` s of motion time
    (``frame_samples``: every 40 ms by default, the step widened to keep to ``max_frames``
    frames), played in real time; the last frame held; loops. A motion ranging wider or taller
    than FOLLOW_POSES times the figure's size is followed by a view that pans
    (``mosys.plots.style.pan``). Written atomically. camera None: the filmstrip's
    (``choose_camera`` for the poses of ``default_interval``, ``elevation`` deg up)."""
    check_animation_options(fps, max_frames)
    chain = join_chain(result_paths)
    motion = chain.motion
    t, endpoints = motion.t, motion.endpoints
    samples, step = frame_samples(t, int(fps), int(max_frames))
    size = pose_size(endpoints)
    if camera is None:
        posed = samples_to_the_end(t, default_interval(chain))
        camera = choose_camera(motion.com[posed], size, elevation)
    cell, x_edges, z_edges = floor_cells(endpoints, FLOOR_MARGIN * size, size)
    seen = project(endpoints[samples], camera)  # (frames, rods, 2, 3)
    corners = project(floor_corners(x_edges, z_edges), camera)
    points = np.concatenate([seen.reshape(-1, 3), corners])
    limits = fit_aspect(
        np.array([points[:, :2].min(axis=0), points[:, :2].max(axis=0)]) + [[-0.1], [0.1]]
    )
    flat = seen[..., :2].reshape(len(samples), -1, 2)
    centre = (flat.min(axis=1) + flat.max(axis=1)) / 2  # (frames, 2) m
    window = FOLLOW_POSES * size * np.array([1.0, FOLLOW_HEIGHT])  # m: a view that pans
    follow = bool(np.any(np.ptp(flat.reshape(-1, 2), axis=0) > window))
    if follow:
        limits = fit_aspect(centre[0] + np.array([-0.5, 0.5])[:, None] * window)
    colors = search_colors(chain)
    segment = chain.segment[samples]
    title = (
        f"{_chain_title(chain)}\n"
        f"rods{' coloured by search' if len(chain.names) > 1 else ''} (the farther ones "
        "lighter), their shadows on the floor\n"
        f"floor squares {cell:g} m; {camera_text(camera)}; played in real time"
    )
    with plot_style():
        figure, ax, _ = scene_figure(
            limits, GIF_WIDTH, title.count("\n") + 1, 0, dpi=GIF_DPI, axes_drawn=False
        )
        ax.set_axis_off()
        figure.suptitle(title, y=1 - 0.08 / figure.get_size_inches()[1], va="top", fontsize=8)
        draw_floor(ax, x_edges, z_edges, camera)
        floor_com = project(motion.com * np.array([1.0, 0.0, 1.0]), camera)
        ends = [*chain.starts[1:], len(t) - 1]
        for k, color in enumerate(colors):
            piece = floor_com[chain.starts[k] : ends[k] + 1]
            ax.plot(piece[:, 0], piece[:, 1], color=color, linewidth=1.6, alpha=0.6)
        shadow = LineCollection(
            np.zeros((endpoints.shape[1], 2, 2)),
            colors=SHADOW_COLOR,
            alpha=SHADOW_ALPHA + 0.1,
            linewidths=ROD_WIDTH + 1.0,
            capstyle="round",
            zorder=2,
        )
        rods = LineCollection(
            np.zeros((endpoints.shape[1], 2, 2)),
            linewidths=ROD_WIDTH + 1.0,
            capstyle="round",
            zorder=3,
        )
        for artist in (shadow, rods):
            ax.add_collection(artist, autolim=False)
        (joints,) = ax.plot([], [], "o", markersize=JOINT_SIZE + 1.0, zorder=3.1, color=OUTLINE)
        box = {"boxstyle": "round,pad=0.3", "facecolor": "white", "alpha": 0.9}
        corner = {"transform": ax.transAxes, "va": "top", "bbox": box, "zorder": 10}
        clock = ax.text(0.02, 0.97, "", ha="left", fontsize=10, family="monospace", **corner)
        label = ax.text(0.98, 0.97, "", ha="right", fontsize=11, fontweight="bold", **corner)
        shadows = shadow_segments(endpoints[samples], camera).reshape(len(samples), -1, 2, 2)

        def update(frame: int) -> bool:
            pose = seen[frame]
            order = np.argsort(pose[..., 2].mean(axis=1), kind="stable")
            depth = pose[order, :, 2].mean(axis=1)
            spread = depth[-1] - depth[0]
            far = (depth[-1] - depth) / spread if spread > 1e-9 else np.zeros(len(depth))
            color = colors[int(segment[frame])]
            rods.set_segments(pose[order, :, :2])
            rods.set_color([lighten(color, FAR_LIGHTER * f) for f in far])
            joints.set_data(pose[..., 0].ravel(), pose[..., 1].ravel())
            shadow.set_segments(shadows[frame])
            clock.set_text(f"t = {t[samples[frame]]:5.2f} s")
            label.set_text(chain.names[int(segment[frame])])
            label.set_color(color)
            if not follow:
                return False
            views = [pan(ax.get_xlim(), centre[frame, 0]), pan(ax.get_ylim(), centre[frame, 1])]
            if views == [None, None]:
                return False
            if views[0] is not None:
                ax.set_xlim(*views[0])
            if views[1] is not None:
                ax.set_ylim(*views[1])
            return True

        frames = animation_frames(
            figure, [shadow, rods, joints, clock, label], range(len(samples)), update
        )
    write_real_time_gif(frames, path, step)
