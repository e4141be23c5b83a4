"""The concatenation editor (the 1995 paper's §3 "manual animation editor"), driven headless
through its widgets and callbacks on an Agg canvas, with real tiny BSR controllers
(``composite_workspace``: its searches make those tests slow) and the session ``mosys
composite`` scores with."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.backend_bases import MouseEvent

from mosys.composite.session import open_session
from mosys.composite.transitions import equal_split
from mosys.editor.concatenation import (
    ConcatenationEditor,
    pose_samples,
    run_editor,
    score_text,
    script_text_with_ticks,
)
from mosys.errors import InputError
from mosys.parsing.composite import parse_composite_script, parse_composite_text

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
SHOW = SPECS / "composite" / "starman_show.comp"
PHASE_LINES = (  # the phase lines of starman_show.comp as written, and their durations
    ("phase cartwheel controller=starman_cartwheel_robust ticks=215", 215),
    ("phase jump      controller=starman_jump_robust      ticks=150", 150),
    ("phase shuffle   controller=starman_shuffle_robust   ticks=100", 100),
)


def open_editor(workspace, script_path: Path) -> ConcatenationEditor:
    """The editor of ``script_path`` on the workspace's controllers, on an Agg canvas."""
    script = parse_composite_script(script_path)
    session = open_session(script, workspace.controller_files(), SPECS / "figures", SPECS / "bsr")
    return ConcatenationEditor(session, script_path)


def copied_script(workspace, directory: Path, text: str | None = None) -> Path:
    """The Table 4 script (or ``text``) in ``directory``, to be rewritten by a test."""
    path = directory / "starman_show.comp"
    if text is None:
        shutil.copy(workspace.script, path)
    else:
        path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def editor(composite_workspace, tmp_path_factory) -> ConcatenationEditor:
    """One editor of the Table 4 script (a copy no test saves to), shared by the tests that
    only move sliders: each puts the durations back to the script's when done."""
    path = copied_script(composite_workspace, tmp_path_factory.mktemp("editor"))
    editor = open_editor(composite_workspace, path)
    yield editor
    editor.figure.clear()


@pytest.fixture
def at_guess(editor):
    editor.reset()
    yield editor
    editor.reset()


def click(ax, x: float = 0.5) -> None:
    """Press and release the left mouse button at ``x`` (a fraction of the width) across the
    middle of ``ax``, as a user's click reaches a widget."""
    canvas = ax.figure.canvas
    pixel_x, pixel_y = ax.transAxes.transform((x, 0.5))
    for name in ("button_press_event", "button_release_event"):
        canvas.callbacks.process(name, MouseEvent(name, canvas, pixel_x, pixel_y, button=1))


def slider_click(slider, ticks: int) -> None:
    """Click a slider where it shows ``ticks``."""
    fraction = (ticks - slider.valmin) / (slider.valmax - slider.valmin)
    click(slider.ax, fraction)


# --------------------------------------------------------------------------- moving a slider


@pytest.mark.slow
def test_the_editor_starts_from_the_scripts_durations(at_guess):
    editor = at_guess
    expected = editor.session.score([215, 150, 100])
    assert editor.ticks.tolist() == [215, 150, 100]
    assert [slider.val for slider in editor.sliders] == [215, 150, 100]
    assert [slider.valmax for slider in editor.sliders] == [645, 465, 465]  # 3x, or the total
    assert editor.scored.total == expected.total
    assert editor.total_text.get_text() == f"total {score_text(expected.total)}"
    assert editor.status_text.get_text() == f"the durations in {editor.script_path}"


