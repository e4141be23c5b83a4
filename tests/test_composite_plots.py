"""The composite plots (the 1995 paper's Figures 13 and 14, Figure 5's search, the refined
motion's GIF) from the real small composite result of the ``composite_workspace`` fixture
(slow: it runs BSR and composite searches), checked through their matplotlib artists
(``filmstrips_figure``, ``search_figure``); the pose and label placement from made-up motions."""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest
from conftest import assert_png
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.colors import to_rgba
from PIL import Image

import mosys.plots.composite as composite
import mosys.plots.style as style
from mosys.plots.composite import (
    drawable_scores,
    filmstrips_figure,
    phase_colors,
    plot_filmstrips,
    plot_search,
    read_composite,
    score_limits,
    search_curve,
    search_figure,
    search_plot,
    shade,
    strip_poses,
    switch_label_places,
    switch_labels,
    switch_samples,
    write_composite_gif,
)
from mosys.plots.style import PlotInputError, frame_indices


@pytest.fixture(scope="module")
def result_path(composite_workspace) -> Path:
    return composite_workspace.result


def test_a_tall_panel_narrowed_keeps_its_margin_round_the_poses() -> None:
    margin = style.STRIP_MARGIN
    # 10 m of poses on 12.88 of 13 inches, 7.2 inches tall: half as wide, and the margin kept
    width, scale = composite.narrowed(13.0, 10.0 / 12.88, 7.2, 10.0)
    assert width == pytest.approx(6.5)
    assert (width - 10.0 / scale) / 2 == pytest.approx(margin)
    # no x extent (a motion straight up), and a panel too narrow for two margins: the ratio
    for x_span, height in ((0.0, 7.2), (1.0, 1e6)):
        width, scale = composite.narrowed(13.0, 0.1, height, x_span)
        assert width == pytest.approx(13.0 * composite.PANEL_HEIGHT_MAX / height)
        assert scale == pytest.approx(0.1 * height / composite.PANEL_HEIGHT_MAX)


def test_strip_poses_of_a_known_motion() -> None:
    t = np.round(np.arange(301) * 0.01, 10)  # 0 to 3 s
    phase = np.searchsorted([1.0, 2.05], t, side="right")  # switch samples: the phase they start
    phases = [
        {"name": "a", "start": 0.0, "end": 1.0},
        {"name": "b", "start": 1.0, "end": 2.05},
        {"name": "c", "start": 2.05, "end": 3.0},
    ]
    np.testing.assert_array_equal(switch_samples(t, phases), [100, 205])
    poses = strip_poses(t, phase, phases, 0.25)
    # every 0.25 s, but 2.0 s is within a third of an interval of the switch at 2.05 s
    expected = [0, 25, 50, 75, 100, 125, 150, 175, 205, 225, 250, 275, 300]
    np.testing.assert_array_equal(poses.samples, expected)
    np.testing.assert_array_equal(np.flatnonzero(poses.switch), [4, 8])
    np.testing.assert_array_equal(poses.phase, [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 2])
    np.testing.assert_allclose(poses.fraction[:4], [0, 0.25, 0.5, 0.75])
    assert poses.fraction[4] == 0 and poses.fraction[8] == 0 and poses.fraction[-1] == 1


@pytest.mark.slow
def test_strip_poses_of_the_real_result(result_path: Path) -> None:
    result = read_composite(result_path)
    interval = 0.25
    for stored, phases in ((result.before, result.phases_before), (result.after, result.phases)):
        t = stored.motion.t
        poses = strip_poses(t, stored.phase, phases, interval)
        assert np.all(np.diff(poses.samples) > 0) and poses.samples[-1] == len(t) - 1
        switches = poses.samples[poses.switch]
        starts = [p["start"] for p in phases[1:]]
        np.testing.assert_allclose(t[switches], starts, atol=1e-9)  # at each switch time
        np.testing.assert_array_equal(poses.phase[poses.switch], np.arange(1, len(phases)))
        regular = ~poses.switch
        np.testing.assert_array_equal(poses.phase[regular], stored.phase[poses.samples[regular]])
        assert set(poses.phase) == set(range(len(phases)))  # every phase drawn
        gaps = np.abs(t[poses.samples[regular]][:, None] - t[switches][None, :])
        assert gaps.min() >= interval / 3 - 1e-9
        assert np.all((poses.fraction >= 0) & (poses.fraction <= 1))


