"""BSR searches' plots (Auslander et al. 1995, "Further Experience with
Controller-Based Automatic Motion Synthesis for Articulated Figures", Figures 7 to 12), drawn from
search results ``results/bsr/NAME/seedK.h5`` (``mosys.io.bsr_result``):

- ``plot_learning``: Figure 8 ("Variability in search-algorithm performance"), one search, the
  best fitness against evaluations for each of its seeds, and each seed's final best.
- ``plot_learning_comparison``: Figure 7 ("Learning curves for both kinds of motion
  controller"), several searches, the median over seeds with the range shaded, raw and as a
  fraction of each search's final median.
- ``plot_filmstrip``: Figures 9 to 12, the best motion as rods at regular times, each pose
  lettered with the rule active then.
- ``write_motion_gif``: an animated GIF of the best motion.

Rules are named by letter, rule 0 ``A``, rule 1 ``B``, ... (``rule_letter``); ``active_rule`` -1
(no rule active) shows as a dash. The figure is drawn from ``best/figure_motion`` only: each rod
a line with round ends, metres in the world frame, y up, equal aspect, over the terrain.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter

from mosys.errors import InputError
from mosys.io.bsr_result import BsrResult, read_bsr_result
from mosys.io.contracts import open_hdf5
from mosys.plots.style import (
    ASPECT_RANGE,
    GIF_DPI,
    GIF_FPS,
    GIF_MAX_FRAMES,
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_RIGHT,
    MARGIN_TOP,
    POSE_TIMES,
    STRIP_GROUND,
    STRIP_MARGIN,
    TITLE_LINE,
    PlotInputError,
    add_legend,
    animate_stick_figure,
    check_animation_options,
    choose_interval,
    controller_colors,
    counted,
    draw_pose,
    draw_terrain,
    fit_aspect,
    frame_indices,
    frame_samples,
    minus_signs,
    new_figure,
    plot_style,
    save_figure,
    scene_figure,
    scene_limits,
    spread_labels,
    write_real_time_gif,
)

KIND_TEXT = {"sense": "sense-based", "time": "time-based"}
KIND_LINESTYLE = {"sense": "-", "time": "--"}  # Figure 7: sense-based solid, time-based dashed
NO_RULE = "–"  # the letter of active_rule -1
# fitness terms: (label, unit, format) for the titles; other terms show by name, unitless
TERMS = {
    "distance": ("distance", "m", "+.2f"),
    "rotations": ("rotations", "", ".2f"),
    "contact_distance": ("contact distance", "m", ".2f"),
    "max_height": ("max height", "m", ".2f"),
}

# learning curves
LEARNING_WIDTH, LEARNING_HEIGHT = 9.5, 5.4  # inches
TITLE_WIDTH = 110  # characters of a title line at the learning figures' width
FINALS_WIDTH = 1.9  # inches: the panel of each seed's final best fitness
EARLY_SHARE = 0.01  # of a linear evaluation axis: the start, too narrow to be read
EARLY_MOST = 0.5  # of the y range: the most a curve's start may take before it is cut off
EARLY_PAD = 0.08  # of the range kept: room below the lowest value kept
FINALS_PAD = 0.15  # of the finals' span, above and below them where the panel zooms
FINALS_LEAST = 0.04  # of the curves' y range: the closest the finals panel zooms
FINALS_ZOOM = 0.5  # the panel zooms where its range is at most this share of the curves'
FINALS_TICKS = 0.4  # inches right of the finals panel for its own scale's tick labels
ZOOM_COLOR = "#ebebeb"  # the zoomed range, shaded behind the curves and the finals panel
CURVE_WIDTH = 1.5  # pt
COMPARISON_WIDTH, COMPARISON_HEIGHT = 12.5, 5.6  # inches
BAND_ALPHA = 0.16  # the min..max band of a search's seeds
SUPTITLE_TOP, AXES_TITLE = 0.1, 0.38  # inches: above the figure's title, for an axes title

# filmstrip (its interval: ``choose_interval``)
SHIFT_BELOW = 0.5  # poses are shifted apart when they advance less than this many pose widths
SHIFT_SPACING = 1.05  # pose widths from one shifted pose to the next
GROUND_GAP = 0.08  # of the spacing: the blank between the ground pieces of shifted poses
STRIP_WIDTH = 10.5  # inches: the data area of a filmstrip row
ROW_HEIGHT_MAX = 3.2  # inches: a taller row is made narrower
ROW_ASPECT_MIN = 0.14  # height / width of a row: poses wrap onto up to MAX_ROWS rows to keep it
MAX_ROWS = 4
ROW_GAP = 0.42  # inches between rows (the upper row's x tick labels)
STRIP_COLORBAR = 1.05  # inches right of the rows for the time colour bar
LETTER_PAD, LETTER_ROW = 0.06, 0.2  # inches: letters above the highest pose, one row's height
LETTER_SPACE = 0.24  # inches: letters nearer than this in x go on different rows
LETTER_SIZE = 11.0  # pt

# animation
GIF_WIDTH = 6.0  # inches, the scene's data area
FOLLOW_POSES = 3.0  # a figure ranging wider than this many pose widths is followed by the view
NONE_COLOR = "0.45"  # rods while no rule is active


# --------------------------------------------------------------------------- reading the inputs


def read_result(path: str | Path, dimensions: int | None = 2) -> BsrResult:
    """Read a BSR result file and check that its parts agree: PlotInputError naming the file
    and what is missing or malformed. ``dimensions``: those of the figure the plot draws (2:
    endpoints (N, rods, 2, 2); 3: (N, rods, 2, 3)); None: either."""
    try:
        result = read_bsr_result(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    evaluations, best = result.evaluations, result.best_fitness
    if evaluations.ndim != 1 or evaluations.shape != best.shape or len(evaluations) == 0:
        raise PlotInputError(
            f"{path}: learning_curve/evaluations {evaluations.shape} and best_fitness "
            f"{best.shape} must be one non-empty row each, the same length"
        )
    samples = len(result.motion.t)
    if samples == 0:
        raise PlotInputError(f"{path}: best/figure_motion has no samples")
    drawn = result.motion.dimensions
    if dimensions is not None and drawn != dimensions:
        other = {2: "plot bsr", 3: "plot bsr3d"}.get(drawn)  # the verb that draws it
        raise PlotInputError(
            f"{path}: best/figure_motion is the motion of a {drawn}-D figure; this plot draws "
            f"{dimensions}-D figures" + (f" (mosys {other} draws {drawn}-D ones)" if other else "")
        )
    endpoints = result.motion.endpoints
    if endpoints.ndim != 4 or endpoints.shape[0] != samples or endpoints.shape[2:] != (2, drawn):
        raise PlotInputError(
            f"{path}: best/figure_motion/endpoints has shape {endpoints.shape}, expected "
            f"({samples}, rods, 2, {drawn}): one row per sample of t"
        )
    if result.active_rule.shape != (samples,):
        raise PlotInputError(
            f"{path}: best/active_rule has shape {result.active_rule.shape}, expected "
            f"({samples},): one rule per sample of best/figure_motion/t"
        )
    for key in ("controller_kind", "seed", "best_fitness"):
        if key not in result.attrs:
            raise PlotInputError(f"{path}: no root attribute {key!r}")
    return result


def root_attrs(path: str | Path) -> dict:
    """A result file's root attributes, without reading its datasets."""
    try:
        with open_hdf5(path) as h5:
            return {key: h5.attrs[key] for key in h5.attrs}
    except InputError as error:  # missing, unreadable, not HDF5
        raise PlotInputError(str(error)) from None


