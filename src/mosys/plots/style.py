"""The one base module of the plot families (the state-space plots, the car's, Luxo's, the BSR
searches', the composite's), which import it and nothing of each other's but a family's own
base (``state_space``, ``car_scene``, ``bsr_results``, ``scene3d``): the shared look (figure
sizes, fonts, markers, colours), the error a bad input raises, the sampling of a motion at
regular times, the scene views, the stick figure the BSR and composite plots and the
concatenation editor draw, the atomic PNG write and the blitted, atomically written animated GIF.

Figures are built with matplotlib's object API on an Agg canvas (no pyplot, no global figure
state), so plotting works headless and in parallel Snakemake jobs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib import patheffects
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import LinearSegmentedColormap, to_rgb, to_rgba
from matplotlib.figure import Figure
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon
from matplotlib.text import Text
from matplotlib.typing import ColorType

from mosys.errors import InputError
from mosys.io.atomic import write_atomically
from mosys.plots.frame_text import draw_text, drawable

if TYPE_CHECKING:  # the annotation only: a plot of a table need not import h5py
    from mosys.io.trajectory import Trajectory

DPI = 120  # dots per inch of every PNG
STYLE = {
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "savefig.facecolor": "white",
    "figure.facecolor": "white",
}
# state variable name -> the symbol the papers use for it
SYMBOLS = {"angle": "θ", "omega": "ω", "heading": "φ", "steer": "δ", "speed": "v"}
DESTINATION_COLOR = "black"
LEGEND_HANDLERS = {tuple: HandlerTuple(ndivide=1)}  # a tuple handle: its parts overlaid


class PlotInputError(InputError):
    """The inputs cannot make the requested plot (wrong count, wrong kind of file...)."""


@contextmanager
def plot_style() -> Iterator[None]:
    """Apply the mosys rc parameters while a figure is built and saved."""
    with matplotlib.rc_context(STYLE):
        yield


def new_figure(width: float, height: float) -> Figure:
    """A figure of ``width`` x ``height`` inches on its own Agg canvas. Its layout is set by
    ``arrange`` (fixed margins: matplotlib's constrained layout measured every text twice per
    save and cost a third of a plot job's time)."""
    figure = Figure(figsize=(width, height))
    FigureCanvasAgg(figure)
    return figure


# Margins, inches: room for tick labels and an axis label (left, bottom), one title line (top).
MARGIN_LEFT, MARGIN_RIGHT, MARGIN_BOTTOM, MARGIN_TOP = 0.8, 0.25, 0.55, 0.2
TITLE_LINE = 0.22  # inches per title line
LEGEND_SIZE = 8.5  # pt: a legend of many entries (the 3-D plots')
LEGEND_ROW = 0.21  # inches per legend row, and once more for the legend's frame
LEGEND_KEEPS = 0.5  # of the subplots' height without a legend, kept under a long one


def arrange(figure: Figure, legend_rows: int = 0) -> None:
    """Fixed margins around the subplots for the longest axes title and a legend of
    ``legend_rows`` rows below them. A legend that would leave the subplots less than
    LEGEND_KEEPS of the height they have without it makes the figure taller instead (a
    hundred entries left no room, and matplotlib raised)."""
    width, height = figure.get_size_inches()
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    title_lines = max((title.count("\n") + 1 for title in titles), default=0)
    top = MARGIN_TOP + TITLE_LINE * title_lines
    bottom = MARGIN_BOTTOM + (LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0)
    least = max(LEGEND_KEEPS * (height - top - MARGIN_BOTTOM), 0.0)  # inches for the subplots
    if height - top - bottom < least:
        height = top + bottom + least
        figure.set_size_inches(width, height)
    figure.subplots_adjust(
        left=MARGIN_LEFT / width,
        right=1 - MARGIN_RIGHT / width,
        top=1 - top / height,
        bottom=bottom / height,
    )


def keep_left_labels_in(figure: Figure, ax: Axes, pad: float = 0.08) -> None:
    """Widen the left margin, if it must be, so that ``ax``'s y tick labels and y label lie
    inside the figure (``pad`` inches from its edge): long tick labels (1.64450) pushed a
    fixed margin's label off the figure. Draws the figure once to measure them."""
    figure.canvas.draw()
    box = ax.get_tightbbox(figure.canvas.get_renderer())
    width = figure.get_size_inches()[0]
    short = pad - box.x0 / figure.dpi  # inches the labels stick out beyond the pad
    if short > 0:
        position = ax.get_position()
        figure.subplots_adjust(left=position.x0 + short / width)


FIGURE_FORMATS = ("png", "pdf", "svg")  # what a plot's file name may end in
# vertices Agg draws a long line in at a time where it cannot in one (a car run of 2,000 s at
# 1e9 m/s: OverflowError, "Exceeded cell block limit"); only then, so other plots keep their pixels
AGG_CHUNK = 10_000


def save_figure(figure: Figure, path: str | Path) -> None:
    """Write ``figure`` to ``path`` atomically (a hidden partial file, then a rename), in the
    format its extension names: PNG (DPI dots per inch), PDF or SVG; PlotInputError for any
    other extension, before anything is written."""
    extension = Path(path).suffix.lower().lstrip(".")
    if extension not in FIGURE_FORMATS:
        allowed = ", ".join(f".{name}" for name in FIGURE_FORMATS)
        raise PlotInputError(f"{path}: a plot's file name ends in {allowed}")

    def save(partial: Path) -> None:
        try:
            figure.savefig(partial, format=extension, dpi=DPI)
        except OverflowError:  # Agg's cell limit: a path too intricate to fill in one piece
            FigureCanvasAgg(figure)  # a new renderer: the failed one draws nothing more
            with matplotlib.rc_context({"agg.path.chunksize": AGG_CHUNK}):
                figure.savefig(partial, format=extension, dpi=DPI)

    write_atomically(path, save)


TEXT_LUMINANCE = 0.18  # text on white at most this luminant: contrast about 4.5 : 1


def text_color(color: ColorType) -> tuple[float, float, float]:
    """``color`` darkened, if it must be, until text in it reads on white: its relative
    luminance (WCAG) at most TEXT_LUMINANCE (a contrast of about 4.5 : 1). Pale colours of a
    20-colour cycle (tab20's light halves) drew names hard to read."""
    rgb = np.array(to_rgb(color))
    for _ in range(20):
        linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
        if float(linear @ [0.2126, 0.7152, 0.0722]) <= TEXT_LUMINANCE:
            break
        rgb = rgb * 0.9
    return float(rgb[0]), float(rgb[1]), float(rgb[2])


def counted(number: int, noun: str) -> str:
    """``1 seed``, ``3 seeds``: ``number`` and ``noun``, plural unless one."""
    return f"{number} {noun}{'' if number == 1 else 's'}"


def minus_signs(text: str) -> str:
    """A true minus sign for hyphens in numbers."""
    return text.replace("-", "−")


def number_text(value: float, fmt: str) -> str:
    """``value`` formatted by ``fmt`` with a true minus sign, and no minus on a value that
    rounds to zero (-0.004 as '.2f' is '0.00', not '−0.00')."""
    text = format(value, fmt)
    if float(text) == 0.0:
        text = format(0.0, fmt)
    return minus_signs(text)


def script_file_name(trajectory: Trajectory, path: str | Path) -> str:
    """The file name of the animation script a trajectory ran (its ``script`` attribute), else
    the trajectory file's name."""
    return Path(str(trajectory.attrs.get("script", path))).name


def unit_text(unit: str) -> str:
    """A unit as the files write it (``N*m``, ``deg/s^2``) as a label shows it (``N·m``,
    ``deg/s²``)."""
    return unit.replace("*", "·").replace("^2", "²").replace("^3", "³")


def axis_label(name: str, unit: str) -> str:
    """Axis label of a state variable: its symbol and unit, e.g. ``angle θ (deg)``."""
    symbol = SYMBOLS.get(name)
    return f"{name} {symbol} ({unit})" if symbol else f"{name} ({unit})"


def lighten(color: ColorType, amount: float) -> tuple[float, float, float, float]:
    """``color`` mixed ``amount`` (0..1) with white."""
    rgba = np.array(to_rgba(color))
    rgba[:3] += (1.0 - rgba[:3]) * float(np.clip(amount, 0.0, 1.0))
    return tuple(float(c) for c in rgba)


def controller_colors(names: Sequence[str]) -> dict[str, tuple[float, float, float, float]]:
    """One distinct colour per controller name, in the order given (tab10, then tab20)."""
    palette = matplotlib.colormaps["tab10" if len(names) <= 10 else "tab20"]
    return {name: palette(k % palette.N) for k, name in enumerate(names)}


def mark_destination(
    axes: Axes, x: float, y: float, color: ColorType = DESTINATION_COLOR, size: float = 11.0
) -> None:
    """The papers' destination marker: an encircled X at (x, y), drawn above the paths on a white
    halo so that it reads on any background."""
    for marker, scale in (("o", 1.0), ("x", 0.62)):
        axes.plot(
            x,
            y,
            marker=marker,
            markersize=size * scale,
            fillstyle="none",
            zorder=5,
            markeredgecolor="white",
            markeredgewidth=3.4,
        )
    for marker, scale in (("o", 1.0), ("x", 0.62)):
        axes.plot(
            x,
            y,
            marker=marker,
            markersize=size * scale,
            fillstyle="none",
            zorder=6,
            markeredgecolor=color,
            markeredgewidth=1.5,
        )


def destination_handle(
    color: ColorType = DESTINATION_COLOR, size: float = 11.0
) -> tuple[Line2D, Line2D]:
    """A legend handle for ``mark_destination`` (draw it with ``LEGEND_HANDLERS``)."""
    return tuple(
        Line2D(
            [],
            [],
            marker=marker,
            markersize=size * scale,
            fillstyle="none",
            markeredgecolor=color,
            markeredgewidth=1.5,
            linestyle="none",
        )
        for marker, scale in (("o", 1.0), ("x", 0.62))
    )


def mark_start(
    axes: Axes, x: float, y: float, color: ColorType, size: float = 6.0, zorder: float = 5.0
) -> None:
    """The papers' start marker: a small filled square."""
    axes.plot(x, y, **start_style(color, size), zorder=zorder)


def start_style(color: ColorType, size: float = 6.0) -> dict:
    """Line2D keywords of the start marker."""
    return {
        "marker": "s",
        "markersize": size,
        "markerfacecolor": color,
        "linestyle": "none",
        "markeredgecolor": "black",
        "markeredgewidth": 0.8,
    }


def add_legend(
    figure: Figure,
    entries: Sequence[tuple[object, str]],
    ncols: int = 3,
    fontsize: float | str | None = None,
) -> None:
    """The figure's legend from (handle, label) pairs, below the axes so that it hides no data
    (the margins are set here, see ``arrange``); a tuple handle draws its parts overlaid. In
    ``ncols`` columns, or fewer where that is wider than the figure (long labels ran off both
    its sides)."""
    handles = [handle for handle, _ in entries]
    labels = [label for _, label in entries]
    for columns in range(max(ncols, 1), 0, -1):
        legend = figure.legend(
            handles,
            labels,
            loc="lower center",
            bbox_to_anchor=(0.5, 0.005),
            ncols=columns,
            fontsize=fontsize,
            framealpha=0.9,
            handler_map=LEGEND_HANDLERS,
        )
        width = legend.get_window_extent(figure.canvas.get_renderer()).width
        if columns == 1 or width <= figure.bbox.width:
            break
        legend.remove()
    arrange(figure, legend_rows=-(-len(entries) // columns))


# --------------------------------------------------------------------------- sampling a motion


def frame_indices(t: np.ndarray, interval: float) -> np.ndarray:
    """Sample indices (int64, increasing, no repeats) of the first sample at or after each
    time t[0] + k·interval (k = 0, 1, ...) up to t[-1]. t: (N,) s, non-decreasing; interval: s.
    Times within 1e-9 s of a sample count as that sample."""
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"t must be 1-D, got shape {t.shape}")
    if not interval > 0:
        raise ValueError(f"interval must be positive, got {interval!r}")
    if len(t) == 0:
        return np.zeros(0, dtype=np.int64)
    count = math.floor((t[-1] - t[0]) / interval + 1e-9) + 1
    times = t[0] + interval * np.arange(count)
    index = np.minimum(np.searchsorted(t, times - 1e-9), len(t) - 1)
    return np.unique(index).astype(np.int64)


def samples_to_the_end(t: np.ndarray, interval: float, max_count: int | None = None) -> np.ndarray:
    """``frame_indices`` of ``t`` (N,) s every ``interval`` s and the last sample, N - 1,
    always; if that one is added, only the first ``max_count`` - 1 of the others are kept
    (None: all)."""
    samples = frame_indices(t, interval)
    if samples[-1] != len(t) - 1:
        keep = len(samples) if max_count is None else max_count - 1
        samples = np.append(samples[:keep], len(t) - 1)
    return samples


# --------------------------------------------------------------------------- scenes

# Scenes draw an articulated figure (``figure_motion``) to scale in metres, y up, over its terrain.
TERRAIN_FACE, TERRAIN_EDGE = "0.8", "0.35"
POSE_TIMES = LinearSegmentedColormap.from_list(  # poses, light (start) to dark (end)
    "pose_times", matplotlib.colormaps["YlGnBu"](np.linspace(0.3, 1.0, 256))
)
COLORBAR_SPACE = 1.05  # inches right of a scene for its colour bar and label
BARE_MARGIN = 0.15  # inches below a scene drawn without axes (no axis label to make room for)


def draw_terrain(ax: Axes, terrain: list, bottom: float) -> None:
    """The terrain polyline (``figure_motion``'s ``terrain``: [x, y] vertices, m), the ground
    below it filled grey down to ``bottom`` (m). Nothing for an empty terrain."""
    if not terrain:
        return
    ground = np.asarray(terrain, dtype=np.float64)
    below = [[ground[-1, 0], bottom], [ground[0, 0], bottom]]
    ax.add_patch(
        Polygon(np.vstack([ground, below]), closed=True, facecolor=TERRAIN_FACE, edgecolor="none")
    )
    ax.plot(ground[:, 0], ground[:, 1], color=TERRAIN_EDGE, linewidth=1.2, zorder=1.5)


def scene_figure(
    limits: np.ndarray,
    width: float,
    header_lines: int,
    legend_rows: int,
    colorbar: bool = False,
    dpi: float | None = None,
    axes_drawn: bool = True,
) -> tuple[Figure, Axes, Axes | None]:
    """A figure with one equal-aspect panel ``width`` inches wide showing ``limits``
    [[xmin, ymin], [xmax, ymax]] (m), sized in inches so that its box has their aspect: room
    above for ``header_lines`` lines of title, below for the axis label (``axes_drawn``; a
    picture without axes, such as the 3-D views, False: only BARE_MARGIN) and a legend of
    ``legend_rows`` rows, on the right for a colour bar (the returned third axes, else None)."""
    (x0, y0), (x1, y1) = limits
    height = width * (y1 - y0) / (x1 - x0)
    top = MARGIN_TOP + TITLE_LINE * header_lines + 0.1
    bottom = (MARGIN_BOTTOM if axes_drawn else BARE_MARGIN) + (
        LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0
    )
    right = MARGIN_RIGHT + (COLORBAR_SPACE if colorbar else 0.0)
    fig_width = MARGIN_LEFT + width + right
    fig_height = top + height + bottom
    figure = new_figure(fig_width, fig_height)
    if dpi is not None:
        figure.set_dpi(dpi)
    ax = figure.add_axes(
        (MARGIN_LEFT / fig_width, bottom / fig_height, width / fig_width, height / fig_height)
    )
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    bar = None
    if colorbar:
        left = (MARGIN_LEFT + width + 0.2) / fig_width
        bar = figure.add_axes((left, bottom / fig_height, 0.16 / fig_width, height / fig_height))
    return figure, ax, bar


# Views of a moving figure (Luxo's, and the BSR and composite animations'), metres.
VIEW_PADDING = 0.08  # m of blank round the figure
GROUND_PADDING = 0.04  # m of ground shown below the lowest ground in view
ASPECT_RANGE = (0.3, 0.85)  # height / width of a view; its x or y limits widen to stay inside


def _ground_range(terrain: list, x0: float, x1: float) -> tuple[float, float] | None:
    """The lowest and highest ground between x0 and x1 (m), None without terrain."""
    if not terrain:
        return None
    ground = np.asarray(terrain, dtype=np.float64)
    inside = ground[(ground[:, 0] >= x0) & (ground[:, 0] <= x1), 1]
    ends = np.interp([x0, x1], ground[:, 0], ground[:, 1])
    heights = np.concatenate([inside, ends])
    return float(heights.min()), float(heights.max())


def scene_limits(points: np.ndarray, terrain: list) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] m of a view of a figure: its ``points`` (..., 2) m with
    VIEW_PADDING all round and the ground in that range of x with GROUND_PADDING below, widened
    by ``fit_aspect``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    low, high = points.min(axis=0) - VIEW_PADDING, points.max(axis=0) + VIEW_PADDING
    limits = np.array([low, high])
    for _ in range(2):  # once more after a widening in x, which may show deeper ground
        ground = _ground_range(terrain, limits[0, 0], limits[1, 0])
        if ground is not None:
            limits[0, 1] = min(limits[0, 1], ground[0] - GROUND_PADDING)
            limits[1, 1] = max(limits[1, 1], ground[1] + VIEW_PADDING)
        limits = fit_aspect(limits)
    return limits


def fit_aspect(limits: np.ndarray, aspect_range: tuple[float, float] | None = None) -> np.ndarray:
    """``limits`` [[xmin, ymin], [xmax, ymax]] (m) widened about their centre to a height /
    width within ``aspect_range`` (None: ASPECT_RANGE): in y if too flat, in x if too tall."""
    limits = np.array(limits, dtype=np.float64)
    width, height = limits[1] - limits[0]
    least, most = ASPECT_RANGE if aspect_range is None else aspect_range
    if height < least * width:
        limits[:, 1] += np.array([-1, 1]) * (least * width - height) / 2
    elif height > most * width:
        limits[:, 0] += np.array([-1, 1]) * (height / most - width) / 2
    return limits


def pan(view: tuple[float, float], x: float) -> tuple[float, float] | None:
    """A view (xmin, xmax) m that follows a figure whose middle is at ``x`` m: None (stay) while
    ``x`` is in the view's middle half, else the view of the same width centred on ``x``."""
    x0, x1 = view
    quarter = (x1 - x0) / 4
    if x0 + quarter <= x <= x1 - quarter:
        return None
    return (x - 2 * quarter, x + 2 * quarter)


# --------------------------------------------------------------------------- stick figures

# A stick figure (the BSR and composite plots, the concatenation editor): each rod a line with
# round ends, outlined thinly, a round marker at each rod end.
ROD_WIDTH = 2.0  # pt
JOINT_SIZE = 3.4  # pt, the round marker at each rod end
OUTLINE = "0.2"  # the thin outline that keeps light poses visible on white


def draw_pose(ax: Axes, pose: np.ndarray, color: ColorType, zorder: float) -> None:
    """One pose (rods, 2, 2) m: rods as lines with round ends, outlined thinly."""
    outline = [patheffects.withStroke(linewidth=ROD_WIDTH + 1.0, foreground=OUTLINE)]
    rods = LineCollection(
        pose, colors=[color], linewidths=ROD_WIDTH, capstyle="round", zorder=zorder
    )
    rods.set_path_effects(outline)
    ax.add_collection(rods, autolim=False)
    ends = pose.reshape(-1, 2)
    ax.plot(
        ends[:, 0],
        ends[:, 1],
        "o",
        markersize=JOINT_SIZE,
        color=color,
        markeredgecolor=OUTLINE,
        markeredgewidth=0.6,
        zorder=zorder + 0.001,
    )


# Filmstrips (the BSR and composite plots): poses at regular times, to scale.
POSES = (12, 20)  # the interval is chosen so that this many poses are drawn, 16 if it can
NICE_STEPS = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)  # mantissas of a chosen interval
STRIP_MARGIN = 0.06  # inches of blank round the poses (in data units: times the m per inch)
STRIP_GROUND = 0.12  # inches of ground shown below the lowest ground point