def test_switch_labels_keep_apart_inside_the_view() -> None:
    scale = 0.5  # m per inch: labels SWITCH_LABEL_WIDTH inches wide are 0.875 m
    gap = composite.SWITCH_LABEL_WIDTH * scale
    x, levels = switch_label_places(np.array([1.0, 1.2, 5.0]), 0.0, 6.0, scale)
    assert not levels.any()  # one row holds them
    assert x[1] - x[0] == pytest.approx(gap) and x[2] == 5.0
    x, levels = switch_label_places(np.array([5.9]), 0.0, 6.0, scale)
    assert x[0] == pytest.approx(6.0 - gap / 2)  # kept inside the view
    # five labels in a 2 m view: two a row, three rows, taken in turn from the left
    x, levels = switch_label_places(np.linspace(0.2, 1.8, 5), 0.0, 2.0, scale)
    np.testing.assert_array_equal(levels, [0, 1, 2, 0, 1])
    for row in range(3):
        assert np.all(np.diff(np.sort(x[levels == row])) >= gap - 1e-9)
    assert x.min() >= gap / 2 - 1e-9 and x.max() <= 2.0 - gap / 2 + 1e-9


@pytest.mark.slow
def test_phase_colours_are_distinct_and_shaded(result_path: Path) -> None:
    phases = read_composite(result_path).phases
    colors = phase_colors(phases)
    assert len(set(colors)) == len(phases) == 3
    color = colors[0]
    assert shade(color, 1.0) == pytest.approx(to_rgba(color))
    assert min(shade(color, 0.0)[:3]) > min(to_rgba(color)[:3])  # lighter: towards white
    assert sum(shade(color, 0.3)[:3]) > sum(shade(color, 0.7)[:3])


