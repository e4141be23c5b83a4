"""3-D BSR searches' plots (Auslander et al. 1995, §4 "Initial Experiments with 3D Articulated
Figures": Figures 15 to 17, and Figures 7 and 8 for 3-D searches), drawn from search results
``results/bsr/NAME/seedK.h5`` whose ``best/figure_motion`` is 3-D (DESIGN.md, "Figure motion"):

- ``plot_filmstrip``: Figures 15 to 17 (Cujo bounding, Rex's walk-turn-walk, Bob walking), the
  best motion of one search, or of a chain of searches drawn as one motion, as stick figures at
  regular times over a checkered floor, seen by one camera (``choose_camera``).
- ``write_motion_gif``: the same motion animated, the same camera.
- ``plot_learning_kinds``: Figure 7 ("Learning curves for both kinds of motion controller"),
  a time-based and a sense-based search of one problem, every seed and the median of each.
- ``plot_seeds``: Figure 8 ("Variability in search-algorithm performance"), the seeds of one
  search (``mosys.plots.bsr.learning_figure``).
- ``plot_figure_at_rest``: a figure's first pose from four sides, its rods named (for the
  README; ``plot_result_at_rest`` draws a result file's).

It builds on ``mosys.plots.bsr``, the 2-D family (reading and checking result files, choosing
seeds, the learning curves, the fitness terms' text), and on ``mosys.plots.style``.

The camera is orthographic: a point (x, y, z) m (y up, the floor y = 0, the figure facing +x at
t = 0) is drawn at its distances along the picture plane's right and up axes (``project``), so
that one metre is as long wherever it is, the floor's squares all alike and the view can pan.
``VIEW`` looks from the figure's right (+z) side, turned CAMERA_AZIMUTH towards its front
(+x) and CAMERA_ELEVATION above the floor: walking forward runs left to right, a left turn heads
away from the camera, a right turn towards it. A motion's filmstrip and animation turn the
camera further towards the front where that spreads the poses out (``choose_camera``: a walk
that turns left and walks on, as Rex's, whose second walk would pile its poses up).

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
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import ListedColormap, Normalize, to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import StrMethodFormatter

from mosys.io.bsr_result import BsrResult
from mosys.io.trajectory import FigureMotion
from mosys.plots.bsr import (
    CURVE_WIDTH,
    FINALS_WIDTH,
    FOLLOW_POSES,
    KIND_LINESTYLE,
    KIND_TEXT,
    LEARNING_HEIGHT,
    LEARNING_WIDTH,
    TERMS,
    FinalsColumn,
    best_result_path,
    curves_on_grid,
    draw_finals,
    draw_seed_curve,
    fitness_formula,
    group_by_search,
    label_learning_curves,
    learning_axes,
    learning_figure,
    read_result,
    root_attrs,
    search_name,
    seed_labels,
    shared_decimals,
    terms_text,
    wrapped,
)
from mosys.plots.style import (
    GIF_DPI,
    GIF_FPS,
    GIF_MAX_FRAMES,
    JOINT_SIZE,
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_RIGHT,
    MARGIN_TOP,
    OUTLINE,
    ROD_WIDTH,
    TITLE_LINE,
    VIEW_PADDING,
    PlotInputError,
    add_legend,
    animation_frames,
    check_animation_options,
    choose_interval,
    controller_colors,
    counted,
    draw_pose,
    fit_aspect,
    frame_samples,
    mark_start,
    minus_signs,
    new_figure,
    pan,
    plot_style,
    samples_to_the_end,
    save_figure,
    scene_figure,
    spread_labels,
    text_color,
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
    **TERMS,
}
MAX_POSES = 500  # a filmstrip drawing more is a grey smear: an --interval that short is refused
LEGEND_WIDTH = 130  # characters of a filmstrip legend's line of terms
CHAIN_TOLERANCE = 1e-3  # m: a continuing search's first pose is its predecessor's last pose

# the camera
CAMERA_AZIMUTH = 30.0  # deg from the figure's right side (+z) towards its front (+x)
CAMERA_ELEVATION = 30.0  # deg above the floor
CAMERA_AZIMUTHS = tuple(np.arange(CAMERA_AZIMUTH, 61.0, 5.0))  # deg: a motion's camera's choice


@dataclass(frozen=True)
class Camera:
    """An orthographic camera looking at the world from ``azimuth`` deg round from +z towards
    +x (0: from the figure's right side, +x to the right; 90: from its front) and
    ``elevation`` deg above the floor (90: from straight above, +x to the right and -z up).
    The picture plane's right axis stays level."""

    azimuth: float = CAMERA_AZIMUTH
    elevation: float = CAMERA_ELEVATION

    def basis(self) -> np.ndarray:
        """(3, 3): rows the picture's right and up axes and the direction towards the
        camera, unit vectors in world (x, y, z)."""
        a, e = math.radians(self.azimuth), math.radians(self.elevation)
        toward = np.array([math.sin(a) * math.cos(e), math.sin(e), math.cos(a) * math.cos(e)])
        right = np.array([math.cos(a), 0.0, -math.sin(a)])
        return np.array([right, np.cross(toward, right), toward])


VIEW = Camera()  # the rest poses' camera, and a straight walk's (``choose_camera``)
SIDE, FRONT, TOP = Camera(0.0, 0.0), Camera(90.0, 0.0), Camera(0.0, 90.0)


def project(points: np.ndarray, camera: Camera = VIEW) -> np.ndarray:
    """Points (..., 3) world (x, y, z) m as the ``camera`` sees them: (..., 3), the distance
    along the picture's right axis (u, m), along its up axis (v, m) and towards the camera
    (depth, m; nearer is larger)."""
    return np.asarray(points, dtype=np.float64) @ camera.basis().T


def choose_camera(com: np.ndarray, size: float, elevation: float = CAMERA_ELEVATION) -> Camera:
    """The camera of a filmstrip and its animation: the one among CAMERA_AZIMUTHS (front right
    views) that draws the filmstrip's poses furthest apart.
    com (k, 3) m: the poses' centres of mass in order; size m: the figure's (``pose_size``).
    Each consecutive pair's distance on the picture counts by its logarithm, taken between 0.1
    and 1 times the size (poses a size apart no longer overlap, and a figure standing still
    overlaps itself from anywhere), and the largest sum wins, the first of equals: a walk
    straight forward is seen from CAMERA_AZIMUTH, and one that turns away from the camera,
    which piles its poses up there, from further round (Rex's second walk, from 50°). Every
    view is ``elevation`` deg above the floor."""
    best, best_score = Camera(CAMERA_AZIMUTH, elevation), -math.inf
    for azimuth in CAMERA_AZIMUTHS:
        camera = Camera(float(azimuth), elevation)
        gaps = np.linalg.norm(np.diff(project(com, camera)[:, :2], axis=0), axis=1)
        score = float(np.log(np.clip(gaps, 0.1 * size, size)).sum())
        if score > best_score + 1e-9:
            best, best_score = camera, score
    return best


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


# --------------------------------------------------------------------------- the floor

NICE_CELLS = (0.05, 0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 2.5, 5.0, 10.0)  # m: a floor square's side
CELLS_PER_SIZE = 5  # at most this many squares across the figure's size
FLOOR_CELLS = 30  # at most this many squares along the floor's longer side
FLOOR_MARGIN = 0.3  # of the largest pose's size: floor beyond the farthest rod end
FLOOR_LIGHT, FLOOR_DARK, FLOOR_EDGE = "0.95", "0.84", "0.55"
SHADOW_COLOR, SHADOW_ALPHA = "0.25", 0.22  # the figure's shadow, straight down on the floor


def pose_size(endpoints: np.ndarray, most: int = 200) -> float:
    """The figure's size, m: the largest distance between two rod ends of one pose, over
    ``most`` poses spread evenly through ``endpoints`` (N, rods, 2, 3) m (at least 0.1 m)."""
    picks = np.unique(np.linspace(0, len(endpoints) - 1, min(len(endpoints), most)).astype(int))
    points = np.asarray(endpoints, dtype=np.float64)[picks].reshape(len(picks), -1, 3)
    gaps = np.linalg.norm(points[:, :, None] - points[:, None], axis=-1)
    return max(float(gaps.max()), 0.1)


def floor_cells(
    points: np.ndarray, margin: float, size: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """The floor under ``points`` (..., 3) m with ``margin`` m round them, for a figure of
    ``size`` m (``pose_size``): its squares' side, m (the smallest of NICE_CELLS giving at most
    CELLS_PER_SIZE across the figure and FLOOR_CELLS along the floor's longer side), and the
    squares' edges along x and along z, m, multiples of the side (so that the squares of one
    world are the same whatever part of it is drawn)."""
    flat = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    low = flat[:, [0, 2]].min(axis=0) - margin
    high = flat[:, [0, 2]].max(axis=0) + margin
    least = max(size / CELLS_PER_SIZE, float((high - low).max()) / FLOOR_CELLS)
    cell = next((c for c in NICE_CELLS if c >= least - 1e-12), NICE_CELLS[-1])
    first = np.floor(low / cell + 1e-9)
    last = np.ceil(high / cell - 1e-9)
    x_edges = cell * np.arange(first[0], last[0] + 1)
    z_edges = cell * np.arange(first[1], last[1] + 1)
    return cell, x_edges, z_edges


def _floor_corners(x_edges: np.ndarray, z_edges: np.ndarray) -> np.ndarray:
    """(4, 3) m: the floor's corners."""
    return np.array([[x, 0.0, z] for x in x_edges[[0, -1]] for z in z_edges[[0, -1]]])


def draw_floor(
    ax: Axes, x_edges: np.ndarray, z_edges: np.ndarray, camera: Camera = VIEW
) -> PolyCollection:
    """The floor y = 0 as a checker of squares between the edges (m) along x and z, seen by
    ``camera``; returns its collection (one polygon per square)."""
    cell = float(x_edges[1] - x_edges[0]) if len(x_edges) > 1 else 1.0
    squares, colors = [], []
    for x0, x1 in zip(x_edges[:-1], x_edges[1:], strict=True):
        for z0, z1 in zip(z_edges[:-1], z_edges[1:], strict=True):
            corners = np.array([[x0, 0, z0], [x1, 0, z0], [x1, 0, z1], [x0, 0, z1]])
            squares.append(project(corners, camera)[:, :2])
            parity = (round(x0 / cell) + round(z0 / cell)) % 2
            colors.append(FLOOR_DARK if parity else FLOOR_LIGHT)
    floor = PolyCollection(squares, facecolors=colors, edgecolors="none", zorder=0.5)
    ax.add_collection(floor, autolim=False)
    rim = project(_floor_corners(x_edges, z_edges)[[0, 1, 3, 2, 0]], camera)
    ax.plot(rim[:, 0], rim[:, 1], color=FLOOR_EDGE, linewidth=0.8, zorder=0.6)
    return floor


def _shadows(poses: np.ndarray, camera: Camera) -> np.ndarray:
    """The poses' (..., rods, 2, 3) m shadows straight down on the floor, projected: (K·rods,
    2, 2)."""
    flat = np.array(poses, dtype=np.float64)
    flat[..., 1] = 0.0
    return project(flat, camera)[..., :2].reshape(-1, 2, 2)


def _draw_shadows(ax, poses: np.ndarray, camera: Camera) -> None:
    """Draw the poses' (..., rods, 2, 3) m shadows on the floor, under everything else."""
    shadows = LineCollection(
        _shadows(poses, camera),
        colors=SHADOW_COLOR,
        alpha=SHADOW_ALPHA,
        linewidths=ROD_WIDTH + 0.5,
        capstyle="round",
        zorder=1,
    )
    ax.add_collection(shadows, autolim=False)


def _drawn_pose(pose: np.ndarray, camera: Camera) -> np.ndarray:
    """A pose (rods, 2, 3) m as ``camera`` sees it, its rods farthest first: (rods, 2, 2) m."""
    seen = project(pose, camera)
    return seen[np.argsort(seen[..., 2].mean(axis=1), kind="stable"), :, :2]


def draw_axes_key(figure: Figure, box: tuple[float, float, float, float], camera: Camera) -> Axes:
    """A small key in ``box`` (figure fraction: left, bottom, width, height) of the world's x,
    y and z axes as ``camera`` sees them, each an arrow lettered at its tip."""
    key = figure.add_axes(box)
    key.set_axis_off()
    key.set_xlim(-1.35, 1.35)
    key.set_ylim(-1.35, 1.35)
    key.set_aspect("equal")
    for axis, letter in enumerate(("x", "y", "z")):
        tip = project(np.eye(3)[axis], camera)[:2]
        key.annotate(
            "",
            xy=tip,
            xytext=(0, 0),
            arrowprops={"arrowstyle": "-|>", "color": "0.2", "linewidth": 1.2},
        )
        key.text(*(tip * 1.22), letter, ha="center", va="center", fontsize=9, style="italic")
    return key


# --------------------------------------------------------------------------- the filmstrip

SCENE_WIDTH = 9.0  # inches: the filmstrip's scene
KEY_SIZE = 0.75  # inches: the axes key in the scene's top left corner
PATH_WIDTH = 2.4  # pt: the centre of mass's path on the floor
ARROW_SIZE = 0.4  # of the largest pose's size: the heading arrows' length
ARROW_COLOR = "black"
POSE_COUNT = (6, 14)  # a filmstrip's poses: the fewest and the most (``pose_count``)
POSES_PER_SIZE = 3.0  # poses per distance the figure covers as long as its size
LEGEND_SIZE = 8.5  # pt
LIGHTEST = 0.6  # a search's first pose: its colour mixed this much with white; its last pure


def search_colors(chain: ChainMotion) -> list[tuple[float, float, float, float]]:
    """One colour per search of the chain (``controller_colors`` of their names)."""
    colors = controller_colors(list(dict.fromkeys(chain.names)))
    return [colors[name] for name in chain.names]


def lighten(color: str | tuple[float, ...], amount: float) -> tuple[float, float, float, float]:
    """``color`` mixed ``amount`` (0..1) with white."""
    rgba = np.array(to_rgba(color))
    rgba[:3] += (1.0 - rgba[:3]) * float(np.clip(amount, 0.0, 1.0))
    return tuple(float(c) for c in rgba)


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


def camera_text(camera: Camera) -> str:
    """Where ``camera`` looks from, in words."""
    if camera.elevation >= 90:
        return "seen from above"
    side = {0.0: "its right side", 90.0: "its front"}.get(camera.azimuth)
    if side is None and 0 < camera.azimuth < 90:
        side = f"its front right ({camera.azimuth:g}° round from its right side)"
    elif side is None:
        side = f"azimuth {camera.azimuth:g}°"
    return f"seen from {side}, {camera.elevation:g}° above the floor"


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
    fitness = minus_signs(f"{float(result.attrs['best_fitness']):.4g}")
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
    seen = project(np.concatenate([poses.reshape(-1, 3), _floor_corners(x_edges, z_edges)]), camera)
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
        _draw_shadows(ax, poses, camera)
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
            draw_pose(
                ax, _drawn_pose(poses[j], camera), shades[samples[j]], 3 + rank / len(samples)
            )
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
    corners = project(_floor_corners(x_edges, z_edges), camera)
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
        shadows = _shadows(endpoints[samples], camera).reshape(len(samples), -1, 2, 2)

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


# --------------------------------------------------------------------------- learning curves

SEED_ALPHA, SEED_WIDTH = 0.35, 0.9  # each seed's faint line
MEDIAN_WIDTH = CURVE_WIDTH + 1.1  # pt
KIND_COLORS = controller_colors(["time", "sense"])  # one colour per controller kind
EARLY_SHARE = 0.01  # of a linear evaluation axis: the start, too narrow to be read
EARLY_MOST = 0.5  # of the y range: the most a curve's start may take before it is cut off
EARLY_PAD = 0.08  # of the range kept: room below the lowest value kept


@dataclass(frozen=True)
class CutStart:
    """Where a learning-curve plot's y axis leaves out the curves' first values: ``low`` (data
    units) the axis's bottom, ``evaluations`` the count after which every curve is above it,
    ``lowest`` the lowest value left out."""

    low: float
    evaluations: int
    lowest: float


def cut_start(results: Sequence[BsrResult], last: int) -> CutStart | None:
    """The y axis's bottom for the best-so-far curves of ``results`` drawn on a linear axis of
    ``last`` evaluations, where their first EARLY_SHARE of it would take more than EARLY_MOST
    of the y range: the lowest value held from there on, padded. A first population's
    best can lie far below everything after it (Rex's -7.7 for 60 of 60,000 evaluations, then
    0.8 and up), squeezing the curves into the top of the plot. None where nothing need be
    cut (the axis then shows every value)."""
    start = EARLY_SHARE * last
    everything = np.concatenate([r.best_fitness for r in results])
    later = np.concatenate(
        [r.best_fitness[max(np.searchsorted(r.evaluations, start, side="right") - 1, 0) :]
         for r in results]
    )  # fmt: skip
    lowest, kept, highest = float(everything.min()), float(later.min()), float(everything.max())
    if not kept - lowest > EARLY_MOST * (highest - lowest):
        return None
    low = kept - EARLY_PAD * (highest - kept)
    below = [r.evaluations[r.best_fitness < low] for r in results]
    evaluations = max((int(e[-1]) for e in below if e.size), default=0)
    return CutStart(low, evaluations, lowest)


def _note_cut_start(ax: Axes, cut: CutStart) -> None:
    """``cut``: the y axis's bottom set to it and, in the plot's lower right (where the curves,
    risen by then, leave room), what was left out."""
    ax.set_ylim(bottom=cut.low)
    ax.text(
        0.985,
        0.03,
        f"↓ below the axis: the best of the first {cut.evaluations:,} evaluations, "
        f"down to {minus_signs(f'{cut.lowest:.3g}')}",
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=8.5,
        color="0.25",
        bbox={"boxstyle": "round,pad=0.25", "facecolor": "white", "alpha": 0.85, "lw": 0},
    )


def _load_kind(paths: Sequence[str | Path], kind: str) -> tuple[str, list[BsrResult]]:
    """The results of one kind's files, checked to be of one search of that kind: (search
    name, results sorted by seed)."""
    loaded = [(read_result(path, dimensions=None), path) for path in paths]
    for result, path in loaded:
        found = str(result.attrs["controller_kind"])
        if found != kind:
            raise PlotInputError(
                f"{path}: a {KIND_TEXT.get(found, found)} search's result given as "
                f"{KIND_TEXT[kind]}"
            )
    names = sorted({search_name(result.attrs, path) for result, path in loaded})
    if len(names) > 1:
        raise PlotInputError(
            f"the {KIND_TEXT[kind]} files are of more than one search ({', '.join(names)}): "
            "give the seeds of one search per kind"
        )
    ordered = sorted((result for result, _ in loaded), key=lambda r: int(r.attrs["seed"]))
    return names[0], ordered


def plot_learning_kinds(
    time_results: Sequence[str | Path],
    sense_results: Sequence[str | Path],
    path: str | Path,
    log_x: bool = False,
) -> None:
    """Write ``learning_kinds_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(learning_kinds_figure(time_results, sense_results, log_x), path)


def _label_ends(ax, ends: list[tuple[object, float, float]], x: float) -> None:
    """Each median curve's final value, in its colour, at ``x`` beyond the longest curve's end
    and spread so that no two overlap, with a thin line from a shorter curve's end (at its own
    end a shorter curve's label sat on the longer curve)."""
    low, high = ax.get_ylim()
    height = ax.get_position().height * ax.figure.get_size_inches()[1]
    gap = (high - low) * (11.5 / 72) / height  # a label's height, data units
    heights = spread_labels(np.array([end[2] for end in ends]), gap, low + gap / 2, high - gap / 2)
    for (color, evaluations, value), label_y in zip(ends, heights, strict=True):
        ax.annotate(
            minus_signs(f"{value:.3g}"),
            (evaluations, value),
            xytext=(x, label_y),
            va="center",
            fontsize=9,
            color=color,
            fontweight="bold",
            arrowprops={"arrowstyle": "-", "color": color, "lw": 0.8, "shrinkA": 0, "shrinkB": 2},
        )
    ax.set_ylim(low, high)


def learning_kinds_figure(
    time_results: Sequence[str | Path],
    sense_results: Sequence[str | Path],
    log_x: bool = False,
) -> Figure:
    """Figure 7 ("Learning curves for both kinds of motion controller"): the best fitness so
    far against the number of controller evaluations of a time-based search and a
    sense-based search of one problem (the seed files of each; one kind may be left out): each
    seed a faint step line, the median over seeds (``curves_on_grid``, up to the fewest
    evaluations any seed ran) a bold one, time-based dashed and sense-based solid as in
    ``mosys.plots.bsr``, its final value written at its end. ``log_x``: evaluations on a log
    axis (default linear, as the paper draws them); on a linear one, a start far below the rest
    is cut off and noted (``cut_start``). The title names the
    figure, the searches and their fitness functions. PlotInputError when no file is given, a
    file is of the other kind, or one kind's files are of two searches."""
    if not time_results and not sense_results:
        raise PlotInputError("plot_learning_kinds: no BSR result files given")
    kinds = [
        (kind, *_load_kind(paths, kind))
        for kind, paths in (("time", time_results), ("sense", sense_results))
        if paths
    ]
    first = min(int(r.evaluations[0]) for _, _, results in kinds for r in results)
    last = max(int(r.evaluations[-1]) for _, _, results in kinds for r in results)
    if log_x and first <= 0:
        raise PlotInputError("plot_learning_kinds: a log axis needs evaluations above 0")
    title = _kinds_title("Learning curves for both kinds of motion controller", kinds)
    entries: list[tuple[object, str]] = []
    ends = []  # (colour, evaluations, median) at each median curve's end
    with plot_style():
        figure = new_figure(LEARNING_WIDTH, LEARNING_HEIGHT)
        ax = figure.subplots()
        for kind, name, results in kinds:
            color, style = KIND_COLORS[kind], KIND_LINESTYLE[kind]
            for result in results:
                ax.step(
                    result.evaluations,
                    result.best_fitness,
                    where="post",
                    color=color,
                    alpha=SEED_ALPHA,
                    linewidth=SEED_WIDTH,
                    linestyle=style,
                )
            grid, values = curves_on_grid(results)
            median = np.nanmedian(values, axis=0)
            ax.step(grid, median, where="post", color=color, linewidth=MEDIAN_WIDTH, ls=style)
            ends.append((color, float(grid[-1]), float(median[-1])))
            entries.append(
                (
                    Line2D([], [], color=color, linewidth=MEDIAN_WIDTH, linestyle=style),
                    f"{name} ({KIND_TEXT[kind]}): median over {counted(len(results), 'seed')}",
                )
            )
            entries.append(
                (
                    Line2D([], [], color=color, alpha=SEED_ALPHA, lw=SEED_WIDTH, ls=style),
                    f"{name}: each seed",
                )
            )
        if log_x:
            ax.set_xscale("log")
            ax.set_xlim(first / 1.2, last * 2.0)
        else:
            ax.set_xlim(0, last * 1.12 if last > 0 else 1)
            ax.xaxis.get_major_locator().set_params(integer=True)  # whole counts
            cut = cut_start([r for _, _, results in kinds for r in results], last)
            if cut is not None:
                _note_cut_start(ax, cut)
        _label_ends(ax, ends, last * (1.1 if log_x else 1.015))
        ax.xaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
        ax.set_xlabel(f"controller evaluations (count{', log scale' if log_x else ''})")
        ax.set_ylabel("best fitness so far (Σ weight × term)")
        _lay_out_kinds(figure, entries, title, above=0.1, right=0.3)
    return figure


def _lay_out_kinds(
    figure: Figure, entries: list[tuple[object, str]], title: str, above: float, right: float
) -> None:
    """The kinds' legend below the axes, ``title`` above them and the margins: ``above`` inches
    more between the title and the axes, ``right`` more at their right."""
    add_legend(figure, entries, ncols=2, fontsize=LEGEND_SIZE)
    width, height = figure.get_size_inches()
    figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=10.5)
    figure.subplots_adjust(
        top=1 - (MARGIN_TOP + above + TITLE_LINE * (title.count("\n") + 1)) / height,
        left=(MARGIN_LEFT + 0.1) / width,
        right=1 - (MARGIN_RIGHT + right) / width,
        wspace=0.05,
    )


def _kinds_title(heading: str, kinds: Sequence[tuple[str, str, list[BsrResult]]]) -> str:
    """A figure title: ``heading`` and the figures drawn, then each (kind, search, results) as
    'time-based NAME (N seeds)' joined by 'vs', then the fitness function (each search's on a
    line of its own where they differ: side by side they ran off the figure)."""
    figures = sorted({str(r.attrs.get("figure", "")) for _, _, rs in kinds for r in rs} - {""})
    formulas = {fitness_formula(results[0].fitness_weights) for _, _, results in kinds}
    versus = " vs ".join(
        f"{KIND_TEXT[kind]} {name} ({counted(len(results), 'seed')})"
        for kind, name, results in kinds
    )
    if len(formulas) == 1:
        fitness = wrapped(formulas.pop())
    else:
        fitness = "\n".join(
            wrapped(f"{name}: {fitness_formula(results[0].fitness_weights)}")
            for _, name, results in kinds
        )
    return f"{heading}{': ' + ', '.join(figures) if figures else ''}\n{wrapped(versus)}\n{fitness}"


def plot_seeds(results: Sequence[str | Path], path: str | Path) -> None:
    """Write ``seeds_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(seeds_figure(results), path)


def seeds_figure(results: Sequence[str | Path]) -> Figure:
    """Figure 8 ("Variability in search-algorithm performance"): the seeds of one search (Bob's
    sense-based walk), or of two searches of the two kinds on one problem (Bob's walk, sense-
    and time-based: the paper's finding is that the sense-based one is the better for Bob, and
    that its runs vary). One search: ``mosys.plots.bsr.learning_figure``. Two: each seed's
    learning curve in its kind's colour (sense-based solid, time-based dashed), and beside them
    each seed's final best fitness, a column per kind, on a scale of their own where they lie
    close together (``draw_finals``). PlotInputError when no file is given, or the files are of
    more than one search of a kind or more than two searches."""
    if not results:
        raise PlotInputError("plot_seeds: no BSR result files given")
    by_kind: dict[str, list[Path]] = {}
    for path in results:
        by_kind.setdefault(str(root_attrs(path).get("controller_kind", "")), []).append(Path(path))
    if len(by_kind) == 1:
        return learning_figure(results)
    unknown = sorted(set(by_kind) - set(KIND_TEXT))
    if unknown:
        raise PlotInputError(f"plot_seeds: results of an unknown controller kind {unknown[0]!r}")
    kinds = [(kind, *_load_kind(by_kind[kind], kind)) for kind in ("sense", "time")]
    title = _kinds_title("Variability in search-algorithm performance", kinds)
    entries: list[tuple[object, str]] = []
    columns = []
    with plot_style():
        figure = new_figure(LEARNING_WIDTH, LEARNING_HEIGHT)
        curves, finals = learning_axes(figure, 2 * FINALS_WIDTH - 0.7)
        right_end = max(int(r.evaluations[-1]) for _, _, rs in kinds for r in rs)
        for kind, name, kind_results in kinds:
            color, style = KIND_COLORS[kind], KIND_LINESTYLE[kind]
            seeds = [int(result.attrs["seed"]) for result in kind_results]
            for result, seed in zip(kind_results, seeds, strict=True):
                draw_seed_curve(
                    curves,
                    result,
                    right_end,
                    color=color,
                    linestyle=style,
                    label=f"{name} seed {seed}",
                )
            entries.append(
                (
                    Line2D([], [], color=color, linewidth=CURVE_WIDTH, linestyle=style),
                    f"{name} ({KIND_TEXT[kind]}): each seed",
                )
            )
            values = np.array([r.best_fitness[-1] for r in kind_results])
            median = minus_signs(f"{np.median(values):.{shared_decimals(values)}f}")
            heading = f"{KIND_TEXT[kind]}\nmedian {median}"
            labels = seed_labels(seeds, values)
            columns.append(FinalsColumn(heading, values, labels, [color] * len(values)))
        label_learning_curves(curves, right_end)
        _lay_out_kinds(figure, entries, title, above=0.3, right=0.0)
        draw_finals(curves, finals, columns)
    return figure


# --------------------------------------------------------------------------- a figure at rest

REST_VIEWS = (("side", SIDE), ("front", FRONT), ("top", TOP))  # the small views, top to bottom
REST_TITLES = {"side": "from its right side", "front": "from its front", "top": "from above"}
# the small views' axes: the world coordinate along the picture's right and up axes
REST_AXES = {"side": ("x (m)", "y (m)"), "front": ("−z (m)", "y (m)"), "top": ("x (m)", "−z (m)")}
REST_MAIN = (7.4, 6.6)  # inches: the oblique view's width and greatest height
REST_PAD = 1.2  # inches of the oblique view's height above and below its drawing
REST_SMALL = 1.75  # inches: the small views' side
REST_SMALL_GAP = 0.8  # inches above each small view: its title and the x label of the one above
REST_SMALL_LEFT = 0.75  # inches left of the small views: their y labels
REST_SMALL_LABELS = 0.45  # inches above a small view for its title, below it for its x label
REST_MAIN_TITLE = 0.3  # inches above the oblique view, where it is as wide as the figure
LABEL_COLUMN = 1.3  # inches left and right of the oblique view's drawing for the rod names
LABEL_SIZE = 9.0  # pt
LABEL_GAP = 0.2  # inches between two rod names' middles
FOOT_MARKER = "^"


@dataclass(frozen=True)
class RestLayout:
    """Where ``figure_at_rest_figure`` puts its views, in inches: the figure's ``size`` (width,
    height), the oblique view's box ``main`` and the small views' ``small`` (side, front, top),
    each (left, bottom, width, height) from the figure's bottom left corner."""

    size: tuple[float, float]
    main: tuple[float, float, float, float]
    small: tuple[tuple[float, float, float, float], ...]


