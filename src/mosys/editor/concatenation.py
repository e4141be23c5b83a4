"""The interactive concatenation editor (``mosys edit SCRIPT``): the 1995 paper's §3 "graphical
editor for animation that allows a user to switch between precomputed, sense-based motion
controllers interactively, using a simple interface in which the time duration for which each
precomputed controller is executed is specified by a slider bar".

One slider per phase of a composite script (``specs/composite/NAME.comp``) sets that phase's
duration in simulator ticks. Each move runs the concatenation again through the script's
``CompositeSession`` (the runtime and score evaluator of ``mosys composite``) and redraws:

- the motion as a filmstrip to scale in metres: the figure's rods at regular instants, each
  phase in its own colour, over the floor, with the centre of mass's path and the switches;
- the heights over time (the centre of mass, the lowest rod end) with the switch times;
- the script's scores: each phase's beside its slider, the total above them.

"Save" writes the chosen durations into the script's ``ticks=`` values and changes nothing else
in the file (``script_text_with_ticks``), so that ``mosys composite`` starts its transition
search from them; the saved script's guessed durations give the same scores.

The figure is built with matplotlib's object API and its widgets; the editor's logic is driven
through ``set_duration``/``set_durations``/``save`` (what the sliders and buttons call), so it runs
headless on an Agg canvas. ``run_editor`` opens it in a window.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.text import Text
from matplotlib.widgets import Button, Slider

from mosys.composite.result_file import check_size
from mosys.composite.session import CompositeSession
from mosys.errors import InputError, NonFiniteStateError
from mosys.io.atomic import write_text_atomically
from mosys.limits import LimitError
from mosys.parsing.composite import parse_composite_text, render_expression
from mosys.parsing.composite_script import CompositeScript
from mosys.parsing.tokens import read_spec_text
from mosys.plots.style import (
    JOINT_SIZE,
    OUTLINE,
    ROD_WIDTH,
    TERRAIN_EDGE,
    TERRAIN_FACE,
    choose_interval,
    controller_colors,
    new_figure,
    plot_style,
)

POSES = (15, 25)  # the filmstrip's interval is a round one drawing about this many poses
SLIDER_SPAN = 3  # a phase's slider runs from 1 tick to this many times its guess (or the total)
# the view of the filmstrip: every rod end with VIEW_MARGIN m all round and GROUND_SHOWN m of
# floor, its edges rounded out to VIEW_GRID m; the views of both plots stay while what they show
# fits in them and fills at least KEEP_FILLING of their width and height (a move that changes
# a view draws the whole figure again)
VIEW_MARGIN, GROUND_SHOWN, VIEW_GRID = 0.15, 0.2, 0.25
TIME_GRID = 0.5  # s: the heights over time end at the motion's end rounded up to this
KEEP_FILLING = 0.6
SCORE_FORMAT = ".3f"

# layout, inches
WIDTH = 13.0
LEFT, RIGHT = 0.75, 0.3  # margins of the plots
HEADER = 1.05  # the title (two lines) and the phases' legend
SCENE_HEIGHT = 3.5
SCENE_GAP = 0.5  # below the scene: its x label
TRACE_HEIGHT = 1.15
TRACE_GAP = 0.55  # below the heights over time: their x label
TOTAL_ROW = 0.4  # the total's line
TOTAL_WIDTH = 1.15  # its number; its formula right of it
SLIDER_ROW = 0.4  # one phase's slider
SLIDER_LEFT, SLIDER_WIDTH = 1.6, 5.2  # the sliders' track; its name left of it
VALUE_WIDTH = 1.0  # right of the track: its "N ticks"; then the phase's time and score
PHASE_WIDTH = 1.75  # ...; then the phase's score formula
BUTTON_ROW = 0.55  # Save, Reset and the status line
BUTTON_WIDTH, BUTTON_HEIGHT, BUTTON_GAP = 0.9, 0.32, 0.15
BOTTOM = 0.12


def editor_size(phases: int) -> tuple[float, float]:
    """The editor figure's width and height, inches, for a script of ``phases`` phases."""
    height = (
        HEADER
        + SCENE_HEIGHT
        + SCENE_GAP
        + TRACE_HEIGHT
        + TRACE_GAP
        + TOTAL_ROW
        + SLIDER_ROW * phases
        + BUTTON_ROW
        + BOTTOM
    )
    return WIDTH, height


