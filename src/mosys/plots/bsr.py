"""BSR searches' best motions (Auslander et al. 1995, "Further Experience with
Controller-Based Automatic Motion Synthesis for Articulated Figures", Figures 9 to 12), drawn from
search results ``results/bsr/NAME/seedK.h5`` of 2-D figures (their learning curves are
``mosys.plots.bsr_learning``'s):

- ``plot_filmstrip``: Figures 9 to 12, the best motion as rods at regular times, each pose
  lettered with the rule active then.
- ``write_motion_gif``: an animated GIF of the best motion.

Rules are named by letter, rule 0 ``A``, rule 1 ``B``, ... (``rule_letter``); ``active_rule`` -1
(no rule active) shows as a dash. The figure is drawn from ``best/figure_motion`` only: each rod
a line with round ends, metres in the world frame, y up, equal aspect, over the terrain.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from mosys.io.bsr_result import BsrResult
from mosys.plots.bsr_results import (
    KIND_TEXT,
    motion_fitness,
    read_result,
    result_kind,
    search_name,
    terms_text,
)
from mosys.plots.style import (
    ASPECT_RANGE,
    FOLLOW_POSES,
    GIF_DPI,
    GIF_FPS,
    GIF_MAX_FRAMES,
    MARGIN_BOTTOM,
    MARGIN_LEFT,
    MARGIN_TOP,
    POSE_TIMES,
    STRIP_GROUND,
    STRIP_MARGIN,
    TITLE_LINE,
    animate_stick_figure,
    check_animation_options,
    choose_interval,
    controller_colors,
    draw_pose,
    draw_terrain,
    fit_aspect,
    frame_indices,
    frame_samples,
    new_figure,
    number_text,
    plot_style,
    save_figure,
    scene_figure,
    scene_limits,
    write_real_time_gif,
)

NO_RULE = "–"  # the letter of active_rule -1

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
NONE_COLOR = "0.45"  # rods while no rule is active


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
    kind = result_kind(result)
    text = f"{KIND_TEXT.get(kind, kind)} controller, {result.controller.rules} rules"
    if kind == "time" and math.isfinite(result.controller.period):
        text += f", period {result.controller.period:g} s"
    return text


def _result_title(result: BsrResult, path: str | Path) -> str:
    name = search_name(result.attrs, path)
    figure_name = result.attrs.get("figure", "")
    on = f" ({figure_name})" if figure_name else ""
    seed = int(result.attrs["seed"])
    fitness = number_text(motion_fitness(result.attrs), ".4g")
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

    kind = result_kind(result)
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
            f"{number_text(travel, '+.2f')} m)"
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