@pytest.mark.slow
def test_moving_a_slider_reruns_the_motion_and_redraws_it(at_guess):
    editor = at_guess
    drawn_before = np.array(editor.poses.get_segments())
    text_before = editor.total_text.get_text()

    slider_click(editor.sliders[0], 120)  # the cartwheel stops after 1.2 s instead of 2.15 s

    assert editor.ticks.tolist() == [120, 150, 100]
    assert editor.sliders[0].val == 120
    expected = editor.session.score([120, 150, 100])  # what the pipeline's session makes of it
    motion = expected.motion
    assert editor.scored.total == expected.total
    assert editor.scored.scores == expected.scores
    np.testing.assert_array_equal(editor.scored.motion.rod_ends, motion.rod_ends)
    # the filmstrip: the poses of that motion at regular instants from its start, by phase
    samples = editor.pose_samples
    assert samples[0] == 0 and len(set(np.diff(samples))) == 1
    assert samples[-1] + samples[1] > len(motion.com) - 1  # to the end
    assert 15 <= len(samples) <= 25
    drawn = np.array(editor.poses.get_segments())
    np.testing.assert_array_equal(drawn, motion.rod_ends[samples].reshape(-1, 2, 2))
    assert drawn.shape != drawn_before.shape or not np.allclose(drawn, drawn_before)
    for k in range(3):  # the centre of mass's path, one polyline per phase
        path = np.asarray(editor.com_path.get_segments()[k])
        np.testing.assert_array_equal(path, motion.com[motion.phase_samples(k)])
    # the scores shown are the session's for these durations
    assert editor.total_text.get_text() == f"total {score_text(expected.total)}" != text_before
    for k, name in enumerate(("cartwheel", "jump", "shuffle")):
        seconds = f"{[1.2, 1.5, 1.0][k]:.2f} s"
        assert editor.phase_texts[k].get_text() == (
            f"{seconds}   score {score_text(expected.scores[name])}"
        )
    assert editor.status_text.get_text().startswith("unsaved")


@pytest.mark.slow
def test_each_phase_is_drawn_in_its_colour(at_guess):
    editor = at_guess
    editor.set_durations([100, 120, 130])
    motion = editor.scored.motion
    samples = editor.pose_samples
    rods = motion.rod_ends.shape[1]
    phase_colors = np.asarray(editor.com_height.get_colors())  # (3, 4), one per phase
    assert len({tuple(color) for color in phase_colors}) == 3
    expected = phase_colors[np.repeat(motion.phase[samples], rods)]
    np.testing.assert_array_equal(editor.poses.get_colors(), expected)
    switches = np.column_stack(editor.switch_marks.get_data())
    np.testing.assert_array_equal(switches, motion.com[[100, 220]])


@pytest.mark.slow
def test_set_duration_moves_the_slider_and_refuses_what_no_slider_gives(at_guess):
    editor = at_guess
    editor.set_duration(2, 150.0)  # a slider gives floats
    assert editor.ticks.tolist() == [215, 150, 150]
    assert editor.sliders[2].val == 150
    assert editor.scored.total == editor.session.total([215, 150, 150])
    for k, ticks, message in (
        (0, 0, "phase cartwheel: a duration is a whole number of ticks >= 1, got 0"),
        (1, 12.5, "phase jump: a duration is a whole number of ticks >= 1, got 12.5"),
        (2, 466, "phase shuffle: at most 465 ticks (its slider's end), got 466"),
    ):
        with pytest.raises(ValueError) as error:
            editor.set_duration(k, ticks)
        assert str(error.value) == message
    assert editor.ticks.tolist() == [215, 150, 150]  # unchanged
    with pytest.raises(IndexError):
        editor.set_duration(3, 10)