def pose_samples(samples: int, dt: float, poses: tuple[int, int] = POSES) -> np.ndarray:
    """The samples (K,) int64 of a motion of ``samples`` samples (one per tick of ``dt`` s and
    the start) whose poses the filmstrip draws: 0 and every ``every`` ticks after it, ``every``
    the round interval of ``choose_interval`` for ``poses`` poses, in whole ticks (at least 1)."""
    duration = (samples - 1) * dt
    every = max(1, round(choose_interval(duration, poses) / dt)) if samples > 1 else 1
    return np.arange(0, samples, every, dtype=np.int64)


def motion_bounds(rod_ends: np.ndarray, floor: float, grid: float = VIEW_GRID) -> np.ndarray:
    """[[x0, y0], [x1, y1]] m around every rod end (..., 2) m of a motion with VIEW_MARGIN m all
    round and, if there is a floor (its height ``floor`` m; nan: none), GROUND_SHOWN m of it,
    the edges rounded out to ``grid`` m."""
    points = np.asarray(rod_ends, np.float64).reshape(-1, 2)
    low = points.min(axis=0) - VIEW_MARGIN
    high = points.max(axis=0) + VIEW_MARGIN
    if not math.isnan(floor):
        low[1] = min(low[1], floor - GROUND_SHOWN)
    return np.array([np.floor(low / grid) * grid, np.ceil(high / grid) * grid])


def fit_box(bounds: np.ndarray, box: tuple[float, float]) -> np.ndarray:
    """``bounds`` [[x0, y0], [x1, y1]] m widened to the aspect of ``box`` (width, height)
    inches at one scale: x about its middle, y upwards (the floor stays at the bottom)."""
    (x0, y0), (x1, y1) = bounds
    width, height = box
    scale = max((x1 - x0) / width, (y1 - y0) / height)  # m per inch
    middle = (x0 + x1) / 2
    return np.array(
        [[middle - scale * width / 2, y0], [middle + scale * width / 2, y0 + scale * height]]
    )


def keeps(view: np.ndarray | None, bounds: np.ndarray, equal_aspect: bool) -> bool:
    """Whether the view [[x0, y0], [x1, y1]] still suits what must be shown, ``bounds`` (the
    same form; None: no view yet): they fit in it and fill at least KEEP_FILLING of its width
    and of its height, or, for a view of ``equal_aspect`` (whose other side follows), of its
    width or of its height."""
    if view is None:
        return False
    inside = bool(np.all(view[0] <= bounds[0]) and np.all(bounds[1] <= view[1]))
    filling = (bounds[1] - bounds[0]) / (view[1] - view[0])
    return inside and bool((filling.max() if equal_aspect else filling.min()) >= KEEP_FILLING)