def choose_interval(duration: float, poses: tuple[int, int] = POSES) -> float:
    """A round interval, s (1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten) at which
    between ``poses`` poses are drawn over ``duration`` s (both ends counted), as near the
    middle of that range as can be."""
    if not duration > 0:
        return 1.0
    least, most = poses
    aim = (least + most) / 2
    best = None
    scale = 10.0 ** math.floor(math.log10(duration / most))
    for power in (scale / 10, scale, scale * 10):
        for mantissa in NICE_STEPS:
            interval = mantissa * power
            count = math.floor(duration / interval + 1e-9) + 1
            if least <= count <= most:
                score = (abs(count - aim), -interval)
                if best is None or score < best[0]:
                    best = (score, interval)
    return best[1] if best else duration / (aim - 1)


def spread_labels(values: np.ndarray, gap: float, low: float, high: float) -> np.ndarray:
    """Label heights near ``values`` (data units), at least ``gap`` apart, kept in
    [low, high] where they fit."""
    values = np.asarray(values, dtype=np.float64)
    order = np.argsort(values, kind="stable")
    placed = values[order].copy()
    for k in range(1, len(placed)):
        placed[k] = max(placed[k], placed[k - 1] + gap)
    overflow = placed[-1] - high if len(placed) else 0.0
    if overflow > 0:
        placed[-1] -= overflow
        for k in range(len(placed) - 2, -1, -1):
            placed[k] = min(placed[k], placed[k + 1] - gap)
    placed = np.maximum(placed, low + gap * np.arange(len(placed)))
    out = np.empty_like(placed)
    out[order] = placed
    return out