def search_name(attrs: Mapping, path: str | Path) -> str:
    """A result's search name: its ``name`` attribute, else the folder it is in
    (``results/bsr/NAME/seedK.h5``)."""
    return str(attrs["name"]) if "name" in attrs else Path(path).parent.name


def best_result_path(paths: Sequence[str | Path]) -> Path:
    """The result with the highest ``best_fitness`` attribute, ties to the lowest ``seed``."""
    if not paths:
        raise PlotInputError("no BSR result files given")
    ranked = []
    for path in paths:
        attrs = root_attrs(path)
        for key in ("best_fitness", "seed"):
            if key not in attrs:
                raise PlotInputError(f"{path}: not a BSR result file: no root attribute {key!r}")
        ranked.append((-float(attrs["best_fitness"]), int(attrs["seed"]), str(path)))
    return Path(min(ranked)[2])


def group_by_search(paths: Sequence[str | Path]) -> dict[str, list[Path]]:
    """The result files grouped by search (``search_name``), in the order first met."""
    groups: dict[str, list[Path]] = {}
    for path in paths:
        groups.setdefault(search_name(root_attrs(path), path), []).append(Path(path))
    return groups


def rule_letter(rule: int) -> str:
    """A rule's letter: rule 0 ``A`` ... rule 25 ``Z``, then ``AA``, ``AB``, ...; -1 (no
    rule active) ``NO_RULE``."""
    rule = int(rule)
    if rule < 0:
        return NO_RULE
    letters = ""
    rule += 1
    while rule:
        rule, digit = divmod(rule - 1, 26)
        letters = chr(ord("A") + digit) + letters
    return letters


def fitness_formula(weights: Mapping[str, float]) -> str:
    """``fitness = 1·distance + 0.5·max_height − 2·rotations`` from term -> weight (zero
    weights left out)."""
    parts = []
    for term, weight in weights.items():
        if weight == 0:
            continue
        sign = "−" if weight < 0 else "+"
        parts.append((sign, f"{abs(weight):g}·{term}"))
    if not parts:
        return "fitness = 0"
    text = ("−" if parts[0][0] == "−" else "") + parts[0][1]
    text += "".join(f" {sign} {part}" for sign, part in parts[1:])
    return f"fitness = {text}"


def wrapped(text: str, width: int = TITLE_WIDTH) -> str:
    """``text`` broken into lines of at most ``width`` characters (a long fitness formula or
    list of terms would run off the figure)."""
    return textwrap.fill(text, width, break_on_hyphens=False)