def _whole_ticks(value, what: str) -> int:
    """``value`` as a whole number of ticks >= 1 (an int, or a float with no fraction, as a
    slider gives); ValueError naming ``what`` otherwise."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number == round(number) and number >= 1):
        raise ValueError(f"{what}: a duration is a whole number of ticks >= 1, got {value!r}")
    return int(number)


def script_text_with_ticks(text: str, script: CompositeScript, ticks: Sequence[int]) -> str:
    """``text``, the ``.comp`` text that ``script`` was parsed from, with phase k's duration set
    to ``ticks[k]`` (P,) whole ticks >= 1: a phase line with ``ticks=`` gets the new value in
    place of the old one; a phase line without (a script of equally spaced phases) gets
    `` ticks=N`` after its last word, before any comment. Every other character, the line ends
    included, is kept. ValueError if ``script``'s words are not where it says in ``text``."""
    if len(ticks) != len(script.phases):
        raise ValueError(f"{len(script.phases)} durations for the phases, got {len(ticks)}")
    lines = text.split("\n")  # as the tokenizer counts lines: '\r' stays with its line

    def located(key: str):
        token = script.tokens[key]
        start = token.column - 1
        line = lines[token.line - 1] if 0 < token.line <= len(lines) else ""
        if line[start : start + len(token.text)] != token.text:
            raise ValueError(
                f"{script.path}: the text is not the one parsed ({key} {token.text!r} is not at "
                f"{token.line}:{token.column})"
            )
        return token, start, start + len(token.text)

    for phase, value in zip(script.phases, ticks, strict=True):
        count = _whole_ticks(value, f"phase {phase.name}")
        key = f"phase.{phase.name}"
        if f"{key}.ticks" in script.tokens:
            token, start, end = located(f"{key}.ticks")
            replacement = str(count)
        else:
            words = [key] + [f"{key}.{part}" for part in ("controller", "seed")]
            ends = [located(word) for word in words if word in script.tokens]
            token, _, start = max(ends, key=lambda found: found[2])
            end = start
            replacement = f" ticks={count}"
        line = lines[token.line - 1]
        lines[token.line - 1] = line[:start] + replacement + line[end:]
    return "\n".join(lines)


def score_text(value: float) -> str:
    """A score as shown: SCORE_FORMAT, a value that rounds to zero without a minus sign."""
    text = format(value, SCORE_FORMAT)
    return format(0.0, SCORE_FORMAT) if float(text) == 0 else text