def rest_layout(span: np.ndarray, title_lines: int) -> RestLayout:
    """The views of a figure at rest whose oblique drawing (floor included) spans ``span``
    (width, height, any unit) under a title of ``title_lines`` lines. The small views stand in
    a column right of the oblique view or, where that leaves less blank, in a row under it, the
    oblique view then as wide as the figure: a long, low figure (Rex, Cujo) drawn in the
    column's narrow view left wide empty bands above and below it; a tall one (Bob) keeps the
    column."""
    top = MARGIN_TOP + 0.1 + TITLE_LINE * title_lines
    main_width, most = REST_MAIN
    width = 0.2 + main_width + REST_SMALL_LEFT + REST_SMALL + MARGIN_RIGHT + 0.1
    small_row = REST_SMALL + 2 * REST_SMALL_LABELS  # inches: a small view, its title and labels

    def main_height(view_width: float) -> float:  # as tall as the drawing needs at that width
        return min(most, span[1] / span[0] * (view_width - 2 * LABEL_COLUMN) + REST_PAD)

    column_room = max(most, 3 * (REST_SMALL + REST_SMALL_GAP))  # inches under the title
    row_width = width - 0.2 - MARGIN_RIGHT
    row_main = main_height(row_width)
    if REST_MAIN_TITLE + row_main + small_row < column_room + MARGIN_BOTTOM:
        height = top + REST_MAIN_TITLE + row_main + small_row
        slot = row_width / len(REST_VIEWS)
        small = tuple(
            (0.2 + k * slot + REST_SMALL_LEFT, REST_SMALL_LABELS, REST_SMALL, REST_SMALL)
            for k in range(len(REST_VIEWS))
        )
        main = (0.2, small_row, row_width, row_main)
        return RestLayout((width, height), main, small)
    height = top + column_room + MARGIN_BOTTOM
    column_main = main_height(main_width)  # centred in the room
    main = (0.2, MARGIN_BOTTOM + (column_room - column_main) / 2, main_width, column_main)
    left = 0.2 + main_width + REST_SMALL_LEFT
    small = tuple(
        (
            left,
            height - top - (k + 1) * (REST_SMALL + REST_SMALL_GAP) + 0.45,
            REST_SMALL,
            REST_SMALL,
        )
        for k in range(len(REST_VIEWS))
    )
    return RestLayout((width, height), main, small)


