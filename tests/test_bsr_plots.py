"""The BSR plots (learning curves of Figures 7 and 8, the filmstrip of Figures 9-12, the motion
GIF) from small synthetic search results: a five-rod star (a torso, two arms at its top, two legs
at its bottom) turning as it moves, written with ``write_bsr_result`` for a sense-based and a
time-based search of a few seeds each, with made-up non-decreasing learning curves. The
figures are checked through their matplotlib artists (``learning_figure``,
``learning_comparison_figure``, ``filmstrip_figure``)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import assert_png
from hypothesis import event, example, given
from hypothesis import strategies as st
from matplotlib.collections import LineCollection, PolyCollection
from PIL import Image

import mosys.plots.bsr as bsr
import mosys.plots.bsr_learning as bsr_learning
from mosys.cli import main
from mosys.io.bsr_result import BsrController, BsrResult, read_bsr_result, write_bsr_result
from mosys.io.trajectory import FigureMotion
from mosys.plots.bsr import (
    filmstrip_figure,
    letter_levels,
    plot_filmstrip,
    pose_offsets,
    rule_letter,
    write_motion_gif,
)
from mosys.plots.bsr_learning import (
    curves_on_grid,
    learning_comparison_figure,
    learning_figure,
    plot_learning,
    plot_learning_comparison,
)
from mosys.plots.bsr_results import best_result_path, fitness_formula, group_by_search, read_result
from mosys.plots.style import (
    PlotInputError,
    choose_interval,
    controller_colors,
    frame_indices,
    spread_labels,
)

DT = 0.01  # s between the samples of the motions
ROD_NAMES = ("torso", "arm_left", "arm_right", "leg_left", "leg_right")
# the star in its own frame, m: per rod its proximal then distal end; the torso hip to neck
STAR = np.array(
    [
        [[0.0, -0.35], [0.0, 0.35]],
        [[0.0, 0.35], [-0.45, 0.75]],
        [[0.0, 0.35], [0.45, 0.75]],
        [[0.0, -0.35], [-0.3, -0.95]],
        [[0.0, -0.35], [0.3, -0.95]],
    ]
)
RULES = 4
JOINTS = 4
SENSES = 3


def star_motion(duration: float, travel: float, turns: float) -> FigureMotion:
    """The star over ``duration`` s: its middle moving ``travel`` m along x at 1.05 m up, the
    whole turning ``turns`` times clockwise, the arms waving."""
    t = np.arange(0.0, duration + DT / 2, DT)
    angle = -2 * math.pi * turns * t / duration
    wave = 0.25 * np.sin(2 * math.pi * t / 0.8)
    body = np.broadcast_to(STAR, (len(t), *STAR.shape)).copy()
    for rod, sign in ((1, -1.0), (2, 1.0)):  # the arms about the neck
        c, s = np.cos(sign * wave), np.sin(sign * wave)
        arm = body[:, rod, 1] - body[:, rod, 0]
        body[:, rod, 1, 0] = body[:, rod, 0, 0] + c * arm[:, 0] - s * arm[:, 1]
        body[:, rod, 1, 1] = body[:, rod, 0, 1] + s * arm[:, 0] + c * arm[:, 1]
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    x = c * body[..., 0] - s * body[..., 1]
    y = s * body[..., 0] + c * body[..., 1]
    com = np.stack([travel * t / duration, np.full_like(t, 1.05)], axis=1)
    endpoints = np.stack([x, y], axis=-1) + com[:, None, None, :]
    rods = len(ROD_NAMES)
    return FigureMotion(
        t=t,
        endpoints=endpoints,
        com=com,
        rod_names=ROD_NAMES,
        rod_mass=np.ones(rods),
        rod_length=np.linalg.norm(STAR[:, 1] - STAR[:, 0], axis=1),
        rod_com=np.full(rods, 0.5),
        rod_inertia=np.full(rods, 0.05),
        gravity=9.81,
        terrain=[[-1000.0, 0.0], [1000.0, 0.0]],
        contact="penalty",
    )


def controller(kind: str, period: float) -> BsrController:
    rng = np.random.default_rng(7)
    target = rng.uniform(-1.0, 1.0, (RULES, JOINTS))
    tau = rng.uniform(0.05, 0.3, RULES)
    if kind == "sense":
        return BsrController(
            "sense",
            target,
            tau,
            rng.uniform(-0.5, 1.5, (RULES, SENSES)),
            rng.uniform(0.4, 4.0, (RULES, SENSES)),
            np.zeros(0),
            float("nan"),
        )
    segment = np.array([0.3, 0.2, 0.4, 0.1]) * period
    empty = np.zeros((RULES, 0))
    return BsrController("time", target, tau, empty, empty, segment, period)


def active_rules(kind: str, t: np.ndarray, period: float) -> np.ndarray:
    """Sense-based: none for the first 0.15 s, then B, C, D, B, ... every 0.35 s; time-based:
    the segment of the period each sample is in."""
    if kind == "sense":
        rules = 1 + (np.floor((t - 0.15) / 0.35).astype(np.int64) % 3)
        return np.where(t < 0.15, -1, rules)
    bounds = np.cumsum([0.3, 0.2, 0.4, 0.1])[:-1] * period
    return np.searchsorted(bounds, np.mod(t, period), side="right").astype(np.int64)


def write_search(
    directory: Path,
    name: str,
    kind: str,
    finals: dict[int, float],
    travel: float = 0.4,
    turns: float = 0.5,
    duration: float = 4.0,
    budget: int = 5000,
) -> list[Path]:
    """One search's result files ``directory/name/seedK.h5``, seed K's best fitness ending at
    ``finals[K]``; all seeds share the one motion."""
    period = 1.2
    motion = star_motion(duration, travel, turns)
    paths = []
    for seed, final in finals.items():
        rng = np.random.default_rng(seed)
        evaluations = np.arange(100, budget + 1, 100, dtype=np.int64)
        steps = rng.exponential(1.0, len(evaluations)) * rng.integers(0, 2, len(evaluations))
        best = np.cumsum(steps / np.arange(1, len(evaluations) + 1))
        best = 0.15 * final + 0.85 * final * best / best[-1]  # non-decreasing, ending at final
        terms = {"distance": travel, "rotations": turns, "contact_distance": 0.8, "max_height": 2}
        result = BsrResult(
            evaluations=evaluations,
            best_fitness=best,
            controller=controller(kind, period),
            motion=motion,
            active_rule=active_rules(kind, motion.t, period),
            joint_names=("shoulder_left", "shoulder_right", "hip_left", "hip_right"),
            sense_names=("height", "angle", "contact") if kind == "sense" else (),
            attrs={
                "name": name,
                "controller_kind": kind,
                "seed": seed,
                "evaluations": budget,
                "best_fitness": final,
                "fitness_terms": json.dumps(terms),
                "fitness_weights": json.dumps(
                    {"distance": 1.0, "rotations": -0.5, "contact_distance": 0.0}
                ),
                "duration": duration,
                "dt": 0.001,
                "figure": "starman",
            },
        )
        path = directory / name / f"seed{seed}.h5"
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bsr_result(path, result)
        paths.append(path)
    return paths


@pytest.fixture(scope="module")
def searches(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[Path]]:
    """Two searches: 'star_sense' (3 seeds; seeds 2 and 3 tie for the best) and 'star_time'
    (2 seeds, a larger fitness scale, a budget of 4000 evaluations)."""
    root = tmp_path_factory.mktemp("bsr")
    return {
        "star_sense": write_search(root, "star_sense", "sense", {3: 2.5, 1: 1.1, 2: 2.5}),
        "star_time": write_search(
            root, "star_time", "time", {1: 7.0, 2: 4.0}, travel=2.5, turns=1.0, budget=4000
        ),
    }


def legend_labels(legend) -> list[str]:
    return [text.get_text() for text in legend.get_texts()]


def test_the_fixture_writes_readable_results(searches: dict[str, list[Path]]) -> None:
    result = read_result(searches["star_time"][0])
    assert result.motion.endpoints.shape == (401, 5, 2, 2)
    assert np.all(np.diff(result.best_fitness) >= 0)
    assert result.best_fitness[-1] == pytest.approx(7.0)
    assert set(result.active_rule) == {0, 1, 2, 3}
    # the legs' ends touch the ground (y 0) when the star is upright
    assert result.motion.endpoints[0, 3:, 1, 1].min() == pytest.approx(0.1, abs=1e-9)


def test_rule_letters() -> None:
    assert [rule_letter(k) for k in (0, 1, 25, 26, 27)] == ["A", "B", "Z", "AA", "AB"]
    assert rule_letter(-1) == bsr.NO_RULE


def test_best_result_is_the_highest_fitness_ties_to_the_lowest_seed(
    searches: dict[str, list[Path]],
) -> None:
    assert best_result_path(searches["star_sense"]).name == "seed2.h5"  # 2 and 3 tie at 2.5
    assert best_result_path(searches["star_time"]).name == "seed1.h5"


def test_a_perturbed_search_is_drawn_and_titled_by_its_nominal_fitness(tmp_path: Path) -> None:
    """A search with a perturb line records the best controller's motion from the nominal
    start, whose fitness_terms add up to nominal_fitness; its best_fitness is one lucky
    perturbed draw's. The best seed (the one the composite chooses) and the title's fitness
    are the nominal ones: the filmstrip of a Beryl search with perturb said 'fitness 6.052'
    beside terms that add up to 2.052, and ranked the seeds by the lucky draws."""
    paths = write_search(tmp_path, "robust", "sense", {1: 6.0, 2: 5.0})
    for path, nominal in zip(paths, (2.0, 3.0), strict=True):
        with h5py.File(path, "r+") as file:
            file.attrs["nominal_fitness"] = nominal
            file.attrs["perturbed"] = True
    assert best_result_path(paths).name == "seed2.h5"
    title = filmstrip_figure(paths[0]).get_suptitle()
    assert "\nfitness 2: " in title and "6" not in title.split("\n")[1].split(":")[0]


def test_group_by_search_reads_the_name_attribute(searches: dict[str, list[Path]]) -> None:
    mixed = [searches["star_time"][0], *searches["star_sense"], searches["star_time"][1]]
    assert group_by_search(mixed) == {
        "star_time": searches["star_time"],
        "star_sense": searches["star_sense"],
    }


def test_curves_on_grid_hold_each_best_until_the_next_record(
    searches: dict[str, list[Path]],
) -> None:
    results = [read_result(p) for p in searches["star_sense"]]
    grid, values = curves_on_grid(results)
    assert grid[0] == 100 and grid[-1] == 5000
    np.testing.assert_allclose(values[0], results[0].best_fitness)
    later = [read_result(p) for p in searches["star_time"]]
    grid, values = curves_on_grid(later + results[:1])  # to the fewest evaluations, 4000
    assert grid[-1] == 4000 and values.shape == (3, 40)


def test_helpers() -> None:
    assert choose_interval(4.0) == 0.25  # 17 poses
    for duration in (0.7, 3.0, 10.0, 37.0, 123.0):
        count = math.floor(duration / choose_interval(duration) + 1e-9) + 1
        assert 12 <= count <= 20
    assert fitness_formula({"distance": 1.0, "rotations": -0.5, "fall": 0.0}) == (
        "fitness = 1·distance − 0.5·rotations"
    )
    np.testing.assert_array_equal(letter_levels(np.array([0.0, 0.1, 0.5, 0.55]), 0.3), [0, 1, 0, 1])
    labels = spread_labels(np.array([1.0, 1.01, 5.0]), 0.2, 0.0, 5.05)
    assert labels[1] - labels[0] == pytest.approx(0.2) and labels[2] <= 5.05


def test_poses_are_shifted_apart_only_when_the_figure_hardly_travels() -> None:
    still = star_motion(4.0, 0.2, 0.5).endpoints[::25]
    offsets, spacing, travel = pose_offsets(still)
    assert spacing > 0 and travel == pytest.approx(0.2, abs=0.2)
    np.testing.assert_allclose(np.diff(offsets), spacing)
    running = star_motion(4.0, 40.0, 0.0).endpoints[::25]
    offsets, spacing, _ = pose_offsets(running)
    assert spacing == 0 and not offsets.any()


def test_learning_figure(searches: dict[str, list[Path]]) -> None:
    figure = learning_figure(searches["star_sense"])
    curves, finals = figure.axes
    assert figure.get_suptitle() == (
        "BSR search star_sense: sense-based controller for starman, 3 seeds\n"
        "best fitness found so far by each seed; fitness = 1·distance − 0.5·rotations"
    )
    assert curves.get_xlabel() == "controller evaluations (count)"
    assert curves.get_ylabel() == "best fitness so far (Σ weight × term)"
    assert curves.get_title() == "learning curve of each seed"
    assert finals.get_title() == "final best fitness"
    steps = [line for line in curves.lines if line.get_label().startswith("seed")]
    assert [line.get_label() for line in steps] == ["seed 1", "seed 2", "seed 3"]  # by seed
    colors = controller_colors(["1", "2", "3"])
    for line, seed in zip(steps, (1, 2, 3), strict=True):
        result = read_result(searches["star_sense"][0].parent / f"seed{seed}.h5")
        np.testing.assert_array_equal(line.get_xdata(), [*result.evaluations, 5000])
        np.testing.assert_array_equal(line.get_ydata()[:-1], result.best_fitness)
        assert line.get_color() == colors[str(seed)]
    assert [text.get_text() for text in finals.texts] == [
        "seed 1: 1.10",  # one precision for all (it gave -36 beside -30.1)
        "seed 2: 2.50",
        "seed 3: 2.50",
    ]
    marks = [line for line in finals.lines if line.get_marker() == "o"]
    assert sorted(line.get_ydata()[0] for line in marks) == pytest.approx([1.1, 2.5, 2.5])
    label_y = sorted(text.get_position()[1] for text in finals.texts)
    assert label_y[2] - label_y[1] > 0  # the tied seeds' labels moved apart
    with pytest.raises(PlotInputError, match="more than one search"):
        learning_figure([*searches["star_sense"], *searches["star_time"]])


def test_learning_figure_cuts_off_a_first_population_far_below(
    searches: dict[str, list[Path]], tmp_path: Path
) -> None:
    """Figure 8 (each seed, 2-D or 3-D) cuts off a start far below the rest, as Figure 7 does:
    Rex's -7.7 over 60 of 60,000 evaluations left the curves in the top half of the plot."""
    low_start = []
    for path in searches["star_sense"]:
        result = read_bsr_result(path)
        # records at 10 and 20 evaluations far below, at 40 the first record's value: the
        # value held at 1 % of the axis (50 of 5,000 evaluations) is the usual one
        evaluations = np.concatenate([[10, 20, 40], result.evaluations])
        best = np.concatenate([[-30.0, -30.0, result.best_fitness[0]], result.best_fitness])
        low_start.append(tmp_path / path.name)
        write_bsr_result(
            low_start[-1],
            dataclasses.replace(result, evaluations=evaluations, best_fitness=best),
        )
    curves, finals = learning_figure(low_start).axes
    kept = min(float(read_bsr_result(p).best_fitness[0]) for p in searches["star_sense"])
    assert curves.get_ylim()[0] == pytest.approx(kept - bsr_learning.EARLY_PAD * (2.5 - kept))
    assert [text.get_text() for text in curves.texts] == [
        "↓ below the axis: the best of the first 20 evaluations, down to −30"
    ]
    assert finals.get_ylim()[0] >= curves.get_ylim()[0]  # the finals' panel within the cut
    whole = learning_figure(searches["star_sense"]).axes[0]
    assert not whole.texts  # nothing far below: nothing cut