class ConcatenationEditor:
    """The editor of one composite script: ``session`` (its controllers, start and scores) and
    ``script_path``, the ``.comp`` file that Save rewrites (the one ``session.script`` was parsed
    from). Draws on ``figure`` (a pyplot figure for a window; None: a new figure on an Agg
    canvas, for tests and PNGs), starting from ``session.guess``.

    ``ticks`` (P,) the current durations, ticks; ``scored`` their ``ScoredMotion``;
    ``saved_ticks`` the durations the file holds (None: none, equally spaced); ``maximum`` (P,)
    each slider's end, ticks; ``sliders``, ``save_button``, ``reset_button`` the widgets;
    ``poses`` the filmstrip's rods (a LineCollection; ``pose_samples`` the samples it shows);
    ``com_path`` the centre of mass's path; ``total_text`` and ``phase_texts`` the scores shown;
    ``status_text`` whether the durations are saved.

    A move redraws only what it changes, over a copy of the rest taken at the last full draw
    (matplotlib's blitting: a full draw of the figure's text takes a few tenths of a second);
    a full draw happens when the view must change or the canvas cannot blit."""

    def __init__(
        self, session: CompositeSession, script_path: str | Path, figure: Figure | None = None
    ):
        self.session = session
        self.script_path = Path(script_path)
        script = session.script
        self.names = script.phase_names
        self.guess = np.asarray(session.guess, np.int64).copy()
        self.maximum = np.maximum(SLIDER_SPAN * self.guess, int(self.guess.sum()))
        self.saved_ticks = script.guessed_ticks
        self._file_sha256 = script.spec_sha256  # what the file holds, as far as we know
        colors = controller_colors(self.names)
        self._rgba = np.array([colors[name] for name in self.names])
        self.scored = session.score(self.guess)
        self.guess_total = self.scored.total
        self.pose_samples = np.zeros(0, np.int64)
        self._animated: list[Artist] = []  # drawn over the background at each move
        self._background = None  # the figure without them, from the last full draw
        self._scene_view: np.ndarray | None = None  # [[x0, y0], [x1, y1]] m
        self._trace_view: np.ndarray | None = None  # [[t0, y0], [t1, y1]] s, m
        with plot_style():
            if figure is None:
                figure = new_figure(*editor_size(len(self.names)))
            else:
                figure.set_size_inches(*editor_size(len(self.names)))
            self.figure = figure
            self._blits = bool(figure.canvas.supports_blit)
            self._build()
        figure.canvas.mpl_connect("draw_event", self._on_draw)
        self._redraw()

    @property
    def ticks(self) -> np.ndarray:
        """The current phase durations (P,) int64, ticks."""
        return self.scored.ticks.copy()

    # ---------------------------------------------------------------------- callbacks

    def set_duration(self, k: int, ticks: float) -> None:
        """Phase k runs ``ticks`` ticks (whole, 1 to ``maximum[k]``; a slider's float is fine):
        score the concatenation again and redraw. What phase k's slider calls."""
        if not 0 <= k < len(self.names):
            raise IndexError(f"phase {k}: the script has phases 0 to {len(self.names) - 1}")
        durations = self.ticks
        durations[k] = _whole_ticks(ticks, f"phase {self.names[k]}")
        self.set_durations(durations)

    def set_durations(self, ticks: Sequence[float]) -> None:
        """Every phase's duration (P,) at once (whole ticks, 1 to ``maximum``): score, redraw."""
        if len(ticks) != len(self.names):
            raise ValueError(f"{len(self.names)} durations for the phases, got {len(ticks)}")
        durations = np.array(
            [
                _whole_ticks(value, f"phase {name}")
                for value, name in zip(ticks, self.names, strict=True)
            ],
            np.int64,
        )
        for name, value, top in zip(self.names, durations, self.maximum, strict=True):
            if value > top:
                raise ValueError(
                    f"phase {name}: at most {top} ticks (its slider's end), got {value}"
                )
        if not np.array_equal(durations, self.scored.ticks):
            check_size(self.session, durations)
            self.scored = self.session.score(durations)
        self._redraw()

    def _slider_moved(self, k: int, ticks: float) -> None:
        """Phase k's slider moved to ``ticks``: ``set_duration``, or, where those durations are
        past the limits or the motion becomes unsound, the slider back where it was and why in
        the status line (shown, not raised into the GUI loop)."""
        try:
            self.set_duration(k, ticks)
        except (LimitError, NonFiniteStateError) as error:  # at the script's line: drop that
            where = re.match(rf"{re.escape(str(self.script_path))}:\d+:\d+: ", str(error))
            self._redraw(status=f"not run: {str(error)[where.end() if where else 0 :]}")

    def reset(self) -> None:
        """Back to the durations the editor started from (``session.guess``). The Reset button."""
        self.set_durations(self.guess)

    def save(self) -> None:
        """Write the current durations into the script file's ``ticks=`` values, atomically, the
        rest of the file unchanged (``script_text_with_ticks``). The Save button. InputError, and
        the file left as it is, if it changed since the editor read or last wrote it."""
        text, digest = read_spec_text(self.script_path)
        if digest != self._file_sha256:
            raise InputError(
                f"{self.script_path} changed since the editor read it; not overwritten (open it "
                f"again to edit the new text)"
            )
        script = parse_composite_text(text, str(self.script_path), digest)
        ticks = tuple(int(value) for value in self.scored.ticks)
        new_text = script_text_with_ticks(text, script, ticks)
        written = parse_composite_text(new_text, str(self.script_path))
        if written.guessed_ticks != ticks:  # the rewrite's own check, before touching the file
            raise AssertionError(f"rewritten script has ticks {written.guessed_ticks}, not {ticks}")
        write_text_atomically(self.script_path, new_text, saves_opened_file=True)
        self._file_sha256 = hashlib.sha256(new_text.encode("utf-8")).hexdigest()
        self.saved_ticks = ticks
        self._redraw(status=f"saved ticks {', '.join(map(str, ticks))} to {self.script_path}")

    def _save_clicked(self) -> None:
        try:
            self.save()
        except (OSError, InputError, ValueError) as error:  # shown, not raised into the GUI loop
            self.status_text.set_text(f"not saved: {error}")
            self._refresh(full=True)

    # ---------------------------------------------------------------------- the figure

    def _axes(self, left: float, top: float, width: float, height: float) -> Axes:
        """New axes ``left`` inches from the figure's left and ``top`` inches from its top."""
        fig_width, fig_height = self.figure.get_size_inches()
        return self.figure.add_axes(
            (
                left / fig_width,
                1 - (top + height) / fig_height,
                width / fig_width,
                height / fig_height,
            )
        )

    def _animate(self, *artists: Artist) -> None:
        """Draw ``artists`` at every move (over the background, in the order given)."""
        for artist in artists:
            artist.set_animated(self._blits)
            self._animated.append(artist)

    def _build(self) -> None:
        session, script, figure = self.session, self.session.script, self.figure
        fig_width, fig_height = figure.get_size_inches()
        figure.suptitle(
            f"composite script {script.name} ({script.figure}): {len(self.names)} controllers "
            f"one after another\ndrag a slider to set how long its phase runs (simulator ticks of "
            f"{session.dt:g} s); Save writes the durations into {self.script_path.name}",
            y=1 - 0.08 / fig_height,
            va="top",
            fontsize=10.5,
        )
        figure.legend(
            [Patch(color=self._rgba[k]) for k in range(len(self.names))],
            [
                f"{name}: {phase.controller}, seed {seed}"
                for name, phase, seed in zip(self.names, script.phases, session.seeds, strict=True)
            ],
            loc="upper center",
            bbox_to_anchor=(0.5, 1 - 0.5 / fig_height),
            ncols=min(len(self.names), 4),
            fontsize=9,
            frameon=False,
        )
        plot_width = fig_width - LEFT - RIGHT
        top = HEADER

        # the filmstrip
        self.scene = self._axes(LEFT, top, plot_width, SCENE_HEIGHT)
        self._scene_box = (plot_width, SCENE_HEIGHT)
        self.scene.set_aspect("equal", adjustable="box")
        self.scene.set_xlabel("x (m)", labelpad=1)
        self.scene.set_ylabel("y (m)")
        floor = session.figure.floor
        if not math.isnan(floor):
            self.scene.axhspan(floor - 1e3, floor, facecolor=TERRAIN_FACE, edgecolor="none")
            self.scene.axhline(floor, color=TERRAIN_EDGE, linewidth=1.2, zorder=1.5)
        self.com_path = LineCollection([], linewidths=1.0, alpha=0.8, zorder=2)
        # the rods thinly outlined (a wider dark copy beneath: a path effect costs 6 times more)
        self._outline = LineCollection(
            [], linewidths=ROD_WIDTH + 1.0, colors=OUTLINE, capstyle="round", zorder=2.9
        )
        self.poses = LineCollection([], linewidths=ROD_WIDTH, capstyle="round", zorder=3)
        for collection in (self.com_path, self._outline, self.poses):
            self.scene.add_collection(collection, autolim=False)
        (self.joints,) = self.scene.plot(
            [], [], "o", markersize=JOINT_SIZE, color=OUTLINE, linestyle="none", zorder=3.5
        )
        (self.switch_marks,) = self.scene.plot(
            [], [], "o", markersize=7, fillstyle="none", color="black", markeredgewidth=1.4,
            linestyle="none", zorder=4,
        )  # fmt: skip
        self._animate(self.com_path, self._outline, self.poses, self.joints, self.switch_marks)
        top += SCENE_HEIGHT + SCENE_GAP

        # the heights over time
        self.trace = self._axes(LEFT, top, plot_width, TRACE_HEIGHT)
        self.trace.set_xlabel("time (s)", labelpad=1)
        self.trace.set_ylabel("height (m)")
        self.com_height = LineCollection([], linewidths=1.6)
        self.low_height = LineCollection([], linewidths=1.2, linestyles="--")
        self.switch_lines = LineCollection([], colors="black", linewidths=0.8, linestyles=":")
        for collection in (self.switch_lines, self.low_height, self.com_height):
            self.trace.add_collection(collection, autolim=False)
        self._animate(self.switch_lines, self.low_height, self.com_height)
        self.trace.legend(
            [
                Line2D([], [], color="0.3", linewidth=1.6),
                Line2D([], [], color="0.3", linewidth=1.2, linestyle="--"),
                Line2D([], [], color="black", linewidth=0.8, linestyle=":"),
            ],
            ["centre of mass", "lowest rod end", "switch"],
            loc="upper right",
            fontsize=8,
            ncols=3,
        )
        top += TRACE_HEIGHT + TRACE_GAP

        # the scores: the numbers change, the formulas do not
        scores = self._axes(LEFT, top, plot_width, TOTAL_ROW)
        scores.set_axis_off()
        scores.set_navigate(False)
        self.total_text = scores.text(0, 0.5, "", va="center", fontsize=10, fontweight="bold")
        scores.text(
            TOTAL_WIDTH / plot_width,
            0.5,
            f"= {render_expression(script.total)}    (at the durations the editor started "
            f"from: {score_text(self.guess_total)})",
            va="center",
            fontsize=10,
        )
        self._animate(self.total_text)
        top += TOTAL_ROW

        # one slider per phase, its time and score right of it
        self.sliders: list[Slider] = []
        self.phase_texts: list[Text] = []
        for k, (name, phase) in enumerate(zip(self.names, script.phases, strict=True)):
            ax = self._axes(SLIDER_LEFT, top + 0.08, SLIDER_WIDTH, SLIDER_ROW - 0.16)
            slider = Slider(
                ax,
                name,
                1,
                int(self.maximum[k]),
                valinit=int(self.guess[k]),
                valstep=1,
                valfmt="%d ticks",
                color=self._rgba[k],
                initcolor="0.25",
            )
            slider.drawon = False  # drawn here, with the rest of a move
            slider.label.set_fontweight("bold")
            slider.on_changed(lambda value, k=k: self._slider_moved(k, value))
            self.sliders.append(slider)
            # right of the track (x in the slider's axes: 1 is its end): time and score, formula
            text = ax.text(
                1 + VALUE_WIDTH / SLIDER_WIDTH,
                0.5,
                "",
                va="center",
                fontsize=9.5,
                transform=ax.transAxes,
            )
            ax.text(
                1 + (VALUE_WIDTH + PHASE_WIDTH) / SLIDER_WIDTH,
                0.5,
                f"= {render_expression(phase.score)}",
                va="center",
                fontsize=9.5,
                transform=ax.transAxes,
            )
            self.phase_texts.append(text)
            # what moves: the track and bar, the marks (the start, the handle) and the value
            moving = [slider.track, slider.poly, *ax.lines, slider.valtext]
            self._animate(*sorted(moving, key=lambda artist: artist.get_zorder()), text)
            top += SLIDER_ROW

        # Save, Reset, and whether the durations are saved
        button_top = top + (BUTTON_ROW - BUTTON_HEIGHT) / 2
        self.save_button = Button(
            self._axes(SLIDER_LEFT, button_top, BUTTON_WIDTH, BUTTON_HEIGHT), "Save"
        )
        self.save_button.on_clicked(lambda _event: self._save_clicked())
        reset_axes = self._axes(
            SLIDER_LEFT + BUTTON_WIDTH + BUTTON_GAP, button_top, BUTTON_WIDTH, BUTTON_HEIGHT
        )
        self.reset_button = Button(reset_axes, "Reset")
        self.reset_button.on_clicked(lambda _event: self.reset())
        self.status_text = reset_axes.text(
            1 + BUTTON_GAP * 2 / BUTTON_WIDTH,
            0.5,
            "",
            va="center",
            fontsize=9,
            color="0.25",
            wrap=True,  # a refusal's reason can be longer than the row
        )  # changes seldom: drawn with the background

    def _redraw(self, status: str | None = None) -> None:
        """Show ``scored``: the poses, the paths, the heights, the scores, the sliders, and
        ``status`` (None: whether the durations are saved)."""
        session, scored = self.session, self.scored
        motion, dt = scored.motion, session.dt
        samples = pose_samples(motion.com.shape[0], dt)
        self.pose_samples = samples
        poses = motion.rod_ends[samples]  # (K, rods, 2, 2) m
        rods = poses.shape[1]
        self.poses.set_segments(poses.reshape(-1, 2, 2))
        self._outline.set_segments(poses.reshape(-1, 2, 2))
        self.poses.set_color(self._rgba[np.repeat(motion.phase[samples], rods)])
        self.joints.set_data(poses[..., 0].ravel(), poses[..., 1].ravel())
        com = motion.com
        phases = [motion.phase_samples(k) for k in range(len(self.names))]  # each a polyline
        self.com_path.set_segments([com[samples] for samples in phases])
        self.com_path.set_color(self._rgba)
        switches = motion.starts[1:-1]
        self.switch_marks.set_data(com[switches, 0], com[switches, 1])

        t = np.arange(com.shape[0]) * dt
        lowest = motion.rod_ends[..., 1].min(axis=(1, 2))
        for collection, height in ((self.com_height, com[:, 1]), (self.low_height, lowest)):
            points = np.stack([t, height], axis=1)
            collection.set_segments([points[samples] for samples in phases])
            collection.set_color(self._rgba)
        times = switches * dt

        self.total_text.set_text(f"total {score_text(scored.total)}")
        for k, name in enumerate(self.names):
            ticks = int(scored.ticks[k])
            self.phase_texts[k].set_text(
                f"{ticks * dt:.2f} s   score {score_text(scored.scores[name])}"
            )
            slider = self.sliders[k]
            if slider.val != ticks:  # set from code: move the slider without calling back
                slider.eventson = False
                slider.set_val(ticks)
                slider.eventson = True

        # what changes seldom, drawn with the background: a change draws the whole figure
        full = False
        if status is None:
            ticks = tuple(int(value) for value in scored.ticks)
            status = (
                f"the durations in {self.script_path}"
                if ticks == self.saved_ticks
                else f"unsaved (Save writes the durations into {self.script_path})"
            )
        if status != self.status_text.get_text():
            self.status_text.set_text(status)
            full = True
        bounds = motion_bounds(motion.rod_ends, session.figure.floor)
        if not keeps(self._scene_view, bounds, equal_aspect=True):
            self._scene_view = fit_box(bounds, self._scene_box)
            (x0, y0), (x1, y1) = self._scene_view
            self.scene.set_xlim(x0, x1)
            self.scene.set_ylim(y0, y1)
            full = True
        every = int(samples[1] - samples[0]) if len(samples) > 1 else 1
        title = (
            f"poses every {every * dt:g} s ({every} ticks), coloured by phase; thin line: the "
            f"centre of mass; circles: the switches"
        )
        if title != self.scene.get_title():
            self.scene.set_title(title, fontsize=9.5)
            full = True
        heights = np.concatenate([com[:, 1], lowest, [0.0]])
        shown = np.array([[0.0, heights.min() - 0.1], [float(t[-1]), heights.max() + 0.3]])
        if not keeps(self._trace_view, shown, equal_aspect=False):
            grid = np.array([TIME_GRID, VIEW_GRID])
            view = np.array([np.floor(shown[0] / grid), np.ceil(shown[1] / grid)]) * grid
            view[1] = np.maximum(view[1], view[0] + grid)
            self._trace_view = view
            self.trace.set_xlim(view[0, 0], view[1, 0])
            self.trace.set_ylim(view[0, 1], view[1, 1])
            full = True
        (_, low), (_, high) = self._trace_view
        self.switch_lines.set_segments([[[s, low], [s, high]] for s in times])
        self._refresh(full)

    def _refresh(self, full: bool) -> None:
        """Show the changes: a full draw, or the moving artists over the background."""
        canvas = self.figure.canvas
        if full or not self._blits or self._background is None:
            canvas.draw_idle()
            return
        canvas.restore_region(self._background)
        self._draw_animated()
        canvas.blit(self.figure.bbox)

    def _draw_animated(self) -> None:
        for artist in self._animated:
            self.figure.draw_artist(artist)

    def _on_draw(self, event) -> None:
        """After a full draw (which leaves out the moving artists): keep it as the background,
        then draw them over it."""
        canvas = event.canvas if event is not None else self.figure.canvas
        if not self._blits or canvas is not self.figure.canvas or canvas.is_saving():
            return
        self._background = canvas.copy_from_bbox(self.figure.bbox)
        self._draw_animated()