@pytest.mark.slow
def test_filmstrips_draw_both_panels_in_phase_colours(
    result_path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    drawn: list[tuple[object, tuple]] = []  # (axes, colour) of each pose drawn
    real = composite.draw_pose

    def recorded(ax, pose, color, zorder):
        drawn.append((ax, tuple(to_rgba(color))))
        real(ax, pose, color, zorder)

    monkeypatch.setattr(composite, "draw_pose", recorded)
    figure = filmstrips_figure(result_path, interval=0.25)

    result = read_composite(result_path)
    colors = phase_colors(result.phases)
    panels = list(dict.fromkeys(ax for ax, _ in drawn))
    assert panels == figure.axes  # before above after
    assert panels[0].get_position().y0 > panels[1].get_position().y0
    assert figure.get_suptitle().startswith(
        "Composite motion starman_show: the trajectory before and after the transition points "
        "are refined\nthe figure every 0.25 s"
    )
    assert (
        panels[0]
        .get_title(loc="left")
        .startswith("Before refinement (Figure 13): the guessed transition points\nscript total ")
    )
    assert (
        panels[1]
        .get_title(loc="left")
        .startswith(
            "After refinement (Figure 14): the transition points found by the search\nscript total "
        )
    )
    for ax, stored, phases, legend in zip(
        panels,
        (result.before, result.after),
        (result.phases_before, result.phases),
        figure.legends,
        strict=True,
    ):
        labels = [text.get_text() for text in legend.get_texts()]
        assert len(labels) == len(phases) + 1
        assert [label.split(":")[0] for label in labels[:-1]] == [p["name"] for p in phases]
        assert labels[-1] == "the pose at a switch (its time above it)"
        switches = switch_samples(stored.motion.t, phases)
        notes = [text.get_text() for text in ax.texts]  # the switch labels, arrows to the poses
        assert notes == switch_labels(phases, switches, stored.motion.t)
        assert len(notes) == len(phases) - 1
        poses = strip_poses(stored.motion.t, stored.phase, phases, 0.25)
        expected = [
            to_rgba(composite.SWITCH_COLOR) if switch else shade(colors[k], fraction)
            for k, switch, fraction in zip(poses.phase, poses.switch, poses.fraction, strict=True)
        ]
        got = [color for a, color in drawn if a is ax]
        assert got == [pytest.approx(color) for color in expected]
        assert ax.get_aspect() == 1.0
        assert sum(c == to_rgba("black") for c in got) == len(phases) - 1
        # every pose drawn lies STRIP_MARGIN inches inside the view's sides, round ends whole
        x0, x1 = ax.get_xlim()
        margin = style.STRIP_MARGIN * (x1 - x0) / (ax.get_position().width * figure.get_figwidth())
        x = stored.motion.endpoints[poses.samples][..., 0]
        assert x.min() >= x0 + 0.99 * margin and x.max() <= x1 - 0.99 * margin
    assert panels[0].get_xlim() == panels[1].get_xlim()  # one view for both
    out = tmp_path / "strips.png"
    plot_filmstrips(result_path, out, interval=0.25)
    assert_png(out, least_width=600)


@pytest.mark.slow
def test_search_plot(result_path: Path, tmp_path: Path) -> None:
    result = read_composite(result_path)
    generations, scores = search_curve(result)
    np.testing.assert_array_equal(generations, np.arange(int(result.attrs["search_g"]) + 1))
    assert scores[0] == result.attrs["score_before"]
    assert scores[-1] == pytest.approx(result.attrs["score_after"])
    assert np.all(np.diff(scores) >= 0)  # the best so far never falls
    figure = search_figure(result_path)
    (ax,) = figure.axes
    assert ax.get_title().startswith(
        "Composite motion starman_show: transition-point search (Figure 5)"
    )
    assert ax.get_xlabel() == "generation (0: the guessed transition points)"
    assert ax.get_ylabel() == "best script total so far"
    guess, curve, points = ax.lines
    assert list(guess.get_ydata()) == [scores[0], scores[0]]  # the guess's total, dotted
    assert guess.get_linestyle() == ":"
    np.testing.assert_array_equal(curve.get_xdata(), generations)
    np.testing.assert_array_equal(curve.get_ydata(), scores)
    assert curve.get_drawstyle() == "steps-post"
    np.testing.assert_array_equal(points.get_ydata(), scores)
    texts = [text.get_text() for text in ax.texts]
    assert texts[0].startswith("the guess: ")
    assert f"{int(result.attrs['simulations']):,} simulations in" in texts[1]
    assert "Q = 4, G = 3, H = 2" in texts[1]
    out = tmp_path / "search.png"
    plot_search(result_path, out)
    assert_png(out, least_width=600)


def test_score_limits_hold_only_finite_scores() -> None:
    """A script's arithmetic may give ±inf or nan (README, "Expressions"): the axis took them
    and matplotlib raised 'Axis limits cannot be NaN or Inf'."""
    assert score_limits(np.array([1.0, 2.0, 3.0]), 1.0) == pytest.approx((0.76, 3.16))
    assert score_limits(np.array([np.inf, np.inf]), np.inf) is None
    assert score_limits(np.array([np.nan, 2.0]), np.nan) == pytest.approx((1.76, 2.16))
    assert score_limits(np.array([1e308, 1.5e308]), -1e308) is None  # the margin overflows


def test_only_scores_an_axis_can_hold_are_drawn() -> None:
    """matplotlib's tick locator overflows on an axis near 1e308 ('arange: cannot compute
    length', found by the verb fuzz, seed 9012): such totals are left out as inf and nan are."""
    drawn = drawable_scores(np.array([1.0, -1e300, 1e300, 1.1e300, -1e308, np.inf, np.nan]))
    np.testing.assert_array_equal(drawn[:3], [1.0, -1e300, 1e300])
    assert np.isnan(drawn[3:]).all()


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(), min_size=1, max_size=12),
    st.floats(),
    st.sampled_from([1.0, 1e-300, 1e150, 1e300]),
)
def test_the_search_plot_draws_any_totals(values: list[float], after: float, scale: float) -> None:
    """Any doubles a script's arithmetic gives (its numbers are not bounded), scaled so that
    both tiny and huge spans come up: the figure renders, the totals an axis can hold are its
    points, and the note says so when any is left out."""
    with np.errstate(over="ignore"):
        scores = np.array(values) * scale
    figure = search_plot(np.arange(len(scores)), scores, after, "Q = 2, G = 1, H = 1", "any")
    figure.savefig(io.BytesIO(), format="png")
    (ax,) = figure.axes
    (curve,) = [line for line in ax.lines if line.get_drawstyle() == "steps-post"]
    drawn = curve.get_ydata()
    kept = np.abs(scores) <= 1e300
    np.testing.assert_array_equal(np.isnan(drawn), ~kept)
    np.testing.assert_array_equal(drawn[kept], scores[kept])
    left_out = "are not drawn" in ax.texts[-1].get_text()
    assert left_out == (not kept.all())
    plt.close(figure)


@pytest.mark.parametrize(
    ("name", "score"),
    [("infinite", "1/0"), ("huge", "1e308 + dcm_x"), ("huge_negative", "-1.7e308 * (1 + dcm_x)")],
)
def test_a_search_of_scores_no_axis_holds_is_drawn_with_a_note(
    composite_workspace, tmp_path: Path, name: str, score: str
) -> None:
    from mosys.cli import main

    script = tmp_path / f"{name}.comp"
    script.write_text(
        "figure starman\nphase a controller=starman_jump_robust ticks=5\n"
        f"score a = {score}\ntotal = a\n"
    )
    result = tmp_path / f"{name}.h5"
    argv = ["composite", script, "--bsr-results", composite_workspace.bsr_results, "--q", "2",
            "--g", "1", "--h", "1", "-o", result]  # fmt: skip
    assert main([str(arg) for arg in argv]) == 0
    out = tmp_path / "search.png"
    assert main(["plot", "composite", str(result), "--search", str(out)]) == 0
    assert_png(out, least_width=600)
    (ax,) = search_figure(result).axes
    notes = [text.get_text() for text in ax.texts]
    assert not any(note.startswith("the guess: ") for note in notes)  # the guess is not drawn
    assert any(
        "scores of ±inf, nan or beyond ±1e+300 (the script's arithmetic) are not drawn" in note
        for note in notes
    )