# --------------------------------------------------------------------------- animations

GIF_DPI = 100  # dots per inch of animation frames (at 80 their text was 7 px high)
GIF_HOLD_MS = 1500  # ms the last frame of an animation stays up before the loop restarts
GIF_FPS = 25  # frames per second of motion time: a frame every 40 ms
GIF_MAX_FRAMES = 150  # a longer motion gets a wider step (``frame_samples``)
# frames of a script's or a parking run's GIF at most: one per 1/fps s of a run up to 24 s (a
# script's 25 fps) or 30 s (the car's 20 fps); a longer one gets a wider step (a 2,000 s car run
# took 2.4 GiB and over two minutes)
REAL_TIME_MAX_FRAMES = 600
FOLLOW_POSES = 3.0  # a figure ranging wider than this many pose widths is followed by the view


def check_animation_options(fps: object, max_frames: object) -> None:
    """ValueError unless ``fps`` is a positive whole number and ``max_frames`` one >= 2."""
    if not (isinstance(fps, int | np.integer) and fps > 0):
        raise ValueError(f"fps must be a positive whole number, got {fps!r}")
    if not (isinstance(max_frames, int | np.integer) and max_frames >= 2):
        raise ValueError(f"max_frames must be a whole number of at least 2, got {max_frames!r}")


