"""Learning curves of 3-D BSR searches (Auslander et al. 1995, §4, drawn as its Figures 7 and 8),
from search results ``results/bsr/NAME/seedK.h5``:

- ``plot_learning_kinds``: Figure 7 ("Learning curves for both kinds of motion controller"),
  a time-based and a sense-based search of one problem, every seed and the median of each.
- ``plot_seeds``: Figure 8 ("Variability in search-algorithm performance"), the seeds of one
  search, or of one search of each kind (``mosys.plots.bsr.learning_figure``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import StrMethodFormatter

from mosys.io.bsr_result import BsrResult
from mosys.plots.bsr_learning import (
    CURVE_WIDTH,
    FINALS_WIDTH,
    FITNESS_LABEL,
    KIND_LINESTYLE,
    LEARNING_HEIGHT,
    LEARNING_WIDTH,
    FinalsColumn,
    curves_on_grid,
    cut_off_start,
    draw_finals,
    draw_seed_curve,
    enlarge_band,
    label_learning_curves,
    learning_axes,
    learning_figure,
    seed_labels,
    shared_decimals,
)
from mosys.plots.bsr_results import (
    KIND_TEXT,
    fitness_formula,
    read_result,
    root_attrs,
    search_name,
    wrapped,
)
from mosys.plots.style import (
    LEGEND_SIZE,
    MARGIN_LEFT,
    MARGIN_RIGHT,
    MARGIN_TOP,
    TITLE_LINE,
    PlotInputError,
    add_legend,
    controller_colors,
    counted,
    minus_signs,
    new_figure,
    plot_style,
    save_figure,
    spread_labels,
)

SEED_ALPHA, SEED_WIDTH = 0.35, 0.9  # each seed's faint line
MEDIAN_WIDTH = CURVE_WIDTH + 1.1  # pt
KIND_COLORS = controller_colors(["time", "sense"])  # one colour per controller kind


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
    and spread so that no two overlap, with a thin dotted line from the curve's end where it
    is shorter (by more than 3 % of the longest) or its label was moved (at its own end a
    shorter curve's label sat on the longer curve). A curve that runs to its label at its own
    height has none: a short line before the number read as a minus sign ('—5.61')."""
    low, high = ax.get_ylim()
    height = ax.get_position().height * ax.figure.get_size_inches()[1]
    gap = (high - low) * (11.5 / 72) / height  # a label's height, data units
    heights = spread_labels(np.array([end[2] for end in ends]), gap, low + gap / 2, high - gap / 2)
    longest = max(end[1] for end in ends)
    for (color, evaluations, value), label_y in zip(ends, heights, strict=True):
        leader = evaluations < 0.97 * longest or abs(label_y - value) > gap / 4
        ax.annotate(
            minus_signs(f"{value:.3g}"),
            (evaluations, value),
            xytext=(x, label_y),
            va="center",
            fontsize=9,
            color=color,
            fontweight="bold",
            arrowprops={
                "arrowstyle": "-",
                "color": color,
                "lw": 0.8,
                "linestyle": ":",
                "shrinkA": 0,
                "shrinkB": 4,
            }
            if leader
            else None,
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
            cut_off_start(ax, [r for _, _, results in kinds for r in results], last)
        _label_ends(ax, ends, last * (1.1 if log_x else 1.015))
        ax.xaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
        ax.set_xlabel(f"controller evaluations (count{', log scale' if log_x else ''})")
        ax.set_ylabel(FITNESS_LABEL)
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
    close together (``draw_finals``); where the seeds' late progress is too narrow to be read,
    the curves drawn again in its range, enlarged, with the finals beside them
    (``enlarge_band``). PlotInputError when no file is given, or the files are of
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
        every = [r for _, _, kind_results in kinds for r in kind_results]  # both kinds' seeds
        right_end = max(int(r.evaluations[-1]) for r in every)
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
        cut_off_start(curves, every, right_end)
        band = enlarge_band(curves, finals, every, right_end)
        _lay_out_kinds(figure, entries, title, above=0.3, right=0.0)
        draw_finals(curves, finals, columns, band)
    return figure
