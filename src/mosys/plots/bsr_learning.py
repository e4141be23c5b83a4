"""Learning curves of BSR searches (Auslander et al. 1995), drawn from search results
``results/bsr/NAME/seedK.h5``; the 3-D figures' Figures 7 and 8 (``mosys.plots.bsr3d_learning``)
build on these:

- ``plot_learning``: Figure 8 ("Variability in search-algorithm performance"), one search, the
  best fitness against evaluations for each of its seeds, and each seed's final best.
- ``plot_learning_comparison``: Figure 7 ("Learning curves for both kinds of motion
  controller"), several searches, the median over seeds with the range shaded, raw and as a
  fraction of each search's final median.

On a linear axis a start far below the rest is cut off and noted (``cut_start``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter

from mosys.io.bsr_result import BsrResult
from mosys.plots.bsr_results import (
    KIND_TEXT,
    fitness_formula,
    read_result,
    result_kind,
    search_name,
    wrapped,
)
from mosys.plots.style import (
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_RIGHT,
    TITLE_LINE,
    PlotInputError,
    add_legend,
    controller_colors,
    counted,
    new_figure,
    number_text,
    plot_style,
    save_figure,
    spread_labels,
)

KIND_LINESTYLE = {"sense": "-", "time": "--"}  # Figure 7: sense-based solid, time-based dashed

# learning curves
LEARNING_WIDTH, LEARNING_HEIGHT = 9.5, 5.4  # inches
FINALS_WIDTH = 1.9  # inches: the panel of each seed's final best fitness
EARLY_SHARE = 0.01  # of a linear evaluation axis: the start, too narrow to be read
EARLY_MOST = 0.5  # of the y range: the most a curve's start may take before it is cut off
EARLY_PAD = 0.08  # of the range kept: room below the lowest value kept
EARLY_TOP = 0.05  # of the range kept: room above the highest value (matplotlib's own margin)
FINALS_PAD = 0.15  # of the finals' span, above and below them where the panel zooms
FINALS_LEAST = 0.04  # of the curves' y range: the closest the finals panel zooms
FINALS_ZOOM = 0.5  # the panel zooms where its range is at most this share of the curves'
LATE_SHARE = 0.25  # of the evaluation axis: the curves from here on are a search's late progress
LATE_SPREAD = 0.1  # of the y range: late progress narrower than this is enlarged in a band
FINALS_TICKS = 0.4  # inches right of the finals panel for its own scale's tick labels
BAND_HEIGHT = 2.8  # inches: the figure grows by this for the enlarged band under the curves
BAND_SHARE = 0.68  # the enlarged band's height, as a share of the whole curves' panel
BAND_GAP = 0.14  # between the curves' panel and the band's, a share of their mean height
ZOOM_COLOR = "#ebebeb"  # the zoomed range, shaded behind the curves, the band and the finals
CURVE_WIDTH = 1.5  # pt
FITNESS_SO_FAR, FITNESS_UNIT = "best fitness so far", "(Σ weight × term)"  # a curve's y axis
FITNESS_LABEL = f"{FITNESS_SO_FAR} {FITNESS_UNIT}"
COMPARISON_WIDTH, COMPARISON_HEIGHT = 12.5, 5.6  # inches
BAND_ALPHA = 0.16  # the min..max band of a search's seeds
SUPTITLE_TOP, AXES_TITLE = 0.1, 0.38  # inches: above the figure's title, for an axes title


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


def held_from(result: BsrResult, evaluations: float) -> np.ndarray:
    """The best fitness values ``result`` holds from ``evaluations`` on: the one held there
    (its first record where it starts later) and every later one."""
    first = int(np.searchsorted(result.evaluations, evaluations, side="right")) - 1
    return result.best_fitness[max(first, 0) :]


@dataclass(frozen=True)
class CutStart:
    """Where a learning-curve plot's y axis leaves out the curves' first values: ``low`` and
    ``high`` (data units) the axis's ends, ``evaluations`` the count after which every curve is
    above ``low``, ``lowest`` the lowest value left out."""

    low: float
    high: float
    evaluations: int
    lowest: float


def cut_start(results: Sequence[BsrResult], last: int) -> CutStart | None:
    """The y axis's ends for the best-so-far curves of ``results`` drawn on a linear axis of
    ``last`` evaluations, where their first EARLY_SHARE of it would take more than EARLY_MOST
    of the y range: from the lowest value held from there on to the highest, padded by a share
    of that range (the top's margin had been a share of the whole, blank). A first population's
    best can lie far below everything after it (Rex's -7.7 for 60 of 60,000 evaluations, then
    0.8 and up), squeezing the curves into the top of the plot. None where nothing need be
    cut (the axis then shows every value)."""
    everything = np.concatenate([r.best_fitness for r in results])
    later = np.concatenate([held_from(r, EARLY_SHARE * last) for r in results])
    lowest, kept, highest = float(everything.min()), float(later.min()), float(everything.max())
    if not kept - lowest > EARLY_MOST * (highest - lowest):
        return None
    low, high = kept - EARLY_PAD * (highest - kept), highest + EARLY_TOP * (highest - kept)
    below = [r.evaluations[r.best_fitness < low] for r in results]
    evaluations = max((int(e[-1]) for e in below if e.size), default=0)
    return CutStart(low, high, evaluations, lowest)


def cut_off_start(ax: Axes, results: Sequence[BsrResult], last: int) -> None:
    """On ``ax``, learning curves of ``results`` on a linear axis of ``last`` evaluations: where
    ``cut_start`` cuts, the y axis's ends set there and, in the plot's lower right (where the
    curves, risen by then, leave room), what was left out."""
    cut = cut_start(results, last)
    if cut is None:
        return
    ax.set_ylim(cut.low, cut.high)
    ax.text(
        0.985,
        0.03,
        f"↓ below the axis: the best of the first {cut.evaluations:,} evaluations, "
        f"down to {number_text(cut.lowest, '.3g')}",
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=8.5,
        color="0.25",
        bbox={"boxstyle": "round,pad=0.25", "facecolor": "white", "alpha": 0.85, "lw": 0},
    )


def plot_learning(results: Sequence[str | Path], path: str | Path) -> None:
    """Write ``learning_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(learning_figure(results), path)


def learning_figure(results: Sequence[str | Path]) -> Figure:
    """Figure 8 ("Variability in search-algorithm performance") for one search: the best
    fitness so far against the number of controller evaluations, one line per seed, and in a
    narrow panel beside it each seed's final best fitness marked with its seed number, on a
    scale of its own where the finals lie close together (``draw_finals``). Where the seeds'
    late progress is too narrow to be read, the curves are drawn again in its range, enlarged,
    under the whole curves, with the finals beside them (``enlarge_band``). The title names
    the search, the controller kind and the fitness function. The figure may be 2-D or 3-D.
    PlotInputError if the files are not all of one search."""
    if not results:
        raise PlotInputError("plot_learning: no BSR result files given")
    loaded = sorted(  # the curves do not depend on the figure's dimensions: 2-D or 3-D
        ((read_result(p, dimensions=None), p) for p in results),
        key=lambda pair: int(pair[0].attrs["seed"]),
    )
    names = {search_name(r.attrs, p) for r, p in loaded}
    kinds = {result_kind(r) for r, _ in loaded}
    if len(names) > 1 or len(kinds) > 1:
        raise PlotInputError(
            "the files are of more than one search (one search's seeds a plot): "
            + ", ".join(f"{p} ({search_name(r.attrs, p)}, {result_kind(r)})" for r, p in loaded)
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
        every = [result for result, _ in loaded]
        right_end = max(int(r.evaluations[-1]) for r in every)
        for result, seed in zip(every, seeds, strict=True):
            draw_seed_curve(
                curves, result, right_end, color=colors[str(seed)], label=f"seed {seed}"
            )
        label_learning_curves(curves, right_end)
        cut_off_start(curves, every, right_end)
        band = enlarge_band(curves, finals, every, right_end)
        _layout_learning(figure, title)
        final_values = np.array([r.best_fitness[-1] for r, _ in loaded])
        labels = seed_labels(seeds, final_values)
        column = FinalsColumn("", final_values, labels, [colors[str(seed)] for seed in seeds])
        draw_finals(curves, finals, [column], band)
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
    curves.set_ylabel(FITNESS_LABEL)
    curves.set_title("learning curve of each seed", fontsize=10)


def seed_labels(seeds: Sequence[int], values: np.ndarray) -> list[str]:
    """'seed K: value' for each seed's final best fitness, all with the same decimals
    (``shared_decimals``)."""
    decimals = shared_decimals(values)
    return [
        f"seed {seed}: {number_text(value, f'.{decimals}f')}"
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
    would be more than FINALS_ZOOM of the curves' (the panel keeps the curves' scale), and
    where fewer than two are finite (one seed's dot has no neighbours to tell apart: it was
    drawn alone on a scale of a thousandth)."""
    finite = values[np.isfinite(values)]
    if finite.size < 2 or not high > low:
        return None
    smallest, largest = float(finite.min()), float(finite.max())
    span = max((largest - smallest) * (1 + 2 * FINALS_PAD), FINALS_LEAST * (high - low))
    if span > FINALS_ZOOM * (high - low):
        return None
    middle = 0.5 * (smallest + largest)
    return middle - span / 2, middle + span / 2


def late_band(
    results: Sequence[BsrResult], right_end: int, low: float, high: float
) -> tuple[float, float] | None:
    """The y range (data units) of the seeds' late progress, where it is too narrow to be read
    on the curves' scale (``low``, ``high``): the values ``results`` hold from LATE_SHARE of
    the ``right_end`` evaluations on, where they span at most LATE_SPREAD of that scale,
    padded as ``finals_range`` pads the finals (they are among them). None where they span more
    (the curves can be read as they are) or nothing (one flat line: nothing to enlarge)."""
    late = np.concatenate([held_from(r, LATE_SHARE * right_end) for r in results])
    late = late[np.isfinite(late)]
    if late.size == 0 or not 0 < np.ptp(late) <= LATE_SPREAD * (high - low):
        return None
    return finals_range(late, low, high)


def enlarge_band(
    curves: Axes, finals: Axes, results: Sequence[BsrResult], right_end: int
) -> Axes | None:
    """Where the seeds' late progress is too narrow to be read on the curves' scale
    (``late_band``: Bob's seeds climb from 2.5 to 3.75 over 50,000 evaluations, on a scale
    from -70 one line), the curves drawn again in its range, in a panel of their own under the
    whole curves. The figure grows BAND_HEIGHT taller, the finals panel moves beside the band
    and shares its scale, the band is shaded on the whole curves and the evaluations are
    labelled under the band. Returns the band's axes, or None where nothing changes. Call once
    the curves (``results``, drawn to ``right_end`` evaluations) are drawn and before the
    figure's margins are set (they are in inches)."""
    low, high = curves.get_ylim()
    zoom = late_band(results, right_end, low, high)
    if zoom is None:
        return None
    figure = curves.figure
    width, height = figure.get_size_inches()
    figure.set_size_inches(width, height + BAND_HEIGHT)
    grid = figure.add_gridspec(
        2,
        2,
        width_ratios=curves.get_subplotspec().get_gridspec().get_width_ratios(),
        height_ratios=[1 - BAND_SHARE, BAND_SHARE],
        hspace=BAND_GAP,
    )
    curves.set_subplotspec(grid[0, 0])
    finals.set_subplotspec(grid[1, 1])
    band = figure.add_subplot(grid[1, 0], sharex=curves)
    for line in curves.lines:  # the seeds' curves, unlabelled
        band.plot(
            line.get_xdata(),
            line.get_ydata(),
            drawstyle=line.get_drawstyle(),
            color=line.get_color(),
            linestyle=line.get_linestyle(),
            linewidth=line.get_linewidth(),
            alpha=line.get_alpha(),
        )
    band.set_ylim(*zoom)
    band.set_facecolor(ZOOM_COLOR)
    band.set_xlabel(curves.get_xlabel())
    band.set_ylabel(f"{FITNESS_SO_FAR},\nthe shaded band enlarged")
    curves.set_ylabel(f"{FITNESS_SO_FAR}\n{FITNESS_UNIT}")  # no taller than its panel
    curves.set_xlabel("")
    curves.tick_params(axis="x", labelbottom=False)
    curves.axhspan(*zoom, color=ZOOM_COLOR, zorder=0, linewidth=0)
    curves.set_ylim(low, high)
    finals.sharey(band)
    finals.set_facecolor(ZOOM_COLOR)
    return band


def draw_finals(
    curves: Axes, finals: Axes, columns: Sequence[FinalsColumn], band: Axes | None = None
) -> None:
    """Each column's seeds as dots at their final best fitness, labelled, side by side in
    ``finals`` (after the curves are drawn and the figure laid out), each column's heading
    below it and, where there are several, its median as a black bar. Beside ``enlarge_band``'s
    ``band`` the panel shares its scale. Otherwise, where the finals lie close together
    (``finals_range``) the panel has a scale of its own, its ticks on the right (the figure's
    right margin widened for them), and the range it shows is shaded on ``curves``."""
    low, high = curves.get_ylim()
    values = np.concatenate([column.values for column in columns])
    zoom = None if band is not None else finals_range(values, low, high)
    shown_low, shown_high = band.get_ylim() if band is not None else zoom or (low, high)
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
            kinds = {result_kind(r) for r in loaded}
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
        raw.set_ylabel(FITNESS_LABEL)
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