# --------------------------------------------------------------------------- the window


def interactive_backend() -> str | None:
    """The name of pyplot's backend (choosing one if not yet chosen) when it opens windows one
    can use the sliders in, else None (Agg and the other file backends: no display)."""
    import matplotlib.pyplot as plt
    from matplotlib.backends import BackendFilter, backend_registry

    backend = plt.get_backend()
    interactive = backend_registry.list_builtin(BackendFilter.INTERACTIVE)
    if backend.lower() in interactive or backend.startswith("module://"):
        return backend
    return None


def no_window_reason(backend: str) -> str:
    """Why matplotlib ended with the file backend ``backend``, in brackets ('' if it was asked
    for): it falls back to Agg without a word when the backend asked for cannot start (the
    message named only 'agg', with MPLBACKEND=TkAgg set) or the display cannot be opened."""
    asked = os.environ.get("MPLBACKEND", "")
    if asked.lower() == backend.lower():
        return ""
    display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    reasons = [f"MPLBACKEND={asked} could not start"] if asked else []
    if sys.platform.startswith("linux"):
        reasons.append(
            f"the display {display!r} could not be opened, or no GUI toolkit (tkinter, a Qt "
            "binding) is installed"
            if display
            else "no display: DISPLAY is not set"
        )
    return f" ({'; '.join(reasons)})" if reasons else ""