def test_finals_range_zooms_only_where_the_finals_lie_close() -> None:
    # Bob's five finals on a scale from -52: a range of their own, padded
    low, high = bsr_learning.finals_range(np.array([3.22, 3.25, 3.33, 3.36, 3.89]), -52.0, 6.0)
    assert high - low == pytest.approx(max(0.67 * (1 + 2 * bsr_learning.FINALS_PAD), 0.04 * 58.0))
    assert (low + high) / 2 == pytest.approx((3.22 + 3.89) / 2)
    # spread over most of the curves' range: the curves' own scale
    assert bsr_learning.finals_range(np.array([15.0, 46.0]), 12.0, 48.0) is None
    # all equal: the least span, about them
    low, high = bsr_learning.finals_range(np.array([2.0, 2.0]), 0.0, 10.0)
    assert (low, high) == pytest.approx(
        (2.0 - 5 * bsr_learning.FINALS_LEAST, 2.0 + 5 * bsr_learning.FINALS_LEAST)
    )
    assert bsr_learning.finals_range(np.array([np.nan]), 0.0, 1.0) is None
    assert bsr_learning.finals_range(np.array([1.0]), 1.0, 1.0) is None
    # one seed: nothing to tell apart (its dot was drawn alone on a scale of a thousandth)
    assert bsr_learning.finals_range(np.array([0.378]), 0.37, 0.38) is None
    assert bsr_learning.finals_range(np.array([0.378, np.nan]), 0.37, 0.38) is None