def terms_text(
    terms: Mapping[str, float], known: Mapping[str, tuple[str, str, str]] = TERMS
) -> str:
    """The measured fitness terms with their units, those ``known`` (term -> label, unit,
    format; default the four of the 2-D contract) first, in its order."""
    shown = [name for name in known if name in terms]
    shown += [name for name in terms if name not in known]
    parts = []
    for name in shown:
        label, unit, fmt = known.get(name, (name.replace("_", " "), "", ".3g"))
        value = minus_signs(format(float(terms[name]), fmt))
        parts.append(f"{label} {value}{' ' + unit if unit else ''}")
    return ", ".join(parts)


def _kind(result: BsrResult) -> str:
    return str(result.attrs.get("controller_kind", result.controller.kind))


def _thousands(axis) -> None:
    """A count axis: whole ticks (a short search's 4 evaluations were labelled 0 0 1 2 2 2 3 4
    4), with thousands separated."""
    axis.get_major_locator().set_params(integer=True)
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:,.0f}"))


# --------------------------------------------------------------------------- learning curves


def curves_on_grid(results: Sequence[BsrResult]) -> tuple[np.ndarray, np.ndarray]:
    """The seeds' best-so-far curves on one grid of evaluations: the union of their recorded
    evaluations up to the fewest any seed ran; each curve a step function (the best after that
    many evaluations), NaN before its first record. Returns grid (G,) and values (S, G)."""
    last = min(int(result.evaluations[-1]) for result in results)
    grid = np.unique(np.concatenate([result.evaluations for result in results]))
    grid = grid[grid <= last]
    values = np.full((len(results), len(grid)), np.nan)
    for s, result in enumerate(results):
        index = np.searchsorted(result.evaluations, grid, side="right") - 1
        found = index >= 0
        values[s, found] = result.best_fitness[index[found]]
    return grid, values


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

    def held_from_start(result: BsrResult) -> np.ndarray:  # the value held at start, and after
        first = int(np.searchsorted(result.evaluations, start, side="right")) - 1
        return result.best_fitness[max(first, 0) :]

    everything = np.concatenate([r.best_fitness for r in results])
    later = np.concatenate([held_from_start(r) for r in results])
    lowest, kept, highest = float(everything.min()), float(later.min()), float(everything.max())
    if not kept - lowest > EARLY_MOST * (highest - lowest):
        return None
    low = kept - EARLY_PAD * (highest - kept)
    below = [r.evaluations[r.best_fitness < low] for r in results]
    evaluations = max((int(e[-1]) for e in below if e.size), default=0)
    return CutStart(low, evaluations, lowest)


def note_cut_start(ax: Axes, cut: CutStart) -> None:
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


def cut_off_start(ax: Axes, results: Sequence[BsrResult], last: int) -> None:
    """On ``ax``, learning curves of ``results`` on a linear axis of ``last`` evaluations: a
    start far below the rest cut off and noted (``cut_start``, ``note_cut_start``)."""
    cut = cut_start(results, last)
    if cut is not None:
        note_cut_start(ax, cut)