def frame_step(span: float, fps: int, max_frames: int) -> float:
    """Seconds of motion a frame of an animation of ``span`` s shows: 1/fps, widened to keep
    to ``max_frames`` frames, and rounded up to whole hundredths, the unit of a GIF's frame
    durations, so that the animation plays in real time."""
    step = max(1.0 / fps, span / (max_frames - 1)) if span > 0 else 1.0 / fps
    return math.ceil(step * 100.0 - 1e-9) / 100.0


def frame_samples(t: np.ndarray, fps: int, max_frames: int) -> tuple[np.ndarray, float]:
    """The samples of ``t`` (s, non-decreasing) an animation shows, one per ``frame_step`` of
    motion time, the last sample always included; and the step, s."""
    step = frame_step(float(t[-1] - t[0]), fps, max_frames)
    return samples_to_the_end(t, step, max_frames), step


def animation_frames(
    figure: Figure,
    moving: Sequence[Artist],
    steps: Iterable,
    update: Callable[[object], bool],
) -> list:
    """RGB frames (PIL images) of ``figure``, blitted: the static part is drawn once, then for
    each item of ``steps`` ``update(item)`` sets the ``moving`` artists, which are drawn over it
    in the order given, except texts that PIL draws as matplotlib would (``frame_text``:
    unrotated, no mathtext), which PIL draws last (a changing text is most of what matplotlib
    spends on a frame). ``update`` returns True when it also changed
    the static part (the limits of a view that pans, say), which is then drawn again. Many
    times faster than matplotlib's animation writers, which redraw the whole figure for every
    frame."""
    from PIL import Image

    for artist in moving:
        artist.set_animated(True)  # left out of full draws: drawn per frame below
    canvas = figure.canvas
    canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)
    frames = []
    for step in steps:
        if update(step):
            canvas.draw()
            background = canvas.copy_from_bbox(figure.bbox)
        canvas.restore_region(background)
        texts = [a for a in moving if isinstance(a, Text) and drawable(a)]  # as they now read
        for artist in moving:
            if not any(artist is text for text in texts):
                figure.draw_artist(artist)
        rgba = np.asarray(canvas.buffer_rgba())
        frame = Image.fromarray(rgba[..., :3].copy())
        for text in texts:
            draw_text(frame, text, figure.dpi)
        frames.append(frame)
    return frames