@given(
    st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=12),
    st.floats(-1e3, 1e3),
    st.floats(1e-3, 2e3),
)
def test_finals_range_holds_every_final(values: list[float], low: float, size: float) -> None:
    """Whatever the finals, the zoomed range holds them all, is no narrower than FINALS_LEAST
    and no wider than FINALS_ZOOM of the curves' range."""
    finals = np.clip(np.array(values), low, low + size)
    zoom = bsr_learning.finals_range(finals, low, low + size)
    if zoom is not None:
        rounding = 8 * math.ulp(abs(low) + size)  # the range's ends are rounded numbers
        assert zoom[0] <= finals.min() and finals.max() <= zoom[1]
        assert bsr_learning.FINALS_LEAST * size - rounding <= zoom[1] - zoom[0]
        assert zoom[1] - zoom[0] <= bsr_learning.FINALS_ZOOM * size + rounding


@given(
    st.lists(
        st.lists(st.floats(0.0, 100.0), min_size=1, max_size=20),
        min_size=1,
        max_size=5,
    ),
    st.floats(0.0, 1.0),
    st.floats(0.0, 3.0),
)
def test_the_late_band_holds_the_late_values_and_is_narrow(
    searches: dict[str, list[Path]], steps: list[list[float]], start: float, shrink: float
) -> None:
    """Whatever the seeds' curves (each a non-decreasing best so far, recorded at evaluations
    1, 2, 4, ..., its rises shrinking or not), the band of their late progress, where there is
    one, holds every value they hold from a quarter of the evaluations on, and is no wider than
    the late spread allows, padded; where the late values span more than LATE_SPREAD of the
    scale, or nothing (one flat line), there is none."""
    template = read_bsr_result(searches["star_sense"][0])
    results = []
    for rises in steps:
        # non-decreasing, as a best so far is; rises shrinking as a search's do, or not
        best = start + np.cumsum(np.array(rises) / (1.0 + shrink * np.arange(len(rises))) ** 2)
        evaluations = 2 ** np.arange(len(best), dtype=np.int64)
        results.append(dataclasses.replace(template, evaluations=evaluations, best_fitness=best))
    right_end = max(int(r.evaluations[-1]) for r in results)
    everything = np.concatenate([r.best_fitness for r in results])
    low, high = float(everything.min()) - 1.0, float(everything.max()) + 1.0
    late = np.concatenate(
        [bsr_learning.held_from(r, bsr_learning.LATE_SHARE * right_end) for r in results]
    )
    band = bsr_learning.late_band(results, right_end, low, high)
    if np.ptp(late) > bsr_learning.LATE_SPREAD * (high - low):
        event("late progress readable: no band")
        assert band is None
        return
    if np.ptp(late) == 0:
        event("no late progress: no band")
        assert band is None
        return
    event("late progress too narrow: a band")
    assert band is not None
    rounding = 8 * math.ulp(abs(low) + abs(high))
    assert band[0] <= late.min() + rounding and late.max() - rounding <= band[1]
    widest = max(
        np.ptp(late) * (1 + 2 * bsr_learning.FINALS_PAD),
        bsr_learning.FINALS_LEAST * (high - low),
    )
    assert band[1] - band[0] <= widest + rounding


