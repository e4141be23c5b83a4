"""The shared look of mosys plots: figure sizes, fonts, markers, colours, the atomic PNG write and
the blitted, atomically written animated GIF.

Figures are built with matplotlib's object API on an Agg canvas (no pyplot, no global figure
state), so plotting works headless and in parallel Snakemake jobs.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D

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


# --------------------------------------------------------------------------- animations

GIF_DPI = 80  # dots per inch of animation frames


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