def plot_learning(results: Sequence[str | Path], path: str | Path) -> None:
    """Write ``learning_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(learning_figure(results), path)


def learning_figure(results: Sequence[str | Path]) -> Figure:
    """Figure 8 ("Variability in search-algorithm performance") for one search: the best
    fitness so far against the number of controller evaluations, one line per seed, and in a
    narrow panel beside it each seed's final best fitness marked with its seed number, on a
    scale of its own where the finals lie close together (``draw_finals``). The title names
    the search, the controller kind and the fitness function. The figure may be 2-D or 3-D.
    PlotInputError if the files are not all of one search."""
    if not results:
        raise PlotInputError("plot_learning: no BSR result files given")
    loaded = sorted(  # the curves do not depend on the figure's dimensions: 2-D or 3-D
        ((read_result(p, dimensions=None), p) for p in results),
        key=lambda pair: int(pair[0].attrs["seed"]),
    )
    names = {search_name(r.attrs, p) for r, p in loaded}
    kinds = {_kind(r) for r, _ in loaded}
    if len(names) > 1 or len(kinds) > 1:
        raise PlotInputError(
            "the files are of more than one search (one search's seeds a plot): "
            + ", ".join(f"{p} ({search_name(r.attrs, p)}, {_kind(r)})" for r, p in loaded)
        )
    name, kind = names.pop(), kinds.pop()
    first = loaded[0][0]
    seeds = [int(r.attrs["seed"]) for r, _ in loaded]
    colors = controller_colors([str(seed) for seed in seeds])
    figure_name = first.attrs.get("figure", "")
    title = (
        f"BSR search {name}: {KIND_TEXT.get(kind, kind)} controller"
        f"{f' for {figure_name}' if figure_name else ''}, {counted(len(loaded), 'seed')}\n"
        + wrapped(
            f"best fitness found so far by each seed; {fitness_formula(first.fitness_weights)}"
        )
    )
    with plot_style():
        figure = new_figure(LEARNING_WIDTH, LEARNING_HEIGHT)
        curves, finals = learning_axes(figure, FINALS_WIDTH)
        right_end = max(int(r.evaluations[-1]) for r, _ in loaded)
        for (result, _), seed in zip(loaded, seeds, strict=True):
            draw_seed_curve(
                curves, result, right_end, color=colors[str(seed)], label=f"seed {seed}"
            )
        label_learning_curves(curves, right_end)
        cut_off_start(curves, [result for result, _ in loaded], right_end)
        _layout_learning(figure, title)
        final_values = np.array([r.best_fitness[-1] for r, _ in loaded])
        labels = seed_labels(seeds, final_values)
        column = FinalsColumn("", final_values, labels, [colors[str(seed)] for seed in seeds])
        draw_finals(curves, finals, [column])
    return figure


def draw_seed_curve(curves: Axes, result: BsrResult, right_end: int, **style: object) -> None:
    """One seed's best fitness so far against evaluations, a step line held at its last value
    out to ``right_end`` evaluations (the longest seed's), drawn with ``style``."""
    curves.step(
        np.append(result.evaluations, right_end),
        np.append(result.best_fitness, result.best_fitness[-1]),
        where="post",
        linewidth=CURVE_WIDTH,
        **style,
    )


def label_learning_curves(curves: Axes, right_end: int) -> None:
    """The learning curves' panel: evaluations from 0 to ``right_end`` in whole thousands-
    separated counts, its axis labels and its title."""
    curves.set_xlim(0, right_end * 1.01 if right_end > 0 else 1)
    _thousands(curves.xaxis)
    curves.set_xlabel("controller evaluations (count)")
    curves.set_ylabel("best fitness so far (Σ weight × term)")
    curves.set_title("learning curve of each seed", fontsize=10)


def seed_labels(seeds: Sequence[int], values: np.ndarray) -> list[str]:
    """'seed K: value' for each seed's final best fitness, all with the same decimals
    (``shared_decimals``)."""
    decimals = shared_decimals(values)
    return [
        f"seed {seed}: {minus_signs(f'{value:.{decimals}f}')}"
        for seed, value in zip(seeds, values, strict=True)
    ]


def learning_axes(figure: Figure, finals_width: float) -> tuple[Axes, Axes]:
    """The learning curves' axes and, ``finals_width`` inches wide to their right, the final
    best fitness panel's."""
    curves, finals = figure.subplots(
        1,
        2,
        gridspec_kw={"width_ratios": [LEARNING_WIDTH - finals_width - 1.5, finals_width]},
    )
    return curves, finals


@dataclass(frozen=True)
class FinalsColumn:
    """One search's seeds in the final best fitness panel: ``heading`` below the column ("" for
    none), each seed's final best fitness ``values`` (S,), the text beside its dot ``labels``
    (S,) and its colour ``colors`` (S,)."""

    heading: str
    values: np.ndarray
    labels: list[str]
    colors: list


def finals_range(values: np.ndarray, low: float, high: float) -> tuple[float, float] | None:
    """The final best fitness panel's own y range (data units) where ``values`` lie close
    together on the curves' axis (low, high): their span padded by FINALS_PAD of it on each
    side and at least FINALS_LEAST of (high - low), so that the seeds' differences can be read
    (Bob's five finals, 3.2 to 3.9, were one blot on a scale from -50); None where that range
    would be more than FINALS_ZOOM of the curves' (the panel keeps the curves' scale)."""
    finite = values[np.isfinite(values)]
    if finite.size == 0 or not high > low:
        return None
    smallest, largest = float(finite.min()), float(finite.max())
    span = max((largest - smallest) * (1 + 2 * FINALS_PAD), FINALS_LEAST * (high - low))
    if span > FINALS_ZOOM * (high - low):
        return None
    middle = 0.5 * (smallest + largest)
    return middle - span / 2, middle + span / 2


def draw_finals(curves: Axes, finals: Axes, columns: Sequence[FinalsColumn]) -> None:
    """Each column's seeds as dots at their final best fitness, labelled, side by side in
    ``finals`` (after the curves are drawn and the figure laid out), each column's heading
    below it and, where there are several, its median as a black bar. Where the finals lie
    close together (``finals_range``) the panel has a scale of its own, its ticks on the right
    (the figure's right margin widened for them), and the range it shows is shaded on
    ``curves``."""
    low, high = curves.get_ylim()
    values = np.concatenate([column.values for column in columns])
    zoom = finals_range(values, low, high)
    shown_low, shown_high = zoom if zoom is not None else (low, high)
    finals.set_xlim(0, 1)
    width = 1.0 / len(columns)
    if any(column.heading for column in columns):  # each column named below it
        finals.set_xticks(
            [(k + 0.5) * width for k in range(len(columns))],
            [column.heading for column in columns],
            fontsize=9,
        )
        finals.tick_params(axis="x", length=0)
    else:
        finals.set_xticks([])
    finals.grid(False, axis="x")
    if zoom is None:
        finals.tick_params(axis="y", labelleft=False, length=0)
        finals.set_title("final best fitness", fontsize=10)
    else:
        figure = finals.figure
        right = figure.subplotpars.right - FINALS_TICKS / figure.get_size_inches()[0]
        figure.subplots_adjust(right=right)
        finals.yaxis.tick_right()
        finals.tick_params(axis="y", labelsize=8.5)
        finals.set_title("final best fitness\n(the shaded band, enlarged)", fontsize=10)
        curves.axhspan(*zoom, color=ZOOM_COLOR, zorder=0, linewidth=0)
        curves.set_ylim(low, high)
        finals.set_facecolor(ZOOM_COLOR)
    height = finals.get_position().height * finals.figure.get_size_inches()[1]
    gap = (shown_high - shown_low) * (11.5 / 72) / height  # a label's height, data units
    for k, column in enumerate(columns):
        dot, text = k * width + 0.12 * width, k * width + 0.32 * width
        labels = spread_labels(column.values, gap, shown_low + gap / 2, shown_high - gap / 2)
        for value, label_y, label, color in zip(
            column.values, labels, column.labels, column.colors, strict=True
        ):
            finals.plot(
                dot, value, "o", color=color, markersize=6, markeredgecolor="black", mew=0.6
            )
            finals.plot([dot, text - 0.02 * width], [value, label_y], color=color, linewidth=0.8)
            finals.text(text, label_y, label, va="center", ha="left", fontsize=8.5)
        if len(columns) > 1:  # each column's median, a short black bar across its dots
            median = float(np.median(column.values))
            finals.plot([dot - 0.08 * width, dot + 0.08 * width], [median, median], "k-", lw=1.6)
    finals.set_ylim(shown_low, shown_high)


def shared_decimals(values: np.ndarray, digits: int = 3) -> int:
    """Decimals that give the largest of ``values`` (finite ones) ``digits`` significant
    digits, for labels that all show the same precision ('-36' beside '-30.1' did not)."""
    finite = np.abs(values[np.isfinite(values)])
    largest = float(finite.max()) if finite.size else 0.0
    if largest == 0.0:
        return digits - 1
    return max(0, digits - 1 - math.floor(math.log10(largest)))


def _layout_learning(figure, title: str) -> None:
    width, height = figure.get_size_inches()
    lines = title.count("\n") + 1
    figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=11)
    top = SUPTITLE_TOP + TITLE_LINE * lines + AXES_TITLE
    figure.subplots_adjust(
        left=(MARGIN_LEFT + 0.1) / width,
        right=1 - MARGIN_RIGHT / width,
        top=1 - top / height,
        bottom=MARGIN_BOTTOM / height,
        wspace=0.05,
    )