def run_editor(
    script_path: str | Path,
    results_dir: str | Path = "results/bsr",
    figures_dir: str | Path = "specs/figures",
    bsr_specs_dir: str | Path = "specs/bsr",
) -> None:
    """Open the editor of the script ``script_path`` in a window and return when it is closed.
    Its phases' controllers are the best seeds under ``results_dir``/SEARCH/ (as ``mosys
    composite`` picks them). InputError (before reading anything) if matplotlib cannot open a
    window; SpecError for a script, figure or controller that is not there; LimitError, before
    the window opens, for a guess past the limits (``composite.result_file.check_size``)."""
    import matplotlib.pyplot as plt

    from mosys.composite.session import find_controller_files, open_session
    from mosys.parsing.composite import parse_composite_script

    if interactive_backend() is None:
        raise InputError(
            f"the editor needs a window, but matplotlib's backend {plt.get_backend()!r} draws "
            f"none{no_window_reason(plt.get_backend())}; run it on a desktop or over ssh -X, "
            "with MPLBACKEND unset or an interactive backend such as TkAgg or QtAgg; without a "
            "display, edit the phases' ticks= in the script and run mosys composite and mosys "
            "plot composite"
        )
    script = parse_composite_script(script_path)
    session = open_session(
        script,
        find_controller_files(script, results_dir),
        figures_dir,
        bsr_specs_dir,
        f"{results_dir}/{{search}}/seed*.h5",
    )
    check_size(session)  # the guess is run at once, as by ``mosys composite``
    with plot_style():
        figure = plt.figure(num=f"mosys edit {script.name}")
        editor = ConcatenationEditor(session, script_path, figure)
    plt.show(block=True)
    plt.close(editor.figure)