@pytest.mark.slow
def test_a_slider_moved_past_the_limits_goes_back_and_says_why(at_guess, monkeypatch):
    """The sliders reach 3x a phase's guess, so a script near the step limit can be dragged
    past it: the move is refused in the status line (not raised into the GUI loop) and the
    slider and motion stay where they were."""
    editor = at_guess
    monkeypatch.setenv("MOSYS_MAX_STEPS", "600")  # the guess, 465 ticks, fits
    scored = editor.scored
    slider_click(editor.sliders[0], 500)  # 650 ticks to the jump's end
    assert editor.ticks.tolist() == [215, 150, 100]
    assert editor.sliders[0].val == 215
    assert editor.scored is scored
    assert editor.status_text.get_text() == (
        "not run: expected at most 600 integration steps per run, found 650 (the phases' 650 "
        'ticks to the end of this one); raise MOSYS_MAX_STEPS to allow it (README, "Limits")'
    )
    slider_click(editor.sliders[0], 300)  # 550 ticks: runs
    assert editor.ticks.tolist() == [300, 150, 100]
    assert editor.status_text.get_text().startswith("unsaved")


@pytest.mark.slow
def test_reset_returns_to_the_start(at_guess):
    editor = at_guess
    editor.set_durations([10, 20, 30])
    click(editor.reset_button.ax)
    assert editor.ticks.tolist() == [215, 150, 100]
    assert [slider.val for slider in editor.sliders] == [215, 150, 100]
    assert editor.status_text.get_text() == f"the durations in {editor.script_path}"


@pytest.mark.slow
def test_a_move_drawn_over_the_background_shows_what_a_full_draw_shows(at_guess):
    editor = at_guess
    canvas = editor.figure.canvas
    editor.set_duration(1, 92)  # unsaved now: the status line changed, a full draw
    shown = [text.get_text() for text in (editor.total_text, *editor.phase_texts)]
    full_draws = []
    connection = canvas.mpl_connect("draw_event", full_draws.append)
    editor.set_duration(1, 94)  # a small move: the views stay, only what moves is drawn
    canvas.mpl_disconnect(connection)
    assert not full_draws
    now = [text.get_text() for text in (editor.total_text, *editor.phase_texts)]
    assert now[0] != shown[0] and now[2] != shown[2]  # the total's and the jump's numbers
    blitted = np.asarray(canvas.buffer_rgba()).copy()
    canvas.draw()
    np.testing.assert_array_equal(blitted, np.asarray(canvas.buffer_rgba()))


def test_scores_show_three_decimals_and_no_negative_zero():
    assert score_text(2.1493024748504297) == "2.149"
    assert score_text(-0.0359) == "-0.036"
    assert score_text(-0.0004) == "0.000"


def test_pose_samples_are_regular_and_round():
    assert pose_samples(350, 0.01).tolist() == list(range(0, 350, 20))  # every 0.2 s
    assert pose_samples(1201, 0.01).tolist() == list(range(0, 1201, 60))  # every 0.6 s
    assert pose_samples(2, 0.01).tolist() == [0, 1]  # never less than a tick apart
    assert pose_samples(1, 0.01).tolist() == [0]


# --------------------------------------------------------------------------- saving


@pytest.mark.slow
def test_save_rewrites_only_the_ticks(composite_workspace, tmp_path):
    path = copied_script(composite_workspace, tmp_path)
    original = path.read_bytes()
    editor = open_editor(composite_workspace, path)
    editor.set_durations([140, 7, 120])
    click(editor.save_button.ax)

    expected = original.decode()
    for (line, old), new in zip(PHASE_LINES, (140, 7, 120), strict=True):
        assert line in expected
        expected = expected.replace(line, line.removesuffix(str(old)) + str(new))
    assert path.read_bytes() == expected.encode()
    saved = parse_composite_script(path)
    assert saved.guessed_ticks == (140, 7, 120)
    assert editor.session.score(saved.guessed_ticks).total == editor.scored.total
    # a session opened on the saved script starts from the chosen motion
    reopened = open_session(
        saved, composite_workspace.controller_files(), SPECS / "figures", SPECS / "bsr"
    )
    assert reopened.score(reopened.guess).total == editor.scored.total
    assert editor.status_text.get_text() == f"saved ticks 140, 7, 120 to {path}"
    assert not list(tmp_path.glob(".*partial"))

    editor.set_duration(1, 90)  # a second save edits the text the first one wrote
    assert editor.status_text.get_text() == f"unsaved (Save writes the durations into {path})"
    editor.save()
    assert parse_composite_script(path).guessed_ticks == (140, 90, 120)
    assert path.read_bytes() == expected.replace("ticks=7\n", "ticks=90\n").encode()


