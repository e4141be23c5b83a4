"""The shared look of mosys plots: figure sizes, fonts, markers, colours, the atomic PNG write and
the blitted, atomically written animated GIF.

Figures are built with matplotlib's object API on an Agg canvas (no pyplot, no global figure
state), so plotting works headless and in parallel Snakemake jobs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LinearSegmentedColormap
from matplotlib.figure import Figure
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon

from mosys.io.atomic import write_atomically

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
LEGEND_ROW = 0.21  # inches per legend row, and once more for the legend's frame


def arrange(figure: Figure, legend_rows: int = 0) -> None:
    """Fixed margins around the subplots for the longest axes title and a legend of
    ``legend_rows`` rows below them."""
    width, height = figure.get_size_inches()
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    title_lines = max((title.count("\n") + 1 for title in titles), default=0)
    top = MARGIN_TOP + TITLE_LINE * title_lines
    bottom = MARGIN_BOTTOM + (LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0)
    figure.subplots_adjust(
        left=MARGIN_LEFT / width,
        right=1 - MARGIN_RIGHT / width,
        top=1 - top / height,
        bottom=bottom / height,
    )


def save_png(figure: Figure, path: str | Path) -> None:
    """Write ``figure`` as a PNG to ``path`` atomically (a hidden partial file, then a rename)."""
    write_atomically(path, lambda partial: figure.savefig(partial, format="png", dpi=DPI))


def axis_label(name: str, unit: str) -> str:
    """Axis label of a state variable: its symbol and unit, e.g. ``angle θ (deg)``."""
    symbol = SYMBOLS.get(name)
    return f"{name} {symbol} ({unit})" if symbol else f"{name} ({unit})"


def controller_colors(names: Sequence[str]) -> dict[str, tuple[float, float, float, float]]:
    """One distinct colour per controller name, in the order given (tab10, then tab20)."""
    palette = matplotlib.colormaps["tab10" if len(names) <= 10 else "tab20"]
    return {name: palette(k % palette.N) for k, name in enumerate(names)}


def mark_destination(axes: Axes, x: float, y: float, color=DESTINATION_COLOR, size=11.0) -> None:
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


def destination_handle(color=DESTINATION_COLOR, size: float = 11.0) -> tuple[Line2D, Line2D]:
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


def mark_start(axes: Axes, x: float, y: float, color, size: float = 6.0, zorder=5.0) -> None:
    """The papers' start marker: a small filled square."""
    axes.plot(x, y, **start_style(color, size), zorder=zorder)


def start_style(color, size: float = 6.0) -> dict:
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
    figure: Figure, entries: Sequence[tuple[object, str]], ncols: int = 3, fontsize=None
) -> None:
    """The figure's legend from (handle, label) pairs, below the axes so that it hides no data
    (the margins are set here, see ``arrange``); a tuple handle draws its parts overlaid."""
    handles = [handle for handle, _ in entries]
    labels = [label for _, label in entries]
    figure.legend(
        handles,
        labels,
        loc="lower center",
        bbox_to_anchor=(0.5, 0.005),
        ncols=ncols,
        fontsize=fontsize,
        framealpha=0.9,
        handler_map=LEGEND_HANDLERS,
    )
    arrange(figure, legend_rows=-(-len(entries) // ncols))


# --------------------------------------------------------------------------- scenes

# Scenes draw an articulated figure (``figure_motion``) to scale in metres, y up, over its terrain.
TERRAIN_FACE, TERRAIN_EDGE = "0.8", "0.35"
POSE_TIMES = LinearSegmentedColormap.from_list(  # poses, light (start) to dark (end)
    "pose_times", matplotlib.colormaps["YlGnBu"](np.linspace(0.3, 1.0, 256))
)
COLORBAR_SPACE = 1.05  # inches right of a scene for its colour bar and label


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
) -> tuple[Figure, Axes, Axes | None]:
    """A figure with one equal-aspect panel ``width`` inches wide showing ``limits``
    [[xmin, ymin], [xmax, ymax]] (m), sized in inches so that its box has their aspect: room
    above for ``header_lines`` lines of title, below for the axis label and a legend of
    ``legend_rows`` rows, on the right for a colour bar (the returned third axes, else None)."""
    (x0, y0), (x1, y1) = limits
    height = width * (y1 - y0) / (x1 - x0)
    top = MARGIN_TOP + TITLE_LINE * header_lines + 0.1
    bottom = MARGIN_BOTTOM + (LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0)
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


# --------------------------------------------------------------------------- animations

GIF_DPI = 80  # dots per inch of animation frames
GIF_HOLD_MS = 1500  # ms the last frame of an animation stays up before the loop restarts


def check_animation_options(fps, max_frames) -> None:
    """ValueError unless ``fps`` is a positive whole number and ``max_frames`` one >= 2."""
    if not (isinstance(fps, int | np.integer) and fps > 0):
        raise ValueError(f"fps must be a positive whole number, got {fps!r}")
    if not (isinstance(max_frames, int | np.integer) and max_frames >= 2):
        raise ValueError(f"max_frames must be a whole number of at least 2, got {max_frames!r}")


def frame_samples(t: np.ndarray, fps: int, max_frames: int) -> tuple[np.ndarray, float]:
    """The samples of ``t`` (s, non-decreasing) an animation shows, one per 1/fps s of motion
    time (the step widened to keep to ``max_frames``, and rounded up to whole hundredths, the
    unit of a GIF's frame durations, so that the animation plays in real time), the last sample
    always included; and the step, s."""
    from mosys.plots.car import frame_indices  # here: car imports this module

    span = float(t[-1] - t[0])
    step = max(1.0 / fps, span / (max_frames - 1)) if span > 0 else 1.0 / fps
    step = math.ceil(step * 100.0 - 1e-9) / 100.0
    samples = frame_indices(t, step)
    if samples[-1] != len(t) - 1:
        samples = np.append(samples[: max_frames - 1], len(t) - 1)
    return samples, step


def animation_frames(
    figure: Figure,
    moving: Sequence[Artist],
    steps: Iterable,
    update: Callable[[object], bool],
) -> list:
    """RGB frames (PIL images) of ``figure``, blitted: the static part is drawn once, then for
    each item of ``steps`` ``update(item)`` sets the ``moving`` artists, which are drawn over it
    in the order given. ``update`` returns True when it also changed the static part (the
    limits of a view that pans, say), which is then drawn again. Many times faster than
    matplotlib's animation writers, which redraw the whole figure for every frame."""
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
        for artist in moving:
            figure.draw_artist(artist)
        rgba = np.asarray(canvas.buffer_rgba())
        frames.append(Image.fromarray(rgba[..., :3].copy()))
    return frames


def shared_palette(frames: list, samples: int = 8) -> list:
    """The RGB ``frames`` as palette images sharing one 256-colour palette, made from a montage
    of a few evenly spaced frames: no colour flicker between frames, and far quicker than a
    palette per frame."""
    from PIL import Image

    picks = frames[:: max(1, len(frames) // samples)][:samples]
    width, height = frames[0].size
    montage = Image.new("RGB", (width, height * len(picks)))
    for k, frame in enumerate(picks):
        montage.paste(frame, (0, height * k))
    palette = montage.quantize(256)
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
