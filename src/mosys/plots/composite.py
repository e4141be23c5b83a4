"""Composite motions' plots (Auslander et al. 1995, §3, Table 4 and Figures 13 and 14), drawn
from composite results ``results/composite/NAME.h5`` (``mosys.io.composite_result``):

- ``plot_filmstrips``: Figure 13 ("Mr. Star-Man's composite trajectory before refinement")
  above Figure 14 ("... after refinement"): each motion as the figure's rods at regular times,
  each phase in its own colour, the pose at each switch between controllers drawn in black and
  labelled with its time.
- ``plot_search``: Figure 5's search, the best script total after each generation against the
  guess's.
- ``write_composite_gif``: an animated GIF of the refined motion, rods coloured by phase.

Phases take their colours in the script's order (``controller_colors`` of their names), the
same in every plot. Figures are drawn from ``figure_motion`` and ``before/figure_motion`` only:
metres in the world frame, y up, equal aspect, over the terrain. Poses are drawn where they are
(they overlap along x as in the paper's figures), never shifted apart.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.typing import ColorType

from mosys.errors import InputError
from mosys.io.composite_result import CompositeMotion, CompositeResult, read_composite_result
from mosys.plots.style import (
    GIF_DPI,
    GIF_FPS,
    GIF_MAX_FRAMES,
    LEGEND_ROW,
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_RIGHT,
    MARGIN_TOP,
    ROD_WIDTH,
    STRIP_GROUND,
    STRIP_MARGIN,
    TITLE_LINE,
    PlotInputError,
    add_legend,
    animate_stick_figure,
    check_animation_options,
    choose_interval,
    controller_colors,
    draw_pose,
    draw_terrain,
    frame_indices,
    frame_samples,
    keep_left_labels_in,
    lighten,
    minus_signs,
    new_figure,
    plot_style,
    save_figure,
    scene_figure,
    scene_limits,
    spread_labels,
    write_real_time_gif,
)

# filmstrips
STRIP_WIDTH = 13.0  # inches: the data area of a panel
FIGURE_WIDTH_MIN = 11.0  # inches: room for the title and the legends
PANEL_HEIGHT_MAX = 3.6  # inches: a taller panel is made narrower
PANEL_GAP = 0.35  # inches between one panel's legend and the next panel's title
LIGHTEST = 0.6  # a phase's first pose: its colour mixed this much with white, its last pure
SWITCH_COLOR = "black"  # the pose at a switch
SWITCH_WIDTH = ROD_WIDTH + 1.0  # pt
SWITCH_LABEL_WIDTH = 1.75  # inches: switch labels nearer than this in x go on different rows
SWITCH_LABEL_ROW = 0.36  # inches per row of switch labels (two text lines)
SWITCH_LABEL_PAD = 0.12  # inches between the highest pose and the lowest label row
SWITCH_LABEL_SIZE = 9.0  # pt
CLOSE_TO_SWITCH = 1 / 3  # of the interval: a regular pose this near a switch pose is left out
LEGEND_COLUMNS = 2

# search
SEARCH_WIDTH, SEARCH_HEIGHT = 8.0, 4.8  # inches
GUESS_COLOR = "0.45"
CURVE_COLOR = "#1f77b4"
# the largest script total drawn: matplotlib's tick locator overflows on an axis near 1e308
# (the script's arithmetic may give any double, as `total = 1e308 + cartwheel` does)
DRAWABLE_SCORE = 1e300

# animation
GIF_WIDTH = 8.0  # inches, the scene's data area: the whole travel is shown, no panning


# --------------------------------------------------------------------------- reading the inputs

ROOT_ATTRS = (
    "phases",
    "phases_before",
    "score_before",
    "score_after",
    "scores_before",
    "scores_after",
    "simulations",
    "wall_seconds",
)


def read_composite(path: str | Path) -> CompositeResult:
    """Read a composite result file and check that its parts agree: PlotInputError naming the
    file and what is missing or malformed."""
    try:
        result = read_composite_result(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    for key in ROOT_ATTRS:
        if key not in result.attrs:
            raise PlotInputError(f"{path}: not a composite result file: no root attribute {key!r}")
    try:
        tables = {"phases": result.phases, "phases_before": result.phases_before}
        scores = {"scores_before": result.scores_before, "scores_after": result.scores_after}
    except (json.JSONDecodeError, TypeError) as error:
        raise PlotInputError(f"{path}: a root attribute is not valid JSON: {error}") from None
    for key, table in tables.items():
        if not table or not all(
            isinstance(phase, dict) and {"name", "controller", "start", "end"} <= phase.keys()
            for phase in table
        ):
            raise PlotInputError(
                f"{path}: root attribute {key!r} must be a non-empty JSON list of objects with "
                f"name, controller, start and end"
            )
    names = [phase["name"] for phase in tables["phases"]]
    if [phase["name"] for phase in tables["phases_before"]] != names:
        raise PlotInputError(f"{path}: 'phases' and 'phases_before' name different phases")
    for key, table in scores.items():
        if not isinstance(table, dict) or set(table) != set(names):
            raise PlotInputError(
                f"{path}: root attribute {key!r} must score each phase ({', '.join(names)})"
            )
    for where, stored in (("", result.after), ("before/", result.before)):
        _check_motion(path, where, stored, len(names))
    if result.best_by_generation.ndim != 1:
        raise PlotInputError(
            f"{path}: search/best_score has shape {result.best_by_generation.shape}, expected "
            f"(G,): one best total per generation"
        )
    return result


def _check_motion(path: str | Path, where: str, stored: CompositeMotion, phases: int) -> None:
    samples = len(stored.motion.t)
    if samples == 0:
        raise PlotInputError(f"{path}: {where}figure_motion has no samples")
    endpoints = stored.motion.endpoints
    if endpoints.ndim != 4 or endpoints.shape[0] != samples or endpoints.shape[2:] != (2, 2):
        raise PlotInputError(
            f"{path}: {where}figure_motion/endpoints has shape {endpoints.shape}, expected "
            f"({samples}, rods, 2, 2): one row per sample of t"
        )
    phase = stored.phase
    if phase.shape != (samples,):
        raise PlotInputError(
            f"{path}: {where}phase has shape {phase.shape}, expected ({samples},): one phase per "
            f"sample of {where}figure_motion/t"
        )
    if phase.min() < 0 or phase.max() >= phases:
        raise PlotInputError(
            f"{path}: {where}phase holds {int(phase.min())} to {int(phase.max())}, expected "
            f"phase indices 0 to {phases - 1}"
        )


def script_name(result: CompositeResult, path: str | Path) -> str:
    """A result's script name: its ``name`` or ``script`` attribute, else the file's stem."""
    for key in ("name", "script"):
        if key in result.attrs:
            return str(result.attrs[key])
    return Path(path).stem


def score_text(value: float) -> str:
    """A score to three significant digits (a true minus sign; 0 for |value| < 1e-9)."""
    return distinct_text(float(value), float(value))


def _same_transitions(before: Sequence[Mapping], after: Sequence[Mapping]) -> bool:
    """Whether the refined phases are the guessed ones (the same durations)."""
    return [phase.get("ticks") for phase in before] == [phase.get("ticks") for phase in after]


def score_texts(before: float, after: float) -> tuple[str, str]:
    """Two scores as ``score_text`` writes them, with more digits where three would show a
    change as none ('1.64 → 1.64' for 1.6429 → 1.6445)."""
    return distinct_text(before, after), distinct_text(after, before)


def distinct_text(value: float, other: float) -> str:
    """``value`` to three significant digits, or as many more (up to 10) as it takes not to
    read as ``other`` when the two differ; a true minus sign; 0 for |value| < 1e-9."""

    def shown(number: float, digits: int) -> str:
        return "0" if abs(number) < 1e-9 else f"{number:.{digits}g}"

    digits = 3
    while digits < 10 and value != other and shown(value, digits) == shown(other, digits):
        digits += 1
    return minus_signs(shown(value, digits))


def phase_colors(phases: Sequence[Mapping]) -> list[tuple[float, float, float, float]]:
    """One distinct colour per phase, in the script's order (``controller_colors`` of their
    names; a name used twice gets one colour)."""
    colors = controller_colors(list(dict.fromkeys(str(phase["name"]) for phase in phases)))
    return [colors[str(phase["name"])] for phase in phases]


def shade(color: ColorType, fraction: float) -> tuple[float, float, float, float]:
    """``color`` for a pose ``fraction`` (0..1) of the way through its phase: mixed LIGHTEST
    with white at 0, pure at 1."""
    return lighten(color, LIGHTEST * (1.0 - float(np.clip(fraction, 0.0, 1.0))))


# --------------------------------------------------------------------------- the filmstrips


@dataclass(frozen=True)
class StripPoses:
    """The poses one filmstrip panel draws, in time order: ``samples`` (K,) int64 indices into
    the motion's samples; ``phase`` (K,) int64, the phase each belongs to (a switch pose: the
    phase it starts); ``switch`` (K,) bool, the pose is at a switch between phases;
    ``fraction`` (K,) float64, how far through its phase the pose is (0 start, 1 end)."""

    samples: np.ndarray
    phase: np.ndarray
    switch: np.ndarray
    fraction: np.ndarray


def switch_samples(t: np.ndarray, phases: Sequence[Mapping]) -> np.ndarray:
    """The sample (int64) at the start of each phase after the first (the first at or after
    its ``start``, s), one per switch, non-decreasing; t: (N,) s, non-decreasing."""
    starts = np.array([float(phase["start"]) for phase in phases[1:]], dtype=np.float64)
    return np.minimum(np.searchsorted(t, starts - 1e-9), len(t) - 1).astype(np.int64)


def strip_poses(
    t: np.ndarray, phase: np.ndarray, phases: Sequence[Mapping], interval: float
) -> StripPoses:
    """The poses of a filmstrip panel: one every ``interval`` s from the start
    (``frame_indices``), the last sample, and the pose at each switch (``switch_samples``); a
    regular pose within CLOSE_TO_SWITCH intervals of a switch is left out, as the switch pose
    stands for it. t: (N,) s; phase: (N,) int64, each sample's phase; phases: the result's
    ``phases`` table (start and end in s)."""
    t = np.asarray(t, dtype=np.float64)
    switches = switch_samples(t, phases)
    regular = np.union1d(frame_indices(t, interval), [len(t) - 1])
    if len(switches):
        nearest = np.abs(t[regular][:, None] - t[switches][None, :]).min(axis=1)
        regular = regular[nearest >= CLOSE_TO_SWITCH * interval - 1e-9]
    samples = np.unique(np.concatenate([regular, switches])).astype(np.int64)
    is_switch = np.isin(samples, switches)
    belongs = phase[samples].astype(np.int64)
    for k, sample in enumerate(switches, start=1):  # the phase a switch starts
        belongs[samples == sample] = k
    start = np.array([float(phases[k]["start"]) for k in belongs])
    end = np.array([float(phases[k]["end"]) for k in belongs])
    span = np.where(end > start, end - start, 1.0)
    fraction = np.clip((t[samples] - start) / span, 0.0, 1.0)
    return StripPoses(samples, belongs, is_switch, fraction)


def switch_labels(phases: Sequence[Mapping], switches: np.ndarray, t: np.ndarray) -> list[str]:
    """One label per distinct switch sample: its time and the phases it goes between
    (``1.43 s\\ncartwheel → jump``)."""
    labels = []
    for sample in np.unique(switches):
        ks = [k for k, s in enumerate(switches, start=1) if s == sample]
        ending, starting = phases[ks[0] - 1]["name"], phases[ks[-1]]["name"]
        labels.append(f"{t[sample]:.2f} s\n{ending} → {starting}")
    return labels


def _phase_label(phase: Mapping) -> str:
    seed = f" seed {phase['seed']}" if "seed" in phase else ""
    start, end = float(phase["start"]), float(phase["end"])
    span = f"{end - start:.2f} s ({start:.2f}–{end:.2f} s)"
    return f"{phase['name']}: {phase['controller']}{seed}, {span}"


def _scores_text(total: float, scores: Mapping[str, float], phases: Sequence[Mapping]) -> str:
    parts = ", ".join(f"{p['name']} {score_text(scores[p['name']])}" for p in phases)
    return f"script total {score_text(total)} (phase scores: {parts})"


@dataclass(frozen=True)
class _Panel:
    heading: str
    stored: CompositeMotion
    phases: list[dict]
    poses: StripPoses
    labels: list[str]
    label_at: np.ndarray  # (S, 2) m: the highest rod end of each switch pose, its label's target


def plot_filmstrips(
    result_path: str | Path, path: str | Path, interval: float | None = None
) -> None:
    """Write ``filmstrips_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(filmstrips_figure(result_path, interval), path)