def plot_learning_comparison(
    results_by_search: Mapping[str, Sequence[str | Path]], path: str | Path
) -> None:
    """Write ``learning_comparison_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(learning_comparison_figure(results_by_search), path)


def learning_comparison_figure(results_by_search: Mapping[str, Sequence[str | Path]]) -> Figure:
    """Figure 7 ("Learning curves for both kinds of motion controller"): for each search (name
    -> its seeds' result files), the median over seeds of the best fitness so far against the
    number of evaluations, the range over seeds (min..max) shaded; sense-based searches solid,
    time-based dashed. A second panel shows each median as a fraction of the search's final
    median, so that searches of different fitness scales compare in speed (a search whose final
    median is not positive cannot be so normalised and is left out there, as its note says)."""
    if not results_by_search or not all(results_by_search.values()):
        raise PlotInputError("plot_learning_comparison: give at least one result per search")
    searches = list(results_by_search)
    colors = controller_colors(searches)
    entries: list[tuple[object, str]] = []
    with plot_style():
        figure = new_figure(COMPARISON_WIDTH, COMPARISON_HEIGHT)
        raw, scaled = figure.subplots(1, 2)
        left_out = []
        right_end = 0
        drawn_kinds = set()
        for name in searches:
            loaded = [read_result(p) for p in results_by_search[name]]
            kinds = {_kind(r) for r in loaded}
            if len(kinds) > 1:
                raise PlotInputError(f"search {name}: its files mix controller kinds {kinds}")
            kind = kinds.pop()
            drawn_kinds.add(kind)
            grid, values = curves_on_grid(loaded)
            median = np.nanmedian(values, axis=0)
            low, high = np.nanmin(values, axis=0), np.nanmax(values, axis=0)
            right_end = max(right_end, int(grid[-1]))
            style = {
                "color": colors[name],
                "linestyle": KIND_LINESTYLE.get(kind, "-."),
                "linewidth": CURVE_WIDTH + 0.3,
            }
            raw.step(grid, median, where="post", **style)
            raw.fill_between(
                grid, low, high, step="post", color=colors[name], alpha=BAND_ALPHA, linewidth=0
            )
            final = median[-1]
            if final > 0:
                scaled.step(grid, median / final, where="post", **style)
            else:
                left_out.append(name)
            entries.append(
                (
                    (Patch(color=colors[name], alpha=BAND_ALPHA * 1.6), Line2D([], [], **style)),
                    f"{name} ({KIND_TEXT.get(kind, kind)}, {counted(len(loaded), 'seed')})",
                )
            )
        for ax in (raw, scaled):
            ax.set_xlim(0, right_end * 1.01 if right_end > 0 else 1)
            _thousands(ax.xaxis)
            ax.set_xlabel("controller evaluations (count)")
        raw.set_ylabel("best fitness so far (Σ weight × term)")
        raw.set_title("median over seeds (line), min to max (shaded)", fontsize=10)
        scaled.set_ylabel("median best fitness / final median (fraction)")
        scaled.set_title("the median as a fraction of its final value", fontsize=10)
        scaled.axhline(1.0, color="0.4", linewidth=0.8, linestyle=":", zorder=1)
        if left_out:
            scaled.text(
                0.98,
                0.04,
                "left out (final median ≤ 0): " + ", ".join(left_out),
                transform=scaled.transAxes,
                ha="right",
                va="bottom",
                fontsize=8.5,
                bbox={"boxstyle": "round,pad=0.25", "facecolor": "white", "alpha": 0.85},
            )
        ncols = min(3, len(entries))
        add_legend(figure, entries, ncols=ncols)
        width, height = figure.get_size_inches()
        if drawn_kinds == {"sense", "time"}:
            title = (
                "Learning curves for both kinds of motion controller\n"
                "BSR searches: sense-based controllers solid, time-based dashed"
            )
        else:  # only the kinds drawn (it said 'time-based dashed' where none was)
            words = {"-": "solid", "--": "dashed"}  # KIND_LINESTYLE's; any other kind: "-."
            shown = ", ".join(
                f"{KIND_TEXT.get(k, k)} controllers "
                + words.get(KIND_LINESTYLE.get(k, "-."), "dash-dotted")
                for k in sorted(drawn_kinds)
            )
            title = f"Learning curves of BSR searches\n{shown}"
        figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=11)
        figure.subplots_adjust(
            top=1 - (SUPTITLE_TOP + TITLE_LINE * 2 + AXES_TITLE) / height,
            left=(MARGIN_LEFT + 0.1) / width,
            wspace=0.24,
        )
    return figure


# --------------------------------------------------------------------------- the filmstrip


def _round_up(value: float) -> float:
    """``value`` rounded up to two significant digits (1.96 -> 2.0, 1.43 -> 1.5)."""
    if not value > 0:
        return 1.0
    unit = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / unit - 1e-9) * unit


def pose_offsets(poses: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Horizontal shifts (K,) m for the poses (K, rods, 2, 2) m of a filmstrip: none when the
    figure advances SHIFT_BELOW pose widths per pose or more on the whole (the middle of the
    last pose's x range minus the first's, over K - 1); else pose k moves k times a fixed
    spacing in the direction the figure travels, the spacing (rounded up to two digits) making
    up the difference between that average advance and SHIFT_SPACING times the widest pose.
    Also returns the spacing, m (0 when not shifted), and the travel, m."""
    xs = poses[..., 0].reshape(len(poses), -1)
    left, right = xs.min(axis=1), xs.max(axis=1)
    centre = (left + right) / 2
    width = max(float((right - left).max()), 1e-3)
    travel = float(centre[-1] - centre[0])
    count = len(poses)
    if count < 2 or abs(travel) >= SHIFT_BELOW * width * (count - 1):
        return np.zeros(count), 0.0, travel
    spacing = _round_up(SHIFT_SPACING * width - abs(travel) / (count - 1))
    direction = -1.0 if travel < 0 else 1.0
    return direction * spacing * np.arange(count), spacing, travel


def _ground_piece(terrain: list, x0: float, x1: float) -> list:
    """The terrain polyline between x0 and x1 (m), its ends interpolated."""
    if not terrain:
        return []
    ground = np.asarray(terrain, dtype=np.float64)
    inside = ground[(ground[:, 0] > x0) & (ground[:, 0] < x1)]
    ends = np.interp([x0, x1], ground[:, 0], ground[:, 1])
    return [[x0, ends[0]], *inside.tolist(), [x1, ends[1]]]


def ground_pieces(
    terrain: list, left: np.ndarray, right: np.ndarray, offsets: np.ndarray, spacing: float
) -> list[list]:
    """The ground under each pose of a filmstrip as drawn: pose k spans x ``left[k]`` to
    ``right[k]`` (m, shifted by ``offsets[k]``); its piece of terrain runs from halfway to the
    pose drawn before it to halfway to the one after it (GROUND_GAP of ``spacing`` left between
    pieces; half a ``spacing`` beyond the ends), taken from where the pose really is and
    shifted with it. [x, y] vertices, m, in drawn coordinates; empty without terrain."""
    if not terrain:
        return [[] for _ in left]
    order = np.argsort((left + right) / 2, kind="stable")
    lo, hi = left[order], right[order]
    middles = (hi[:-1] + lo[1:]) / 2
    gap = GROUND_GAP * spacing / 2
    starts = np.concatenate([[lo[0] - spacing / 2], middles + gap])
    ends = np.concatenate([middles - gap, [hi[-1] + spacing / 2]])
    pieces: list[list] = [[] for _ in left]
    for k, start, end in zip(order, starts, ends, strict=True):
        shift = offsets[k]
        piece = _ground_piece(terrain, start - shift, max(end, start) - shift)
        pieces[k] = [[x + shift, y] for x, y in piece]
    return pieces


def letter_levels(x: np.ndarray, space: float) -> np.ndarray:
    """A row (0, 1, ...) for each letter at ``x`` so that letters on one row are at least
    ``space`` apart (greedy, left to right)."""
    levels = np.zeros(len(x), dtype=np.int64)
    ends: list[float] = []  # the x of the last letter on each row
    for k in np.argsort(x, kind="stable"):
        for level, end in enumerate(ends):
            if x[k] - end >= space:
                levels[k], ends[level] = level, x[k]
                break
        else:
            levels[k] = len(ends)
            ends.append(x[k])
    return levels


def _controller_text(result: BsrResult) -> str:
    kind = _kind(result)
    text = f"{KIND_TEXT.get(kind, kind)} controller, {result.controller.rules} rules"
    if kind == "time" and math.isfinite(result.controller.period):
        text += f", period {result.controller.period:g} s"
    return text


def _result_title(result: BsrResult, path: str | Path) -> str:
    name = search_name(result.attrs, path)
    figure_name = result.attrs.get("figure", "")
    on = f" ({figure_name})" if figure_name else ""
    seed = int(result.attrs["seed"])
    fitness = minus_signs(f"{float(result.attrs['best_fitness']):.4g}")
    return (
        f"BSR search {name}{on}, seed {seed}: {_controller_text(result)}\n"
        f"fitness {fitness}: {terms_text(result.fitness_terms)}"
    )


def plot_filmstrip(
    result_path: str | Path, path: str | Path, interval: float | None = None
) -> None:
    """Write ``filmstrip_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(filmstrip_figure(result_path, interval), path)


def filmstrip_figure(result_path: str | Path, interval: float | None = None) -> Figure:
    """Figures 9 to 12: the best motion of a search as the figure's rods (lines with round
    ends) every ``interval`` s from its start to its end (None: a round interval giving 12 to
    20 poses, ``choose_interval``), light to dark with time (colour bar, s), each pose lettered
    with the rule active then (for a time-based controller: the rule of that time segment),
    over the ground, to scale in metres. Poses are drawn where they are, unless the figure
    advances less than SHIFT_BELOW pose widths per pose: then each is shifted a fixed spacing
    further than the one before (``pose_offsets``), as the subtitle says. A long strip wraps
    onto up to MAX_ROWS rows at one scale. The title gives the search, seed, controller kind,
    fitness and measured terms."""
    result = read_result(result_path)
    motion = result.motion
    t = motion.t
    duration = float(t[-1] - t[0])
    if interval is None:
        interval = choose_interval(duration)
    if not interval > 0:
        raise ValueError(f"interval must be a positive number of seconds, got {interval!r}")
    samples = frame_indices(t, interval)
    poses = motion.endpoints[samples]
    offsets, spacing, travel = pose_offsets(poses)
    drawn = poses.copy()
    drawn[..., 0] += offsets[:, None, None]
    count = len(samples)
    xs = drawn[..., 0].reshape(count, -1)
    left, right = xs.min(axis=1), xs.max(axis=1)
    letters = [rule_letter(result.active_rule[s]) for s in samples]
    pieces = ground_pieces(motion.terrain, left, right, offsets, spacing)
    grounds = np.array([y for piece in pieces for _, y in piece])
    low = min(float(drawn[..., 1].min()), float(grounds.min()) if grounds.size else np.inf)
    flat = grounds.size == 0 or np.ptp(grounds) < 1e-9  # looks the same shifted: drawn whole
    top = float(drawn[..., 1].max())

    # rows: consecutive poses, all at one scale, as few as keep a row from being too flat
    for row_count in range(1, MAX_ROWS + 1):
        rows = [r for r in np.array_split(np.arange(count), row_count) if r.size]
        span = max(right[r].max() - left[r].min() for r in rows)
        if (top - low) / max(span, 1e-9) >= ROW_ASPECT_MIN:
            break
    data_width = STRIP_WIDTH
    scale = span / (data_width - 2 * STRIP_MARGIN)  # m per inch
    levels = [letter_levels((left[r] + right[r]) / 2, LETTER_SPACE * scale) for r in rows]
    letter_rows = max(int(level.max()) + 1 for level in levels)
    y0 = low - STRIP_GROUND * scale
    letter_base = top + LETTER_PAD * scale
    y1 = letter_base + (letter_rows * LETTER_ROW + STRIP_MARGIN) * scale
    row_height = (y1 - y0) / scale
    if row_height > ROW_HEIGHT_MAX:  # a tall scene: narrower rows at a larger scale
        data_width *= ROW_HEIGHT_MAX / row_height
        scale *= row_height / ROW_HEIGHT_MAX
        row_height = ROW_HEIGHT_MAX
    x_span = span + 2 * STRIP_MARGIN * scale

    kind = _kind(result)
    rule_text = "the rule of that time segment" if kind == "time" else "the rule active then"
    subtitle = (
        f"poses every {interval:g} s from {t[0]:g} s to {t[samples[-1]]:.3g} s, light → dark; "
        f"letter: {rule_text} ({NO_RULE}: none)"
    )
    if spacing:
        side = "left" if offsets[-1] < 0 else "right"
        subtitle += (
            f"\neach pose shifted {side} by {spacing:g} m more than the one before, so that "
            "they do not overlap (unshifted, the poses' middles move "
            f"{minus_signs(f'{travel:+.2f}')} m)"
        )
    title = _result_title(result, result_path) + "\n" + subtitle
    title_lines = title.count("\n") + 1
    header = MARGIN_TOP + 0.1 + TITLE_LINE * title_lines
    fig_width = max(MARGIN_LEFT + data_width + STRIP_COLORBAR, 9.0)
    fig_height = header + len(rows) * row_height + (len(rows) - 1) * ROW_GAP + MARGIN_BOTTOM
    norm = Normalize(float(t[0]), float(t[-1]) if t[-1] > t[0] else float(t[0]) + 1.0)
    with plot_style():
        figure = new_figure(fig_width, fig_height)
        figure.suptitle(title, y=1 - 0.1 / fig_height, va="top", fontsize=10.5)
        axes = []
        for k, row in enumerate(rows):
            bottom = MARGIN_BOTTOM + (len(rows) - 1 - k) * (row_height + ROW_GAP)
            ax = figure.add_axes(
                (
                    MARGIN_LEFT / fig_width,
                    bottom / fig_height,
                    data_width / fig_width,
                    row_height / fig_height,
                )
            )
            x0 = left[row].min() - STRIP_MARGIN * scale
            ax.set_xlim(x0, x0 + x_span)
            ax.set_ylim(y0, y1)
            ax.set_aspect("equal", adjustable="box")
            ax.set_ylabel("y (m)")
            ax.grid(alpha=0.2)
            if spacing and not flat:  # the ground under each pose, shifted with it
                for j in row:
                    draw_terrain(ax, pieces[j], y0 - 1.0)
            else:
                draw_terrain(ax, motion.terrain, y0 - 1.0)
            for j, level in zip(row, levels[k], strict=True):
                color = POSE_TIMES(norm(t[samples[j]]))
                draw_pose(ax, drawn[j], color, 3 + j / count)
                ax.text(
                    (left[j] + right[j]) / 2,
                    letter_base + level * LETTER_ROW * scale,
                    letters[j],
                    ha="center",
                    va="bottom",
                    fontsize=LETTER_SIZE,
                    fontweight="bold",
                    zorder=10,
                )
            axes.append(ax)
        axes[-1].set_xlabel("x (m)" + (" (poses shifted apart, see the title)" if spacing else ""))
        bar_bottom = MARGIN_BOTTOM / fig_height
        bar_height = (fig_height - header - MARGIN_BOTTOM) / fig_height
        bar = figure.add_axes(
            (
                (MARGIN_LEFT + data_width + 0.2) / fig_width,
                bar_bottom,
                0.16 / fig_width,
                bar_height,
            )
        )
        figure.colorbar(ScalarMappable(norm, POSE_TIMES), cax=bar, label="time t (s)")
    return figure


# --------------------------------------------------------------------------- the animation


def write_motion_gif(
    result_path: str | Path,
    path: str | Path,
    fps: int = GIF_FPS,
    max_frames: int = GIF_MAX_FRAMES,
) -> None:
    """An animated GIF of a search's best motion, to scale in metres: the terrain, the rods
    (lines with round ends) coloured by the rule active, and in the corner the time and that
    rule's letter. One frame per 1/``fps`` s of motion time (at most every 40 ms by default),
    played in real time, the step widened to keep to ``max_frames`` frames; the last frame held
    GIF_HOLD_MS ms; loops. A figure ranging wider than FOLLOW_POSES of its widths is followed by
    a view that pans (``mosys.plots.style.pan``). Written atomically."""
    check_animation_options(fps, max_frames)
    result = read_result(result_path)
    motion = result.motion
    t, endpoints = motion.t, motion.endpoints
    samples, step = frame_samples(t, int(fps), int(max_frames))
    poses = endpoints[samples]
    limits = scene_limits(poses.reshape(-1, 2), motion.terrain)
    xs = poses[..., 0].reshape(len(samples), -1)
    centre = (xs.min(axis=1) + xs.max(axis=1)) / 2
    pose_width = float((xs.max(axis=1) - xs.min(axis=1)).max())
    window = max(FOLLOW_POSES * pose_width, (limits[1, 1] - limits[0, 1]) / ASPECT_RANGE[1])
    follow = limits[1, 0] - limits[0, 0] > window
    if follow:
        limits[:, 0] = centre[0] + np.array([-0.5, 0.5]) * window
        limits = fit_aspect(limits)
    rules = result.controller.rules
    letters = [rule_letter(r) for r in range(rules)]
    colors = controller_colors(letters)
    active = result.active_rule[samples]
    title = _result_title(result, result_path) + (
        "\nrods coloured by the active rule (grey while none is), played in real time"
    )
    with plot_style():
        figure, ax, _ = scene_figure(
            limits, GIF_WIDTH, title.count("\n") + 1, legend_rows=0, dpi=GIF_DPI
        )
        figure.suptitle(title, y=1 - 0.08 / figure.get_size_inches()[1], va="top", fontsize=9)
        draw_terrain(ax, motion.terrain, limits[0, 1] - 1.0)

        def look(frame: int) -> tuple:
            which = int(active[frame])
            color = colors[letters[which]] if 0 <= which < rules else NONE_COLOR
            return color, f"rule {rule_letter(which)}", color if which >= 0 else "black"

        frames = animate_stick_figure(
            figure,
            ax,
            t,
            endpoints,
            samples,
            look,
            label_size=13,
            follow=centre if follow else None,
        )
    write_real_time_gif(frames, path, step)