def test_learning_plot_writes_a_png(searches: dict[str, list[Path]], tmp_path: Path) -> None:
    out = tmp_path / "learning.png"
    plot_learning(searches["star_sense"], out)
    width, height = assert_png(out, least_width=600)
    assert width > height


def test_learning_comparison_figure(searches: dict[str, list[Path]]) -> None:
    figure = learning_comparison_figure(searches)
    raw, scaled = figure.axes
    assert figure.get_suptitle().startswith("Learning curves for both kinds of motion controller")
    medians = [line for line in raw.lines if len(line.get_xdata()) > 1]
    assert [line.get_linestyle() for line in medians] == ["-", "--"]  # sense solid, time dashed
    bands = [c for c in raw.collections if isinstance(c, PolyCollection)]
    assert len(bands) == 2  # min..max over the seeds of each search
    grid, values = curves_on_grid([read_result(p) for p in searches["star_time"]])
    np.testing.assert_allclose(medians[1].get_ydata(), np.nanmedian(values, axis=0))
    scaled_lines = [line for line in scaled.lines if len(line.get_xdata()) > 2]
    assert [line.get_ydata()[-1] for line in scaled_lines] == pytest.approx([1.0, 1.0])
    assert raw.get_xlabel() == scaled.get_xlabel() == "controller evaluations (count)"
    assert scaled.get_ylabel() == "median best fitness / final median (fraction)"
    (legend,) = figure.legends
    assert legend_labels(legend) == [
        "star_sense (sense-based, 3 seeds)",
        "star_time (time-based, 2 seeds)",
    ]