@pytest.mark.slow
def test_save_leaves_a_script_changed_since_alone(composite_workspace, tmp_path):
    path = copied_script(composite_workspace, tmp_path)
    editor = open_editor(composite_workspace, path)
    changed = path.read_text() + "# a note written while the editor was open\n"
    path.write_text(changed)
    editor.set_duration(0, 100)
    with pytest.raises(InputError) as error:
        editor.save()
    assert str(error.value) == (
        f"{path} changed since the editor read it; not overwritten (open it again to edit the "
        f"new text)"
    )
    assert path.read_text() == changed
    click(editor.save_button.ax)  # the button shows it instead
    assert editor.status_text.get_text() == f"not saved: {error.value}"
    assert path.read_text() == changed


@pytest.mark.slow
def test_a_script_without_ticks_starts_equally_spaced_and_gains_them(composite_workspace, tmp_path):
    text = SHOW.read_text()
    for line, _ in PHASE_LINES:
        text = text.replace(line, re.sub(r"\s+ticks=\d+$", "", line))
    text = text.replace(  # a comment after the last word, as any line may have
        "controller=starman_jump_robust", "controller=starman_jump_robust  # then a jump"
    )
    path = copied_script(composite_workspace, tmp_path, text)
    assert parse_composite_script(path).guessed_ticks is None
    editor = open_editor(composite_workspace, path)
    guess = equal_split(editor.session.default_length, 3)
    assert editor.ticks.tolist() == guess.tolist()
    assert editor.status_text.get_text().startswith("unsaved")

    editor.save()
    a, b, c = guess.tolist()
    expected = (
        text.replace("starman_cartwheel_robust\n", f"starman_cartwheel_robust ticks={a}\n")
        .replace(
            "starman_jump_robust  # then a jump", f"starman_jump_robust ticks={b}  # then a jump"
        )
        .replace("starman_shuffle_robust\n", f"starman_shuffle_robust ticks={c}\n")
    )
    assert path.read_text() == expected
    saved = parse_composite_script(path)
    assert saved.guessed_ticks == (a, b, c)
    assert editor.session.score(saved.guessed_ticks).total == editor.scored.total


# --------------------------------------------------------------------------- the text edit

SMALL = (
    "figure starman\r\n"
    "phase a controller=s1 ticks=12 seed=3 # first\r\n"
    "  phase   b\tcontroller=s2   seed=1\t\r\n"
    "score a = dtime\r\n"
    "score b = dtime ?= 12\r\n"
    "total = a + b  # ticks=5 here is a comment\r\n"
)


def test_script_text_with_ticks_keeps_every_other_character():
    with_ticks = SMALL.replace("seed=1\t", "seed=1 ticks=4\t")
    script = parse_composite_text(with_ticks)
    assert script_text_with_ticks(with_ticks, script, (7, 12345)) == with_ticks.replace(
        "ticks=12 ", "ticks=7 "
    ).replace("ticks=4\t", "ticks=12345\t")
    without = SMALL.replace(" ticks=12", "")
    assert script_text_with_ticks(without, parse_composite_text(without), (1, 2)) == (
        without.replace("seed=3 #", "seed=3 ticks=1 #").replace("seed=1\t", "seed=1 ticks=2\t")
    )