@pytest.mark.slow
def test_gif_plays_the_refined_motion_in_real_time(result_path: Path, tmp_path: Path) -> None:
    result = read_composite(result_path)
    t = result.after.motion.t
    duration_ms = 1000 * (t[-1] - t[0])
    out = tmp_path / "show.gif"
    write_composite_gif(result_path, out)
    assert 10_000 < out.stat().st_size < 2_000_000
    with Image.open(out) as gif:
        frames = gif.n_frames
        assert gif.info["duration"] == 40
        durations = []
        for k in range(frames):
            gif.seek(k)
            durations.append(gif.info["duration"])
    expected = len(frame_indices(t, 0.04))
    assert frames in (expected, expected + 1)  # every 40 ms, and the last sample
    assert abs(sum(durations[:-1]) - duration_ms) <= 40  # real time
    assert durations[-1] == style.GIF_HOLD_MS
    assert not list(tmp_path.glob(".*.partial"))
    short = tmp_path / "short.gif"
    write_composite_gif(result_path, short, max_frames=9)
    with Image.open(short) as gif:
        assert gif.n_frames == 9
        assert abs(8 * gif.info["duration"] - duration_ms) <= 8 * 10  # GIF keeps 10 ms units


def _without(source: Path, target: Path, attribute: str) -> Path:
    shutil.copy(source, target)
    with h5py.File(target, "r+") as h5:
        del h5.attrs[attribute]
    return target


@pytest.mark.parametrize(
    "write", [plot_filmstrips, plot_search, write_composite_gif], ids=lambda f: f.__name__
)
@pytest.mark.slow
def test_bad_input_raises_and_writes_nothing(result_path: Path, tmp_path: Path, write) -> None:
    out = tmp_path / "out.png"
    not_hdf5 = tmp_path / "bogus.h5"
    not_hdf5.write_text("not hdf5")
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as h5:
        h5.create_dataset("t", data=np.zeros(3))
    cases = {
        tmp_path / "missing.h5": "no such file",
        not_hdf5: "cannot read it as HDF5",
        other: "not a composite result",
        _without(result_path, tmp_path / "noscores.h5", "scores_after"): "'scores_after'",
    }
    for path, message in cases.items():
        with pytest.raises(PlotInputError, match=message) as error:
            write(path, out)
        assert str(path) in str(error.value)
        assert not out.exists()
        assert not list(tmp_path.glob(".*.partial"))


def test_scores_that_differ_are_written_so() -> None:
    """A search that gained 0.0016 read '1.64 → 1.64 (× 1)'."""
    from mosys.plots.composite import distinct_text, score_texts

    assert score_texts(1.64289, 1.6445) == ("1.643", "1.645")
    assert score_texts(5.8, 18.2) == ("5.8", "18.2")
    assert distinct_text(1.6445 / 1.64289, 1.0) == "1.001"
    assert score_texts(2.0, 2.0) == ("2", "2")
    assert distinct_text(-3e-10, 0.0) == "0"


def test_long_tick_labels_keep_the_axis_label_on_the_figure() -> None:
    """Ticks of 1.64275..1.64450 pushed the y label off a figure with a fixed left margin."""
    from mosys.plots.style import keep_left_labels_in, new_figure, plot_style

    with plot_style():
        figure = new_figure(8.0, 4.8)
        ax = figure.subplots()
        ax.plot([0, 8], [1.64289, 1.6445])
        ax.set_ylabel("best script total so far")
        figure.subplots_adjust(left=0.8 / 8.0)
        figure.canvas.draw()
        before = ax.get_tightbbox(figure.canvas.get_renderer()).x0
        keep_left_labels_in(figure, ax)
        figure.canvas.draw()
        after = ax.get_tightbbox(figure.canvas.get_renderer()).x0
    assert before < 0.07 * figure.dpi  # at the edge (in a search plot, beyond it)
    assert after == pytest.approx(0.08 * figure.dpi, abs=1.0)


def test_a_search_that_kept_the_guess_says_so_on_the_strips() -> None:
    """Two identical panels with nothing said looked like a mistake."""
    from mosys.plots.composite import _same_transitions

    guess = [{"name": "a", "ticks": 200}, {"name": "b", "ticks": 150}]
    assert _same_transitions(guess, [dict(phase) for phase in guess])
    assert not _same_transitions(guess, [{"name": "a", "ticks": 190}, {"name": "b", "ticks": 160}])