def test_learning_comparison_of_one_kind_names_only_that_kind(
    searches: dict[str, list[Path]],
) -> None:
    """Sense-based searches alone: the title said 'time-based dashed' of no curve drawn."""
    figure = learning_comparison_figure({"star_sense": searches["star_sense"]})
    assert figure.get_suptitle() == (
        "Learning curves of BSR searches\nsense-based controllers solid"
    )
    figure = learning_comparison_figure({"star_time": searches["star_time"]})
    assert figure.get_suptitle().endswith("\ntime-based controllers dashed")


def test_learning_comparison_writes_a_png(searches: dict[str, list[Path]], tmp_path: Path) -> None:
    out = tmp_path / "comparison.png"
    plot_learning_comparison(searches, out)
    width, height = assert_png(out, least_width=600)
    assert width > 1.5 * height


@pytest.mark.parametrize("search", ["star_sense", "star_time"])
def test_filmstrip_figure(searches: dict[str, list[Path]], search: str) -> None:
    path = searches[search][0]
    figure = filmstrip_figure(path)
    *rows, colorbar = figure.axes
    result = read_result(path)
    t = result.motion.t
    interval = choose_interval(float(t[-1] - t[0]))
    assert interval == 0.25  # 4 s: 17 poses
    samples = frame_indices(t, interval)
    seed = int(result.attrs["seed"])
    kind = "sense-based" if search == "star_sense" else "time-based"
    assert figure.get_suptitle().startswith(
        f"BSR search {search} (starman), seed {seed}: {kind} controller, 4 rules"
    )
    assert "poses every 0.25 s from 0 s to 4 s" in figure.get_suptitle()
    assert colorbar.get_ylabel() == "time t (s)"
    poses = [c for ax in rows for c in ax.collections if isinstance(c, LineCollection)]
    assert len(poses) == len(samples) == 17  # one stick figure per pose
    letters = [text.get_text() for ax in rows for text in ax.texts]
    assert letters == [rule_letter(result.active_rule[s]) for s in samples]
    assert all(ax.get_ylabel() == "y (m)" and ax.get_aspect() == 1.0 for ax in rows)
    assert rows[-1].get_xlabel().startswith("x (m)")
    # both travel less than half a pose width per pose: the poses are shifted apart
    assert "each pose shifted right by" in figure.get_suptitle()
    drawn_x = [pose.get_segments()[0][:, 0].mean() for pose in poses]
    assert np.all(np.diff(drawn_x) > 0)