def test_script_text_with_ticks_refuses_bad_durations_and_other_text():
    script = parse_composite_text(SMALL.replace("seed=1\t", "seed=1 ticks=4\t"))
    for ticks, message in (
        ((1,), "2 durations for the phases, got 1"),
        ((1, 0), "phase b: a duration is a whole number of ticks >= 1, got 0"),
        ((1, 2.5), "phase b: a duration is a whole number of ticks >= 1, got 2.5"),
    ):
        with pytest.raises(ValueError) as error:
            script_text_with_ticks(SMALL, script, ticks)
        assert str(error.value) == message
    with pytest.raises(ValueError) as error:
        script_text_with_ticks("\n" + SMALL, script, (1, 2))
    assert str(error.value) == (
        "<text>: the text is not the one parsed (phase.a.ticks '12' is not at 2:29)"
    )


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, 10**6), min_size=3, max_size=3))
def test_the_rewritten_table_4_script_parses_to_the_durations_given(ticks):
    text = SHOW.read_text()
    new = script_text_with_ticks(text, parse_composite_text(text), ticks)
    assert parse_composite_text(new).guessed_ticks == tuple(ticks)
    changed = [
        (old, line) for old, line in zip(text.split("\n"), new.split("\n"), strict=True)
        if old != line
    ]  # fmt: skip
    assert all(old.startswith("phase ") for old, _ in changed)
    assert [re.sub(r"ticks=\d+", "", line) for _, line in changed] == [
        re.sub(r"ticks=\d+", "", old) for old, _ in changed
    ]


# --------------------------------------------------------------------------- the window


@pytest.fixture
def no_display(monkeypatch):
    """pyplot on Agg (what it falls back to without a display), restored afterwards."""
    import matplotlib.pyplot as plt

    backend = plt.get_backend()
    plt.switch_backend("agg")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("MPLBACKEND", raising=False)
    yield
    plt.switch_backend(backend)


def test_run_editor_refuses_a_guess_past_the_limits_before_its_window(
    no_display, composite_workspace, tmp_path, monkeypatch
):
    """The guess is run at once, so a script whose ticks are past the limits is refused as by
    ``mosys composite``, at its line, before any window opens (here a window could open: the
    backend check is told so)."""
    import matplotlib.pyplot as plt

    import mosys.editor.concatenation as concatenation
    from mosys.limits import LimitError

    text = composite_workspace.script.read_text().replace("ticks=150\n", "ticks=99999999999\n", 1)
    script = copied_script(composite_workspace, tmp_path, text)
    monkeypatch.setattr(concatenation, "interactive_backend", lambda: "tkagg")
    figures = plt.get_fignums()
    with pytest.raises(LimitError) as error:
        run_editor(script, composite_workspace.bsr_results, SPECS / "figures", SPECS / "bsr")
    assert str(error.value).startswith(
        f"{script}:9:59: expected at most 10,000,000 integration steps per run, found "
        "100,000,000,214 (the phases' 100,000,000,214 ticks to the end of this one)"
    )
    assert plt.get_fignums() == figures


@pytest.mark.parametrize(
    ("environment", "why"),
    [
        ({}, "no display: DISPLAY is not set"),
        (  # matplotlib falls back to Agg without a word: the message named only 'agg'
            {"MPLBACKEND": "TkAgg", "DISPLAY": ":99"},
            "MPLBACKEND=TkAgg could not start; the display ':99' could not be opened, or no "
            "GUI toolkit (tkinter, a Qt binding) is installed",
        ),
    ],
)
def test_run_editor_without_a_window_says_so(no_display, tmp_path, monkeypatch, environment, why):
    for name, value in environment.items():
        monkeypatch.setenv(name, value)
    with pytest.raises(InputError) as error:  # before reading anything: no such script here
        run_editor(tmp_path / "missing.comp", tmp_path)
    assert str(error.value) == (
        f"the editor needs a window, but matplotlib's backend 'agg' draws none ({why}); run it "
        "on a desktop or over ssh -X, with MPLBACKEND unset or an interactive backend such as "
        "TkAgg or QtAgg; without a display, edit the phases' ticks= in the script and run mosys "
        "composite and mosys plot composite"
    )