def narrowed(
    data_width: float, scale: float, panel_height: float, x_span: float
) -> tuple[float, float]:
    """The data width (inches) and scale (m per inch) of a panel ``panel_height`` inches tall
    at ``scale``, made PANEL_HEIGHT_MAX tall: narrower by that ratio, the scale larger by it,
    and larger still where that keeps STRIP_MARGIN inches of blank round poses ``x_span`` m
    wide (scaling the margin with the panel left a fortieth of an inch, and the outermost
    rods' round ends were cut in half); a panel too narrow for two margins keeps the ratio."""
    data_width *= PANEL_HEIGHT_MAX / panel_height
    scale *= panel_height / PANEL_HEIGHT_MAX
    if data_width > 4 * STRIP_MARGIN:
        scale = max(scale, x_span / (data_width - 2 * STRIP_MARGIN))
    return data_width, scale


def filmstrips_figure(result_path: str | Path, interval: float | None = None) -> Figure:
    """Figures 13 and 14 in one figure: above, the motion from the guessed transition points
    (``before/figure_motion``); below, the refined one (``figure_motion``). Each panel draws
    the figure's rods (lines with round ends, m) every ``interval`` s (None: a round interval
    giving 12 to 20 poses over the longer motion, ``choose_interval``) and at its end, each
    phase in its own colour, light at the phase's start to full at its end; the pose at each
    switch between phases is drawn in black, thicker, and labelled with its time (s) and the
    phases it goes between. Both panels share one scale and one view (m), equal aspect, over
    the ground; poses are drawn where they are and may overlap. Each panel's title gives the
    script total and each phase's score, its legend each phase's controller (and seed),
    duration and time span (s)."""
    result = read_composite(result_path)
    t_ends = [float(s.motion.t[-1] - s.motion.t[0]) for s in (result.before, result.after)]
    if interval is None:
        interval = choose_interval(max(t_ends))
    if not interval > 0:
        raise ValueError(f"interval must be a positive number of seconds, got {interval!r}")
    colors = phase_colors(result.phases)
    panels = []
    for heading, stored, phases, total, scores in (
        (
            "Before refinement (Figure 13): the guessed transition points",
            result.before,
            result.phases_before,
            result.attrs["score_before"],
            result.scores_before,
        ),
        (
            "After refinement (Figure 14): the transition points found by the search"
            + (  # identical panels looked like a mistake
                " (the guess's: the search found none better)"
                if _same_transitions(result.phases_before, result.phases)
                else ""
            ),
            result.after,
            result.phases,
            result.attrs["score_after"],
            result.scores_after,
        ),
    ):
        t = stored.motion.t
        poses = strip_poses(t, stored.phase, phases, interval)
        switches = switch_samples(t, phases)
        rod_ends = stored.motion.endpoints[np.unique(switches)]
        rod_ends = rod_ends.reshape(len(rod_ends), rod_ends.shape[1] * 2, 2)  # (S, ends, 2) m
        label_at = rod_ends[np.arange(len(rod_ends)), rod_ends[..., 1].argmax(axis=1)]
        panels.append(
            _Panel(
                f"{heading}\n{_scores_text(total, scores, phases)}",
                stored,
                phases,
                poses,
                switch_labels(phases, switches, t),
                label_at,
            )
        )

    # one view for both panels: every drawn pose, and the ground under them
    drawn = np.concatenate([p.stored.motion.endpoints[p.poses.samples] for p in panels])
    x_low, x_high = float(drawn[..., 0].min()), float(drawn[..., 0].max())
    terrain = result.after.motion.terrain
    ground_low = _ground_low(terrain, x_low, x_high)
    low = min(float(drawn[..., 1].min()), ground_low)
    top = float(drawn[..., 1].max())
    data_width = STRIP_WIDTH
    scale = max((x_high - x_low) / (data_width - 2 * STRIP_MARGIN), 1e-6)  # m per inch

    def layout(data_width: float, scale: float):
        """The view's x and y limits (m), each panel's switch labels' x (m) and rows, and the
        height of the lowest row (m), at ``scale`` m per inch."""
        middle = (x_low + x_high) / 2
        x0, x1 = middle - data_width * scale / 2, middle + data_width * scale / 2
        places = [switch_label_places(p.label_at[:, 0], x0, x1, scale) for p in panels]
        rows = max((int(level.max()) + 1 for _, level in places if level.size), default=0)
        y0 = low - STRIP_GROUND * scale
        base = top + SWITCH_LABEL_PAD * scale
        y1 = base + (rows * SWITCH_LABEL_ROW + STRIP_MARGIN) * scale
        return (x0, x1), (y0, y1), places, base

    (x0, x1), (y0, y1), places, label_base = layout(data_width, scale)
    panel_height = (y1 - y0) / scale
    if panel_height > PANEL_HEIGHT_MAX:  # a tall scene: narrower panels at a larger scale
        data_width, scale = narrowed(data_width, scale, panel_height, x_high - x_low)
        (x0, x1), (y0, y1), places, label_base = layout(data_width, scale)
        panel_height = (y1 - y0) / scale

    title = (
        f"Composite motion {script_name(result, result_path)}: the trajectory before and after "
        f"the transition points are refined\nthe figure every {interval:g} s, each phase in its "
        "colour (light → dark through the phase); black: the pose at a switch, labelled"
    )
    legend_rows = [-(-(len(p.phases) + 1) // LEGEND_COLUMNS) for p in panels]
    header = MARGIN_TOP + 0.1 + 2 * TITLE_LINE  # the figure's two-line title
    heading = 0.12 + 2 * TITLE_LINE  # a panel's two-line title
    below = [MARGIN_BOTTOM + LEGEND_ROW * (rows + 1) for rows in legend_rows]
    fig_width = max(MARGIN_LEFT + data_width + MARGIN_RIGHT, FIGURE_WIDTH_MIN)
    axes_left = max(MARGIN_LEFT, (fig_width - data_width + MARGIN_LEFT - MARGIN_RIGHT) / 2)
    fig_height = header + sum(heading + panel_height + b for b in below) + PANEL_GAP
    with plot_style():
        figure = new_figure(fig_width, fig_height)
        figure.suptitle(title, y=1 - 0.1 / fig_height, va="top", fontsize=11)
        top_edge = fig_height - header
        for panel, place, under in zip(panels, places, below, strict=True):
            axes_top = top_edge - heading
            bottom = axes_top - panel_height
            ax = figure.add_axes(
                (
                    axes_left / fig_width,
                    bottom / fig_height,
                    data_width / fig_width,
                    panel_height / fig_height,
                )
            )
            ax.set_xlim(x0, x1)
            ax.set_ylim(y0, y1)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
            ax.grid(alpha=0.2)
            ax.set_title(panel.heading, fontsize=10, loc="left")
            draw_terrain(ax, terrain, y0 - 1.0)
            _draw_strip(ax, panel, colors, place, label_base, scale)
            entries = [
                (Line2D([], [], color=colors[k], linewidth=ROD_WIDTH + 1), _phase_label(phase))
                for k, phase in enumerate(panel.phases)
            ]
            if len(panel.labels):
                entries.append(
                    (
                        Line2D([], [], color=SWITCH_COLOR, linewidth=SWITCH_WIDTH),
                        "the pose at a switch (its time above it)",
                    )
                )
            figure.legend(
                [handle for handle, _ in entries],
                [label for _, label in entries],
                loc="upper center",
                bbox_to_anchor=(0.5, (bottom - MARGIN_BOTTOM + 0.05) / fig_height),
                ncols=min(LEGEND_COLUMNS, len(entries)),
                fontsize=8.5,
                framealpha=0.9,
            )
            top_edge = bottom - under - PANEL_GAP
    return figure


def switch_label_places(
    x: np.ndarray, x0: float, x1: float, scale: float
) -> tuple[np.ndarray, np.ndarray]:
    """Where the switch labels of one panel go: a row each (0 lowest; as few rows as hold
    them, labels taken in turn from left to right) and their x (m), moved apart from the
    poses' ``x`` (m) to SWITCH_LABEL_WIDTH inches apart within a row and kept inside the view
    x0..x1 (m) (``spread_labels``); ``scale``: m per inch."""
    x = np.asarray(x, dtype=np.float64)
    gap = SWITCH_LABEL_WIDTH * scale
    fit = max(int((x1 - x0) // gap), 1)  # labels a row holds
    rows = -(-len(x) // fit)
    levels = np.zeros(len(x), dtype=np.int64)
    placed = x.copy()
    for row in range(rows):
        members = np.argsort(x, kind="stable")[row::rows]
        levels[members] = row
        placed[members] = spread_labels(x[members], gap, x0 + gap / 2, x1 - gap / 2)
    return placed, levels


def _ground_low(terrain: list, x0: float, x1: float) -> float:
    """The lowest ground (m) between x0 and x1; +inf without terrain."""
    if not terrain:
        return np.inf
    ground = np.asarray(terrain, dtype=np.float64)
    inside = ground[(ground[:, 0] > x0) & (ground[:, 0] < x1), 1]
    ends = np.interp([x0, x1], ground[:, 0], ground[:, 1])
    return float(np.concatenate([inside, ends]).min())


def _draw_strip(ax, panel: _Panel, colors, place, label_base: float, scale: float) -> None:
    """The poses of one panel (later ones above earlier ones, switch poses above all) and the
    switch labels at ``place`` (x, m, and row, as ``switch_label_places``) above
    ``label_base`` (m), an arrow from each to its pose."""
    poses, ends = panel.poses, panel.stored.motion.endpoints
    count = len(poses.samples)
    for j, sample in enumerate(poses.samples):
        if poses.switch[j]:
            draw_pose(ax, ends[sample], SWITCH_COLOR, 5 + j / count)
            ax.add_collection(  # thicker than the others
                LineCollection(
                    ends[sample],
                    colors=[SWITCH_COLOR],
                    linewidths=SWITCH_WIDTH,
                    capstyle="round",
                    zorder=5 + j / count,
                ),
                autolim=False,
            )
        else:
            color = shade(colors[poses.phase[j]], poses.fraction[j])
            draw_pose(ax, ends[sample], color, 3 + j / count)
    label_x, levels = place
    for label, target, level, x in zip(panel.labels, panel.label_at, levels, label_x, strict=True):
        ax.annotate(
            label,
            xy=(target[0], target[1] + 0.03 * scale),
            xytext=(x, label_base + level * SWITCH_LABEL_ROW * scale),
            ha="center",
            va="bottom",
            fontsize=SWITCH_LABEL_SIZE,
            linespacing=1.1,
            arrowprops={"arrowstyle": "-|>", "color": "0.25", "linewidth": 0.8, "shrinkA": 1},
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.85, "lw": 0},
            zorder=10,
        )


# --------------------------------------------------------------------------- the search


def search_curve(result: CompositeResult) -> tuple[np.ndarray, np.ndarray]:
    """The search's progress: generations (G + 1,) int64, 0 to G, and the best script total
    after each, the guess's (``score_before``) at generation 0."""
    best = np.asarray(result.best_by_generation, dtype=np.float64)
    scores = np.concatenate([[float(result.attrs["score_before"])], best])
    return np.arange(len(scores), dtype=np.int64), scores


def plot_search(result_path: str | Path, path: str | Path) -> None:
    """Write ``search_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(search_figure(result_path), path)


def drawable_scores(scores: np.ndarray) -> np.ndarray:
    """``scores`` (any shape) as float64 with nan where a value cannot be drawn: ±inf, nan or
    beyond ±DRAWABLE_SCORE."""
    values = np.asarray(scores, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        return np.where(np.abs(values) <= DRAWABLE_SCORE, values, np.nan)


def score_limits(scores: np.ndarray, before: float) -> tuple[float, float] | None:
    """The y-axis limits of the search's scores (G + 1,) and the guess's total ``before``:
    their finite values with a margin below and above (the script's arithmetic may give ±inf
    or nan, which no axis can hold); None, matplotlib's own, where no value is finite or the
    limits or their distance overflow."""
    finite_scores = scores[np.isfinite(scores)]
    finite_before = [before] if np.isfinite(before) else []
    if finite_scores.size == 0 and not finite_before:
        return None
    low = min([*finite_scores, *finite_before])
    high = max(finite_scores) if finite_scores.size else before
    with np.errstate(over="ignore"):
        span = float(np.ptp(finite_scores)) if finite_scores.size else 0.0
        span = span or max(abs(before) if finite_before else abs(high), 1.0)
        limits = (low - 0.12 * span, high + 0.08 * span)
        width = limits[1] - limits[0]  # what the tick locator divides: it must be finite too
    return limits if np.isfinite([*limits, width]).all() and width > 0 else None


def search_figure(result_path: str | Path) -> Figure:
    """Figure 5's transition-point search (``search_plot``) of the composite result at
    ``result_path``, annotated with the search's size (Q, G, H), the simulations it ran and its
    wall time (s)."""
    result = read_composite(result_path)
    generations, scores = search_curve(result)
    attrs = result.attrs
    size = (
        f"Q = {attrs['search_q']}, G = {attrs['search_g']}, H = {attrs['search_h']}: "
        if {"search_q", "search_g", "search_h"} <= attrs.keys()
        else ""
    )
    facts = (
        f"{size}{int(attrs['simulations']):,} simulations in {float(attrs['wall_seconds']):.3g} s"
    )
    return search_plot(
        generations,
        scores,
        float(attrs["score_after"]),
        facts,
        script_name(result, result_path),
    )


def search_plot(
    generations: np.ndarray, scores: np.ndarray, after: float, facts: str, name: str
) -> Figure:
    """Figure 5's transition-point search of the script ``name``: the best script total (the
    script's ``total``, unitless) ``scores`` (G + 1,) after each of the ``generations`` 0 to G
    (0: the guessed transition points), a dotted line at the guess's total ``scores[0]``; a
    note of ``facts`` (one line), the totals before and ``after`` and the gain. Any doubles
    are drawn: those no axis can hold (``drawable_scores``) are left out, and the note says so."""
    before = float(scores[0])
    shown_before, shown_after = score_texts(before, after)
    note = f"{facts}\nscript total {shown_before} → {shown_after}"
    if before > 0 and np.isfinite(before) and np.isfinite(after):
        note += f" (× {distinct_text(after / before, 1.0)})"
    drawn_scores, (drawn_before,) = drawable_scores(scores), drawable_scores([before])
    if np.isnan(drawn_scores).any():
        note += (
            f"\nscores of ±inf, nan or beyond ±{DRAWABLE_SCORE:.0e} (the script's arithmetic)"
            " are not drawn"
        )
    with plot_style():
        figure = new_figure(SEARCH_WIDTH, SEARCH_HEIGHT)
        ax = figure.subplots()
        if not np.isnan(drawn_before):
            ax.axhline(drawn_before, color=GUESS_COLOR, linestyle=":", linewidth=1.3, zorder=1)
            ax.annotate(
                f"the guess: {shown_before}",
                xy=(generations[-1], drawn_before),
                xytext=(0, -4),
                textcoords="offset points",
                ha="right",
                va="top",
                color=GUESS_COLOR,
                fontsize=9,
            )
        ax.step(generations, drawn_scores, where="post", color=CURVE_COLOR, lw=1.8, zorder=3)
        ax.plot(generations, drawn_scores, "o", color=CURVE_COLOR, markersize=4, zorder=4)
        ax.text(
            0.98,
            0.5,
            note,
            transform=ax.transAxes,
            ha="right",
            va="center",
            fontsize=9.5,
            bbox={"boxstyle": "round,pad=0.35", "facecolor": "white", "alpha": 0.9},
        )
        ax.set_xlim(-0.3, max(generations[-1], 1) + 0.3)
        limits = score_limits(drawn_scores, drawn_before)
        if limits is not None:
            ax.set_ylim(*limits)
        ax.xaxis.get_major_locator().set_params(integer=True)
        ax.set_xlabel("generation (0: the guessed transition points)")
        ax.set_ylabel("best script total so far")
        ax.set_title(
            f"Composite motion {name}: transition-point search "
            "(Figure 5)\nthe best script total after each generation",
            fontsize=11,
        )
        figure.subplots_adjust(
            left=MARGIN_LEFT / SEARCH_WIDTH,
            right=1 - MARGIN_RIGHT / SEARCH_WIDTH,
            bottom=MARGIN_BOTTOM / SEARCH_HEIGHT,
            top=1 - (MARGIN_TOP + 2 * TITLE_LINE + 0.1) / SEARCH_HEIGHT,
        )
        keep_left_labels_in(figure, ax)  # a search that gained 0.002: ticks of 6 digits
    return figure


# --------------------------------------------------------------------------- the animation


def write_composite_gif(
    result_path: str | Path,
    path: str | Path,
    fps: int = GIF_FPS,
    max_frames: int = GIF_MAX_FRAMES,
) -> None:
    """An animated GIF of the refined composite motion, to scale in metres, the whole travel in
    view: the terrain, the rods (lines with round ends) coloured by phase (legend: each phase's
    controller and time span, s), and in the corners the time (s) and the current phase's
    name. One frame per 1/``fps`` s of motion time (every 40 ms by default), played in real
    time, the step widened to keep to ``max_frames`` frames (``frame_samples``); the last frame
    held GIF_HOLD_MS ms; loops. Written atomically."""
    check_animation_options(fps, max_frames)
    result = read_composite(result_path)
    stored, phases = result.after, result.phases
    motion = stored.motion
    t, endpoints = motion.t, motion.endpoints
    samples, step = frame_samples(t, int(fps), int(max_frames))
    limits = scene_limits(endpoints[samples].reshape(-1, 2), motion.terrain)
    colors = phase_colors(phases)
    phase = stored.phase[samples]
    title = (
        f"Composite motion {script_name(result, result_path)}, refined (Figure 14): script "
        f"total {score_text(result.attrs['score_after'])}\nrods coloured by phase, played in "
        "real time"
    )
    entries = [
        (Line2D([], [], color=colors[k], linewidth=ROD_WIDTH + 1), _phase_label(p))
        for k, p in enumerate(phases)
    ]
    with plot_style():
        figure, ax, _ = scene_figure(
            limits, GIF_WIDTH, title.count("\n") + 1, legend_rows=len(entries), dpi=GIF_DPI
        )
        figure.suptitle(title, y=1 - 0.08 / figure.get_size_inches()[1], va="top", fontsize=9)
        add_legend(figure, entries, ncols=1, fontsize=8)
        draw_terrain(ax, motion.terrain, limits[0, 1] - 1.0)

        def look(frame: int) -> tuple:
            k = int(phase[frame])
            return colors[k], str(phases[k]["name"]), colors[k]

        frames = animate_stick_figure(figure, ax, t, endpoints, samples, look, label_size=12)
    write_real_time_gif(frames, path, step)