def animate_stick_figure(
    figure: Figure,
    ax: Axes,
    t: np.ndarray,
    endpoints: np.ndarray,
    samples: np.ndarray,
    look: Callable[[int], tuple],
    label_size: float,
    follow: np.ndarray | None = None,
) -> list:
    """The frames (``animation_frames``) of a stick figure at ``samples`` of its motion (t (N,)
    s, endpoints (N, rods, 2, 2) m) on ``ax``: the rods as lines with round ends and their
    joints, the time in the top left corner and a label in the top right. ``look(frame)`` gives
    that frame's rod colour, label text and label colour; ``follow`` (frames,) m: the x the view
    keeps in sight, panning (``pan``), or None for a fixed view."""
    rods = LineCollection(
        np.zeros((endpoints.shape[1], 2, 2)), linewidths=ROD_WIDTH + 1.0, capstyle="round", zorder=3
    )
    ax.add_collection(rods, autolim=False)
    (joints,) = ax.plot([], [], "o", markersize=JOINT_SIZE + 1.5, zorder=3.1)
    box = {"boxstyle": "round,pad=0.3", "facecolor": "white", "alpha": 0.9}
    corner = {"transform": ax.transAxes, "va": "top", "bbox": box, "zorder": 10}
    clock = ax.text(0.02, 0.97, "", ha="left", fontsize=10, family="monospace", **corner)
    label = ax.text(0.98, 0.97, "", ha="right", fontsize=label_size, fontweight="bold", **corner)

    def update(frame: int) -> bool:
        sample = int(samples[frame])
        pose = endpoints[sample]
        color, text, text_color = look(frame)
        rods.set_segments(pose)
        rods.set_color(color)
        joints.set_data(pose[..., 0].ravel(), pose[..., 1].ravel())
        joints.set_color(color)
        joints.set_markeredgecolor(OUTLINE)
        clock.set_text(f"t = {t[sample]:5.2f} s")
        label.set_text(text)
        label.set_color(text_color)
        view = None if follow is None else pan(ax.get_xlim(), follow[frame])
        if view is None:
            return False
        ax.set_xlim(*view)
        return True

    return animation_frames(figure, [rods, joints, clock, label], range(len(samples)), update)