def _figure_box(box: tuple[float, float, float, float], size: tuple[float, float]) -> tuple:
    """``box`` (left, bottom, width, height) inches as fractions of a figure of ``size``."""
    width, height = size
    return (box[0] / width, box[1] / height, box[2] / width, box[3] / height)


def plot_figure_at_rest(motion: FigureMotion, path: str | Path, name: str = "") -> None:
    """Write ``figure_at_rest_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(figure_at_rest_figure(motion, name), path)


def figure_at_rest_figure(motion: FigureMotion, name: str = "") -> Figure:
    """A 3-D figure at rest (``motion`` at its first sample; ``name`` for the title): large,
    seen by ``VIEW`` over a patch of checkered floor with its shadow, each rod its own colour
    and named in a column beside the drawing (a leader line to the rod's middle); and small,
    from its right side, its front and above, all three to one scale in metres, each with the
    world axes it shows. In every view the rod ends it walks on (``feet``) are triangles and
    the heading rod is drawn thicker. PlotInputError for a motion that is not 3-D or has no
    samples."""
    endpoints = np.asarray(motion.endpoints, dtype=np.float64)
    if motion.dimensions != 3 or endpoints.ndim != 4 or endpoints.shape[2:] != (2, 3):
        raise PlotInputError(
            "plot_figure_at_rest: needs a 3-D figure's motion, endpoints (N, rods, 2, 3); got "
            f"dimensions {motion.dimensions}, endpoints {endpoints.shape}"
        )
    if len(endpoints) == 0:
        raise PlotInputError("plot_figure_at_rest: the motion has no samples")
    pose = endpoints[0]
    colors = controller_colors(list(motion.rod_names))
    heading = motion.heading_rod or "(none)"
    title = (
        f"{name or 'The figure'} at rest (t = {float(motion.t[0]):g} s): "
        f"{len(motion.rod_names)} rods, {float(np.sum(motion.rod_mass)):.3g} kg, heading rod "
        f"{heading}\n▲ the rod ends it walks on; the heading rod is drawn thicker"
    )
    size = pose_size(pose[None])
    floor = floor_cells(pose, FLOOR_MARGIN * size, size)
    drawn = project(np.concatenate([pose.reshape(-1, 3), _floor_corners(*floor[1:])]))
    layout = rest_layout(np.ptp(drawn[:, :2], axis=0), title.count("\n") + 1)
    width, height = layout.size
    with plot_style():
        figure = new_figure(width, height)
        figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=11)
        main = figure.add_axes(_figure_box(layout.main, layout.size))
        _draw_rest_oblique(main, motion, pose, colors, floor)
        main.set_title(camera_text(VIEW), fontsize=10)
        seen = {view: project(pose, camera)[..., :2].reshape(-1, 2) for view, camera in REST_VIEWS}
        half = 0.55 * max(float(np.ptp(points, axis=0).max()) for points in seen.values())
        half = max(half, 0.05)  # m: every small view spans twice this, to one scale
        for (view, camera), box in zip(REST_VIEWS, layout.small, strict=True):
            ax = figure.add_axes(_figure_box(box, layout.size))
            middle = (seen[view].min(axis=0) + seen[view].max(axis=0)) / 2
            if view != "top":  # the floor at the bottom of the view, a little of it showing
                middle[1] = max(middle[1], 0.9 * half)
            ax.set_xlim(middle[0] - half, middle[0] + half)
            ax.set_ylim(middle[1] - half, middle[1] + half)
            ax.set_aspect("equal")
            if view != "top":
                ax.axhspan(-2 * half, 0.0, color=FLOOR_DARK, zorder=0.5)
                ax.axhline(0.0, color=FLOOR_EDGE, linewidth=1.0, zorder=0.6)
            _draw_rest_pose(ax, motion, pose, colors, camera)
            xlabel, ylabel = REST_AXES[view]
            ax.set_xlabel(xlabel, labelpad=1)
            ax.set_ylabel(ylabel, labelpad=1)
            ax.tick_params(labelsize=7.5)
            ax.set_title(REST_TITLES[view], fontsize=9.5)
    return figure


def plot_result_at_rest(result_path: str | Path, path: str | Path) -> None:
    """``plot_figure_at_rest`` of a 3-D BSR result's best motion, named by its ``figure``."""
    result = read_result(result_path, dimensions=3)
    plot_figure_at_rest(result.motion, path, str(result.attrs.get("figure", "")))


def _draw_rest_pose(
    ax: Axes, motion: FigureMotion, pose: np.ndarray, colors: dict, camera: Camera
) -> np.ndarray:
    """The rods of ``pose`` (rods, 2, 3) m seen by ``camera``, the farthest first, each in its
    colour with round ends, the heading rod thicker, the feet marked; returns the projected
    pose (rods, 2, 3)."""
    seen = project(pose, camera)
    names = list(motion.rod_names)
    for rank, rod in enumerate(np.argsort(seen[..., 2].mean(axis=1), kind="stable")):
        width = ROD_WIDTH + (2.5 if names[rod] == motion.heading_rod else 1.0)
        ax.plot(
            seen[rod, :, 0],
            seen[rod, :, 1],
            color=colors[names[rod]],
            linewidth=width,
            solid_capstyle="round",
            marker="o",
            markersize=JOINT_SIZE,
            markeredgecolor=OUTLINE,
            markeredgewidth=0.5,
            zorder=3 + rank / len(names),
        )
    for rod, end in motion.feet:
        ax.plot(
            seen[rod, end, 0],
            seen[rod, end, 1],
            FOOT_MARKER,
            color="black",
            markersize=7,
            markerfacecolor="white",
            markeredgewidth=1.3,
            zorder=5,
        )
    return seen


def _draw_rest_oblique(
    ax: Axes, motion: FigureMotion, pose: np.ndarray, colors: dict, floor: tuple
) -> None:
    """The large view of ``figure_at_rest_figure``: the ``floor`` (``floor_cells``), the
    shadow, the rods and their names in a column each side (rods left of the middle named on
    the left), LABEL_COLUMN inches wide, the names spread apart (``spread_labels``) and joined
    to their rods."""
    cell, x_edges, z_edges = floor
    ax.set_axis_off()
    draw_floor(ax, x_edges, z_edges)
    _draw_shadows(ax, pose[None], VIEW)
    seen = _draw_rest_pose(ax, motion, pose, colors, VIEW)
    drawn = np.concatenate([seen.reshape(-1, 3), project(_floor_corners(x_edges, z_edges))])
    low, high = drawn[:, :2].min(axis=0), drawn[:, :2].max(axis=0)
    centre = (low + high) / 2
    box = ax.get_position()
    inches = np.array([box.width, box.height]) * ax.figure.get_size_inches()
    room = inches - [2 * LABEL_COLUMN, REST_PAD]  # inches for the drawing
    scale = float(max((high - low) / room))  # m per inch
    ax.set_xlim(centre[0] - inches[0] * scale / 2, centre[0] + inches[0] * scale / 2)
    ax.set_ylim(centre[1] - inches[1] * scale / 2, centre[1] + inches[1] * scale / 2)
    ax.set_aspect("equal")
    middles = seen[..., :2].mean(axis=1)
    names = list(motion.rod_names)
    reach = (high[0] - low[0]) / 2 + 0.1 * scale
    y_low, y_high = ax.get_ylim()
    for side in (-1, 1):
        rods = [r for r in range(len(names)) if (middles[r, 0] >= centre[0]) == (side > 0)]
        if not rods:
            continue
        column = centre[0] + side * reach
        heights = spread_labels(middles[rods, 1], LABEL_GAP * scale, y_low, y_high)
        for rod, y in zip(rods, heights, strict=True):
            color = colors[names[rod]]
            ax.plot(
                [middles[rod, 0], column], [middles[rod, 1], y], color=color, lw=0.7, zorder=2.5
            )
            ax.text(
                column + side * 0.05 * scale,
                y,
                names[rod],
                ha="left" if side > 0 else "right",
                va="center",
                fontsize=LABEL_SIZE,
                color=text_color(color),
                fontweight="bold",
                zorder=6,
            )
    ax.text(0.02, 0.02, f"floor squares {cell:g} m", transform=ax.transAxes, color="0.3")
    width, height = ax.figure.get_size_inches()
    # the key in the bottom left corner, above the floor's note: in the top left it sat on the
    # names of the left column
    bottom = box.y0 + 0.3 / height
    draw_axes_key(ax.figure, (box.x0, bottom, KEY_SIZE / width, KEY_SIZE / height), VIEW)