def test_filmstrip_writes_a_png(searches: dict[str, list[Path]], tmp_path: Path) -> None:
    out = tmp_path / "star_time.png"
    plot_filmstrip(searches["star_time"][0], out)
    assert_png(out, least_width=600)


@pytest.mark.slow
def test_motion_gif_is_small_and_real_time(searches: dict[str, list[Path]], tmp_path: Path) -> None:
    out = tmp_path / "motion.gif"
    write_motion_gif(searches["star_time"][0], out)
    assert 10_000 < out.stat().st_size < 2_000_000
    with Image.open(out) as gif:
        assert gif.n_frames == 101  # 4 s, a frame every 40 ms, both ends
        assert gif.info["duration"] == 40
        assert 400 < gif.size[0] < 800
    assert not list(tmp_path.glob(".*.partial"))
    short = tmp_path / "short.gif"
    write_motion_gif(searches["star_time"][0], short, max_frames=9)
    with Image.open(short) as gif:
        assert gif.n_frames == 9 and gif.info["duration"] == 500


@pytest.mark.slow
def test_cli_draws_the_best_seed(
    searches: dict[str, list[Path]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    drawn = []
    real = bsr.plot_filmstrip

    def recorded(result_path, path, *args, **kwargs):
        drawn.append(Path(result_path).name)
        return real(result_path, path, *args, **kwargs)

    monkeypatch.setattr(bsr, "plot_filmstrip", recorded)
    learning, strip, gif = tmp_path / "l.png", tmp_path / "f.png", tmp_path / "m.gif"
    files = [str(p) for p in searches["star_sense"]]
    code = main(
        ["plot", "bsr", *files, "--learning", str(learning), "--filmstrip", str(strip)]
        + ["--gif", str(gif)]
    )
    assert code == 0
    assert drawn == ["seed2.h5"]
    assert_png(learning, least_width=600)
    assert_png(strip, least_width=600)
    assert gif.stat().st_size > 10_000


def test_cli_comparison_groups_files_by_search(
    searches: dict[str, list[Path]], tmp_path: Path
) -> None:
    out = tmp_path / "compare.png"
    files = [str(p) for paths in searches.values() for p in paths]
    assert main(["plot", "bsr-learning", *files, "-o", str(out)]) == 0
    assert_png(out, least_width=600)


def test_cli_rejects_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    bogus = tmp_path / "bogus.h5"
    bogus.write_text("not hdf5")
    assert main(["plot", "bsr", str(bogus), "--learning", str(tmp_path / "l.png")]) == 2
    assert "bogus.h5" in capsys.readouterr().err
    assert not (tmp_path / "l.png").exists()
    with pytest.raises(SystemExit):
        main(["plot", "bsr", str(bogus)])  # no output asked for


def test_counts_read_as_words():
    from mosys.plots.style import counted

    assert [counted(n, "seed") for n in (1, 2)] == ["1 seed", "2 seeds"]  # "1 seeds" in a title


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6))
@example(-0.004)
@example(-1.5)
def test_a_measured_term_that_rounds_to_zero_has_no_minus(value):
    """A 3-D filmstrip's legend printed 'distance −0.00 m' for a figure that went nowhere."""
    from mosys.plots.bsr3d import TERMS_3D
    from mosys.plots.bsr_results import terms_text
    from mosys.plots.style import number_text

    text = number_text(value, ".2f")
    assert text == format(value, ".2f").replace("-", "−") or text == "0.00"
    assert text != "−0.00"
    if value == -0.004:
        assert terms_text({"distance": value}, TERMS_3D) == "distance +0.00 m"