def shared_palette(frames: list) -> list:
    """The RGB ``frames`` as palette images sharing one palette of at most 256 colours: the
    colours that cover the most pixels of any one frame (a plot's solid colours first, then the
    commonest anti-aliasing shades); every other colour becomes the nearest of them. No colour
    flicker between frames, and a colour that only a few frames show (a rule active for half a
    second) keeps its own entry: a palette cut from a montage of 8 sampled frames drew such a
    rule in another rule's colour."""
    from PIL import Image

    largest: dict[tuple, int] = {}  # colour -> the most pixels it covers in one frame
    for frame in frames:
        for count, color in frame.getcolors(frame.width * frame.height):
            if count > largest.get(color, 0):
                largest[color] = count
    chosen = sorted(largest, key=lambda color: (-largest[color], color))[:256]
    palette = Image.new("P", (1, 1))
    flat = [channel for color in chosen for channel in color]
    palette.putpalette(flat + flat[:3] * (256 - len(chosen)))  # padded with the first colour
    return [frame.quantize(palette=palette, dither=Image.Dither.NONE) for frame in frames]


def write_real_time_gif(frames: list, path: str | Path, step: float) -> None:
    """Write ``frames`` shown ``step`` s of motion apart (``frame_samples``) as a GIF that plays
    in real time (at least 20 ms a frame), its last frame held GIF_HOLD_MS ms."""
    frame_ms = max(20, round(1000 * step))
    write_gif(frames, path, [frame_ms] * (len(frames) - 1) + [GIF_HOLD_MS])


def write_gif(frames: list, path: str | Path, durations: int | Sequence[int]) -> None:
    """Write the RGB ``frames`` (PIL images) as a GIF that loops forever, atomically, with one
    shared palette (``shared_palette``). durations: ms per frame, one for all or one each."""
    if not frames:
        raise ValueError("write_gif: no frames")
    frames = shared_palette(frames)
    durations = durations if isinstance(durations, int) else list(durations)

    def write(partial: Path) -> None:
        frames[0].save(
            partial,
            format="GIF",
            save_all=True,
            append_images=frames[1:],
            duration=durations,
            loop=0,
        )

    write_atomically(path, write)
