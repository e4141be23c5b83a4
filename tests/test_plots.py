"""The pendulum plots: the cylindrical path splitting (hypothesis), and what each plot draws
(through its matplotlib Figure) from hand-made tables and a hand-made trajectory, quick; the
phase portraits and the CLI from controllers generated here by the DP from the real specs, slow."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_png
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from matplotlib.collections import QuadMesh
from matplotlib.colors import same_color
from matplotlib.contour import ContourSet
from matplotlib.lines import Line2D
from PIL import Image

import mosys.plots.script as script_plots
from mosys.cli import main
from mosys.io.controller_table import (
    ControllerTable,
    read_controller_table,
    write_controller_table,
)
from mosys.io.trajectory import FigureMotion, Trajectory, read_trajectory, write_trajectory
from mosys.parsing.controller import parse_controller_spec
from mosys.plots.controller import plot_torque, portrait_figure, portrait_starts, torque_figure
from mosys.plots.controls import controls_figure
from mosys.plots.script import (
    covered_pieces,
    plot_script,
    script_path_figure,
    write_script_gif,
)
from mosys.plots.state_space import StateAxis, cylinder_pieces, format_state_axes
from mosys.plots.style import (
    MARGIN_BOTTOM,
    MARGIN_TOP,
    PlotInputError,
    add_legend,
    controller_colors,
    frame_step,
    new_figure,
)
from mosys.ssc.generate import generate_controller

ROOT = Path(__file__).resolve().parents[1]
PENDULUM_SPECS = ROOT / "specs" / "controllers" / "pendulum"
PENDULUM_AXES = (
    StateAxis("angle", "deg", -180.0, 180.0, 360.0),
    StateAxis("omega", "deg/s", -500.0, 500.0, None),
)
ANGLES = np.arange(-180.0, 171.0, 10.0)  # the specs' grid: 36 nodes, wrapped
RATES = np.linspace(-500.0, 500.0, 21)
DESTINATIONS = {"A": {"angle": 0.0, "omega": 0.0}, "D": {"angle": 0.0, "omega": 300.0}}
DT = 0.001  # s between the samples of the hand-made trajectory


# --------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def drawn_tables(tmp_path_factory) -> dict[str, Path]:
    """Hand-made controllers A (rest at 0 deg) and D (periodic: 0 deg at 300 deg/s) on the
    specs' grid, enough for the plots that only read a table: a PD torque law (N·m, within
    ±10) and a cost-to-go (s) growing with the distance from the destination."""
    directory = tmp_path_factory.mktemp("drawn_controllers")
    angle, rate = np.meshgrid(ANGLES, RATES, indexing="ij")
    paths = {}
    for name, dest in DESTINATIONS.items():
        error = (angle - dest["angle"], rate - dest["omega"])
        torque = np.clip(-0.05 * error[0] - 0.02 * error[1], -10.0, 10.0)[..., None]
        value = 2.0 * np.hypot(error[0] / 180.0, error[1] / 500.0)
        paths[name] = directory / f"{name}.h5"
        write_controller_table(
            paths[name],
            ControllerTable(
                state_order=("angle", "omega"),
                control_names=("torque",),
                axes=(ANGLES, RATES),
                axis_units=("deg", "deg/s"),
                wrap=(True, False),
                torque=torque,
                value=value,
                control_min=np.array([-10.0]),
                control_max=np.array([10.0]),
                effort_weight=np.array([0.1]),
                dest=dest,
                figure="link1",
                attrs={"dt": DT},
            ),
        )
    return paths


@pytest.fixture(scope="module")
def trajectory(tmp_path_factory) -> Path:
    """A hand-made two-controller script, 1 s: A from (-135 deg, 400 deg/s) for 0.5 s, then D;
    the angle passes +180 deg (wraps to -180) near t = 0.8 s. The rod (1 m, pinned at the
    origin) at the angle as its figure_motion."""
    t = DT * np.arange(1001)
    rate = 400.0 - 60.0 * t
    unwrapped = -135.0 + 400.0 * t - 30.0 * t**2
    angle = (unwrapped + 180.0) % 360.0 - 180.0
    radians = np.radians(angle)
    endpoints = np.zeros((len(t), 1, 2, 2))
    endpoints[:, 0, 1] = np.column_stack([np.cos(radians), np.sin(radians)])
    motion = FigureMotion(
        t=t,
        endpoints=endpoints,
        com=0.5 * endpoints[:, 0, 1],
        rod_names=("link",),
        rod_mass=np.array([1.0]),
        rod_length=np.array([1.0]),
        rod_com=np.array([0.5]),
        rod_inertia=np.array([1.0 / 12.0]),
        gravity=9.81,
        terrain=[],
        contact="none",
    )
    path = tmp_path_factory.mktemp("trajectories") / "two_controllers.h5"
    write_trajectory(
        path,
        Trajectory(
            t=t,
            state=np.column_stack([angle, rate]),
            control=np.zeros((len(t), 1)),
            controller=(t >= 0.5 - 1e-9).astype(np.int64),
            state_order=("angle", "omega"),
            control_names=("torque",),
            controllers=("A", "D"),
            attrs={
                "script": "two_controllers.anim",
                "figure": "link1",
                "switch_times": [0.0, 0.5],
                "switch_controllers": ["A", "D"],
            },
            motion=motion,
        ),
    )
    return path


@pytest.fixture(scope="module")
def dynamics(link1):
    """The real pendulum dynamics, compiled from specs/figures/link1.fig (conftest)."""
    return link1


@pytest.fixture(scope="module")
def tables(dynamics, tmp_path_factory) -> dict[str, Path]:
    """Controllers A and D generated by the DP from the real specs (slow: a few seconds)."""
    directory = tmp_path_factory.mktemp("controllers")
    paths = {}
    for name in "AD":
        paths[name] = directory / f"{name}.h5"
        spec = parse_controller_spec(PENDULUM_SPECS / f"{name}.ssc")
        generate_controller(spec, dynamics, paths[name], quiet=True)
    return paths


def legend_labels(figure) -> list[str]:
    (legend,) = figure.legends
    return [text.get_text() for text in legend.get_texts()]


def marker_lines(ax, marker: str) -> list:
    return [line for line in ax.lines if line.get_marker() == marker]


def assert_destination_marked(ax, x: float, y: float) -> None:
    """mark_destination's encircled X: a white halo under a black circle and cross at (x, y)."""
    marks = [
        line for line in ax.lines if line.get_marker() in ("o", "x") and line.get_zorder() >= 5
    ]
    marks = [line for line in marks if line.get_markersize() >= 6.8]
    assert sorted(line.get_marker() for line in marks) == ["o", "o", "x", "x"]
    for line in marks:
        assert (line.get_xdata()[0], line.get_ydata()[0]) == (x, y)


def assert_no_partials(directory: Path) -> None:
    assert not [p for p in directory.iterdir() if "partial" in p.name]


# --------------------------------------------------------------------------- wrap splitting


@st.composite
def wrapped_paths(draw):
    """(angles, period): samples anywhere in one period, often a random walk that wraps."""
    period = draw(st.floats(1e-3, 1e4, allow_nan=False, allow_infinity=False))
    low = draw(st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False))
    if draw(st.booleans()):
        fractions = draw(st.lists(st.floats(0.0, 1.0, exclude_max=True), max_size=60))
        return low + period * np.array(fractions, dtype=np.float64), period
    steps = draw(st.lists(st.floats(-0.45, 0.45), min_size=1, max_size=200))
    unwrapped = np.cumsum(np.array(steps)) * period
    return low + np.mod(unwrapped, period), period


def wrap_axes(period: float) -> tuple[StateAxis, StateAxis]:
    """An angle axis of ``period`` and a rate axis that does not wrap."""
    return (
        StateAxis("angle", "deg", -period / 2, period / 2, period),
        StateAxis("omega", "deg/s", -1.0, 1.0, None),
    )


@given(wrapped_paths())
@example((np.array([2048.0, 2048.0005]), 0.001))  # a step of half a period, at 2048
@settings(max_examples=300, deadline=None)
def test_cylinder_pieces_have_no_jumps_and_lose_no_points(case):
    """Each piece, its borrowed neighbours aside, is a run of the path: the runs cover it once,
    in order, split only where the angle jumps by more than half a period; and no piece, its
    neighbours shifted by whole periods included, steps by more than half a period. A step of
    half a period is either, to the rounding of the angles' magnitude (2048.001 - 2048.0005 is
    0.0005 + 2e-13: a relative tolerance of the period failed there)."""
    angle, period = case
    slack = 8 * np.finfo(float).eps * (float(np.max(np.abs(angle), initial=0.0)) + period)
    points = np.column_stack([angle, np.arange(len(angle), dtype=np.float64)])
    pieces = cylinder_pieces(points, wrap_axes(period))
    runs = []
    for k, piece in enumerate(pieces):
        assert np.all(np.abs(np.diff(piece[:, 0])) <= period / 2 + slack)
        runs.append(piece[(k > 0) : len(piece) - (k < len(pieces) - 1)])
    joined = np.concatenate(runs) if runs else np.empty((0, 2))
    np.testing.assert_array_equal(joined, points)
    starts = np.cumsum([0] + [len(run) for run in runs])[1:-1]
    for start in starts:  # splits only where it must: at a jump
        assert abs(angle[start] - angle[start - 1]) > period / 2 - slack


def test_cylinder_pieces_count_the_wraps_of_a_spinning_pendulum():
    unwrapped = np.linspace(-170.0, 170.0 + 2 * 360.0, 500)  # two whole turns, counter-clockwise
    wrapped = -180.0 + np.mod(unwrapped + 180.0, 360.0)
    path = np.column_stack([wrapped, np.zeros_like(wrapped)])
    assert len(cylinder_pieces(path, PENDULUM_AXES)) == 3
    assert cylinder_pieces(np.empty((0, 2)), PENDULUM_AXES) == []


def test_cylinder_pieces_run_on_to_the_edges():
    path = np.array([[170.0, 10.0], [178.0, 20.0], [-176.0, 30.0], [-170.0, 40.0]])
    first, second = cylinder_pieces(path, PENDULUM_AXES)
    np.testing.assert_allclose(first, [[170, 10], [178, 20], [184, 30]])  # on past +180
    np.testing.assert_allclose(second, [[-182, 20], [-176, 30], [-170, 40]])  # in from -180


def test_portrait_starts_are_spread_over_the_domain():
    starts = portrait_starts(PENDULUM_AXES, 8)
    assert starts.shape == (8, 2)
    assert len({tuple(s) for s in starts}) == 8
    assert np.all((starts[:, 0] >= -180) & (starts[:, 0] < 180))
    assert np.all(np.abs(starts[:, 1]) <= 400)
    assert np.ptp(starts[:, 0]) > 270 and np.ptp(starts[:, 1]) > 600


# --------------------------------------------------------------------------- the plots


@pytest.mark.parametrize("name", ["A", "D"])
def test_torque_figure_draws_the_table_as_a_heat_map(drawn_tables, name):
    figure = torque_figure(drawn_tables[name])
    ax, colorbar = figure.axes
    dest = DESTINATIONS[name]
    assert ax.get_title() == (
        f"Controller {name}: torque table, 36 × 21 nodes\n"
        f"destination θ = 0 deg, ω = {dest['omega']:g} deg/s"
    )
    assert ax.get_xlabel() == "angle θ (deg) — cylindrical"
    assert ax.get_ylabel() == "omega ω (deg/s)"
    assert ax.get_xlim() == (-180.0, 180.0)  # one period of the wrapped angle
    assert ax.get_ylim() == pytest.approx((-520.0, 520.0))  # the range and a 2 % margin
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    assert mesh.get_array().shape == (21, 37)  # a cell per node, the wrapped edge repeated
    assert mesh.get_clim() == (-10.0, 10.0)  # centred on 0 N·m
    assert mesh.get_array().min() < -5 and mesh.get_array().max() > 5
    assert colorbar.get_ylabel() == "torque (N·m)"
    (contours,) = [c for c in ax.collections if isinstance(c, ContourSet)]
    np.testing.assert_allclose(np.diff(contours.levels), contours.levels[0])  # round steps
    assert 6 <= len(contours.levels) <= 12
    labels = [text.get_text() for text in ax.texts]
    assert labels and all(label.endswith(" s") for label in labels)
    # apart from each other and from the destination's mark (they piled up where the contours
    # converge on it)
    size = ax.get_position().size * figure.get_size_inches()
    inches = [ax.transLimits.transform(text.get_position()) * size for text in ax.texts]
    mark = ax.transLimits.transform((dest["angle"], dest["omega"])) * size
    for k, here in enumerate(inches):
        assert np.hypot(*(here - mark)) >= 0.45
        assert all(np.hypot(*(here - other)) >= 0.45 for other in inches[:k])
    assert_destination_marked(ax, dest["angle"], dest["omega"])
    assert legend_labels(figure) == ["cost-to-go, contours labelled in s", "destination"]


def test_torque_writes_a_png(drawn_tables, tmp_path):
    out = tmp_path / "plots" / "torque_A.png"  # the directory is made as needed
    plot_torque(drawn_tables["A"], out)
    assert assert_png(out) == (840, 696)  # 7 x 5.8 inches at 120 dpi
    assert_no_partials(out.parent)


def test_script_figure_draws_each_controllers_stretch(trajectory, drawn_tables):
    figure = script_path_figure(trajectory, [drawn_tables["A"], drawn_tables["D"]])
    (ax,) = figure.axes
    assert ax.get_title() == (
        "State-space path of the animation script two_controllers.anim\n"
        "2 controller invocations over 1.00 s"
    )
    assert ax.get_xlabel() == "angle θ (deg) — cylindrical"
    assert ax.get_xlim() == (-180.0, 180.0)
    colors = controller_colors(["A", "D"])
    state = read_trajectory(trajectory).state
    paths = [line for line in ax.lines if line.get_linewidth() == 1.8]
    # each stretch cut where the angle wraps: A's one piece, D's two (it passes +180 deg)
    expected = [("A", piece) for piece in cylinder_pieces(state[:501], PENDULUM_AXES)]
    expected += [("D", piece) for piece in cylinder_pieces(state[500:], PENDULUM_AXES)]
    assert len(paths) == len(expected) == 3
    for line, (name, piece) in zip(paths, expected, strict=True):
        assert same_color(line.get_color(), colors[name])
        np.testing.assert_array_equal(line.get_xydata(), piece)
    starts = marker_lines(ax, "s")
    assert [(s.get_xdata()[0], s.get_ydata()[0]) for s in starts] == [
        tuple(state[0]),
        tuple(state[500]),
    ]
    for start, name in zip(starts, "AD", strict=True):
        assert same_color(start.get_markerfacecolor(), colors[name])
    (end,) = [line for line in ax.lines if line.get_marker() == "o" and line.get_markersize() == 5]
    assert (end.get_xdata()[0], end.get_ydata()[0]) == tuple(state[-1])
    assert sorted(text.get_text() for text in ax.texts) == ["dA", "dD", "sA", "sD"]
    assert legend_labels(figure) == [
        "controller A",
        "controller D",
        "sX: controller X invoked",
        "dX: destination of controller X",
        "end, t = 1.00 s",
    ]


def test_script_figure_without_tables_draws_no_destinations(trajectory):
    figure = script_path_figure(trajectory, [])
    (ax,) = figure.axes
    assert sorted(text.get_text() for text in ax.texts) == ["sA", "sD"]
    assert "dX: destination of controller X" not in legend_labels(figure)
    assert ax.get_ylim() == pytest.approx((-520.0, 520.0))  # the pendulum's rates, deg/s
    assert not [line for line in ax.lines if line.get_marker() == "x"]


def test_a_breakpoint_box_open_in_omega_is_shaded_across_the_plot_only(
    trajectory, drawn_tables, tmp_path
):
    """A ``when`` box bounding the angle alone spans the plot's rates, clipped to its limits
    (an edge reaching to ±1e9 deg/s took Agg 16 s to dash)."""
    source = read_trajectory(trajectory)
    attrs = dict(
        source.attrs,
        breakpoints='[{"box": {"angle": [75.0, 105.0]}, '
        '"controller": "D", "once": true, "line": 3}]',
    )
    path = tmp_path / "breakpoint.h5"
    write_trajectory(path, dataclasses.replace(source, attrs=attrs))
    figure = script_path_figure(path, [drawn_tables["A"], drawn_tables["D"]])
    (ax,) = figure.axes
    (box,) = [patch for patch in ax.patches if patch.get_alpha() == pytest.approx(0.18)]
    (x0, y0), (x1, y1) = box.get_bbox().get_points()
    assert (x0, x1) == (75.0, 105.0)
    assert (y0, y1) == pytest.approx(ax.get_ylim())
    assert "breakpoint: 75 < angle < 105 → D (once)" in legend_labels(figure)


def test_copies_of_a_breakpoint_are_shaded_once_and_counted(trajectory, drawn_tables, tmp_path):
    """500 ``when`` lines with one box and controller (the verb fuzz wrote 10,000): their
    shading stacked opaque over the path; now one box, and the legend counts the lines. A
    different controller on the same box is a box of its own."""
    source = read_trajectory(trajectory)
    copy = {"box": {"angle": [75.0, 105.0]}, "controller": "D", "once": True}
    written = [dict(copy, line=3 + k) for k in range(500)]
    written.append(dict(copy, controller="A", line=503))
    path = tmp_path / "copies.h5"
    attrs = dict(source.attrs, breakpoints=json.dumps(written))
    write_trajectory(path, dataclasses.replace(source, attrs=attrs))
    figure = script_path_figure(path, [drawn_tables["A"], drawn_tables["D"]])
    (ax,) = figure.axes
    boxes = [patch for patch in ax.patches if patch.get_alpha() == pytest.approx(0.18)]
    assert len(boxes) == 2
    labels = legend_labels(figure)
    assert "breakpoint: 75 < angle < 105 → D (once, 500 lines)" in labels
    assert "breakpoint: 75 < angle < 105 → A (once)" in labels


def test_many_distinct_breakpoints_are_shaded_and_counted_in_the_legend(
    trajectory, drawn_tables, tmp_path
):
    """300 ``when`` boxes made a legend taller than the figure, and matplotlib raised."""
    source = read_trajectory(trajectory)
    written = [
        {"box": {"angle": [k - 150.0, k - 149.5]}, "controller": "AD"[k % 2], "once": False}
        for k in range(300)
    ]
    path = tmp_path / "distinct.h5"
    attrs = dict(source.attrs, breakpoints=json.dumps(written))
    write_trajectory(path, dataclasses.replace(source, attrs=attrs))
    figure = script_path_figure(path, [drawn_tables["A"], drawn_tables["D"]])
    (ax,) = figure.axes
    assert len([patch for patch in ax.patches if patch.get_alpha() == pytest.approx(0.18)]) == 300
    labels = [label for label in legend_labels(figure) if "breakpoint" in label]
    assert labels == [
        "breakpoint: -150 < angle < -149.5 → A",
        "breakpoint: -149 < angle < -148.5 → D",
        "breakpoint: -148 < angle < -147.5 → A",
        "297 more breakpoints, each in its controller's colour",
    ]
    out = tmp_path / "distinct.png"
    plot_script(path, [drawn_tables["A"], drawn_tables["D"]], out)
    assert assert_png(out) == (912, 768)


def test_script_writes_a_png(trajectory, drawn_tables, tmp_path):
    out = tmp_path / "script.png"
    plot_script(trajectory, [drawn_tables["A"], drawn_tables["D"]], out)
    assert assert_png(out) == (912, 768)


def test_a_long_scripts_gif_keeps_to_the_frame_limit_in_real_time(
    trajectory, tmp_path, monkeypatch
):
    monkeypatch.setattr(script_plots, "REAL_TIME_MAX_FRAMES", 6)
    out = tmp_path / "script.gif"
    write_script_gif(trajectory, out)  # 1 s: 26 frames at 25 fps
    with Image.open(out) as gif:
        assert gif.n_frames == 6  # every 0.2 s
        assert gif.info["duration"] == 200


def test_frame_step():
    assert frame_step(1.0, 25, 600) == 0.04  # a frame per 1/fps
    assert frame_step(0.0, 20, 600) == 0.05
    assert frame_step(2000.0, 20, 600) == 3.34  # 2000 / 599, up to whole hundredths
    assert frame_step(29.96, 20, 600) == 0.06  # 600 frames would be 0.050017 s apart


def test_gif_is_animated(trajectory, tmp_path):
    out = tmp_path / "script.gif"
    write_script_gif(trajectory, out)
    assert out.read_bytes()[:6] == b"GIF89a"
    assert_no_partials(tmp_path)
    with Image.open(out) as gif:
        assert gif.n_frames == 26  # 1.0 s at 25 frames per second, both ends included
        assert gif.info["duration"] == 40
        first = np.asarray(gif.convert("RGB"))
        gif.seek(gif.n_frames - 1)
        assert gif.info["duration"] == 40  # the last frame not held
        last = np.asarray(gif.convert("RGB"))
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 20
    assert np.any(first != last)  # the pendulum moved


@pytest.mark.slow
@pytest.mark.parametrize("name", ["A", "D"])
def test_portrait_draws_closed_loop_paths_from_spread_starts(dynamics, tables, name):
    figure = portrait_figure(tables[name], dynamics)
    (ax,) = figure.axes
    dest = DESTINATIONS[name]
    assert ax.get_title() == (
        f"Controller {name}: destination θ = 0 deg, ω = {dest['omega']:g} deg/s\n"
        "closed-loop paths, 3 s from each of 8 start states"
    )
    assert ax.get_xlabel() == "angle θ (deg) — cylindrical"
    assert ax.get_ylabel() == "omega ω (deg/s)"
    starts = marker_lines(ax, "s")
    np.testing.assert_allclose(
        [(s.get_xdata()[0], s.get_ydata()[0]) for s in starts],
        portrait_starts(PENDULUM_AXES, 8),
    )
    paths = [line for line in ax.lines if line.get_linewidth() == 1.3]
    assert len(paths) >= 8  # a path from each start, more where it wraps
    assert len({tuple(line.get_color()) for line in paths}) == 8  # a colour each
    assert all(len(line.get_xdata()) > 100 for line in paths[:1])
    cycle = [line for line in ax.lines if line.get_linewidth() == 5.0]
    expected = ["start state (one colour per path)", "destination"]
    if name == "D":  # a periodic destination: its cycle drawn thick and grey
        assert cycle
        expected.insert(0, "cycle through the destination")
    else:
        assert not cycle
    assert legend_labels(figure) == expected
    assert_destination_marked(ax, dest["angle"], dest["omega"])


@pytest.mark.slow
def test_cli_makes_every_plot_kind(trajectory, tables, dynamics, tmp_path):
    portrait, torque = tmp_path / "portrait.png", tmp_path / "torque.png"
    commands = [
        [
            "controller",
            str(tables["D"]),
            "--dynamics",
            dynamics.__file__,
            "--portrait",
            str(portrait),
            "--torque",
            str(torque),
        ],
        [
            "script",
            str(trajectory),
            str(tables["A"]),
            str(tables["D"]),
            "--path",
            str(tmp_path / "script.png"),
            "--gif",
            str(tmp_path / "script.gif"),
        ],
    ]
    for command in commands:
        assert main(["plot", *command]) == 0
    for name in ("portrait.png", "torque.png", "script.png"):
        assert_png(tmp_path / name)
    with Image.open(tmp_path / "script.gif") as gif:
        assert gif.n_frames == 26


def test_cli_portrait_without_dynamics_exits_2_and_writes_nothing(drawn_tables, tmp_path, capsys):
    out = tmp_path / "portrait.png"
    with pytest.raises(SystemExit) as exit_:
        main(["plot", "controller", str(drawn_tables["A"]), "--portrait", str(out)])
    assert exit_.value.code == 2
    assert "--portrait needs --dynamics" in capsys.readouterr().err
    assert not out.exists()


def test_cli_gif_of_a_trajectory_without_figure_motion_exits_2(trajectory, tmp_path, capsys):
    import shutil

    import h5py

    bare = tmp_path / "bare.h5"
    shutil.copy(trajectory, bare)
    with h5py.File(bare, "a") as h5:
        del h5["figure_motion"]
    out = tmp_path / "x.gif"
    assert main(["plot", "script", str(bare), "--gif", str(out)]) == 2
    assert capsys.readouterr().err.startswith("mosys: ")
    assert not out.exists()


@pytest.mark.parametrize(("span", "max_frames"), [(3.49, 9), (17.3, 120), (2.0, 200), (0.01, 5)])
def test_animation_steps_are_whole_hundredths_so_gifs_play_in_real_time(span, max_frames):
    from mosys.plots.style import frame_samples

    t = np.arange(0.0, span + 1e-9, 0.001)
    samples, step = frame_samples(t, 25, max_frames)
    assert round(step * 100) == pytest.approx(step * 100, abs=1e-9)  # a GIF stores centiseconds
    assert step >= 1 / 25 and len(samples) <= max_frames
    assert samples[-1] == len(t) - 1


@pytest.mark.parametrize(
    ("suffix", "magic"), [(".png", b"\x89PNG"), (".pdf", b"%PDF"), (".svg", b"<?xml")]
)
def test_a_plot_is_written_in_the_format_its_file_name_names(tmp_path, suffix, magic):
    from matplotlib.figure import Figure

    from mosys.plots.style import save_figure

    figure = Figure()
    figure.add_subplot().plot([0, 1], [1, 0])
    out = tmp_path / f"plot{suffix}"
    save_figure(figure, out)
    assert out.read_bytes().startswith(magic)


def test_a_plot_file_name_without_a_known_format_is_refused(tmp_path):
    """A ``.jpg`` (or no extension) is a PlotInputError (the CLI's exit 2) naming the formats
    taken, and nothing is written."""
    from matplotlib.figure import Figure

    from mosys.plots.style import PlotInputError, save_figure

    for name in ("plot.jpg", "plot"):
        with pytest.raises(PlotInputError, match=r"ends in \.png, \.pdf, \.svg"):
            save_figure(Figure(), tmp_path / name)
    assert list(tmp_path.iterdir()) == []


def test_controls_figure_draws_a_single_sample_and_says_it_has_no_rate(trajectory, tmp_path):
    """A run that begins at its destination has one sample: its control was drawn as a line of
    one point, which shows nothing, above an empty rate panel."""
    whole = read_trajectory(trajectory)
    lone = tmp_path / "at_destination.h5"
    first = dataclasses.replace(
        whole,
        t=whole.t[:1],
        state=whole.state[:1],
        control=whole.control[:1],
        controller=whole.controller[:1],
        attrs={**whole.attrs, "script": "at_destination.anim", "switch_times": [0.0]},
        motion=None,
    )
    write_trajectory(lone, first)
    figure = controls_figure([lone])
    top, bottom = figure.axes
    (point,) = top.lines
    assert point.get_marker() == "o" and list(point.get_xdata()) == [0.0]
    assert legend_labels(figure) == ["at_destination.anim (no limit; a single sample)"]
    (note,) = bottom.texts
    assert note.get_text() == "no rate of change: no two samples apart in time"
    # the control's name as the figure spells it (it was capitalised: 'Elbow_torque')
    assert top.get_title().startswith("torque against time: at_destination.anim\n")
    both = controls_figure([trajectory, lone])
    assert not both.axes[1].texts and both.axes[0].lines[0].get_marker() in ("", "None", None)


def test_controls_figure_labels_each_control_in_the_unit_its_file_records(trajectory, tmp_path):
    """The unit came from the control's name (N·m for a torque, "spec unit" for anything
    else), though the file records it: a car's steer_rate was labelled "spec unit"."""
    assert controls_figure([trajectory]).axes[0].get_ylabel() == "torque (N·m)"
    whole = read_trajectory(trajectory)
    steered = tmp_path / "steered.h5"
    write_trajectory(
        steered,
        dataclasses.replace(
            whole,
            control_names=("steer_rate",),
            control_units=("deg/s^2",),
            attrs={**whole.attrs, "script": "steered.anim"},
        ),
    )
    top, bottom = controls_figure([steered]).axes
    assert top.get_ylabel() == "steer_rate (deg/s²)"
    assert bottom.get_ylabel() == "|dsteer_rate/dt| (deg/s²/s)"


def test_a_colour_few_frames_show_keeps_its_own_palette_entry():
    """A GIF's palette was cut from 8 sampled frames: a rule active in none of them was drawn in
    another rule's colour (Star-Man's cartwheel: rule D red drawn brown). Here 300 shades fill
    every frame, and a red square shows in one frame of 40."""
    from mosys.plots.style import shared_palette

    shades = np.zeros((30, 100, 3), np.uint8)
    shades[..., 0] = np.arange(100)[None, :]
    shades[..., 1] = np.arange(30)[:, None] * 8
    shades[..., 2] = 120
    red = (214, 39, 40)
    frames = []
    for k in range(40):
        pixels = np.full((60, 100, 3), 255, np.uint8)
        pixels[:30] = shades
        if k == 13:
            pixels[40:50, 40:50] = red
        frames.append(Image.fromarray(pixels))
    quantized = shared_palette(frames)
    shown = np.asarray(quantized[13].convert("RGB"))
    assert tuple(shown[45, 45]) == red
    assert len({tuple(frame.getpalette()) for frame in quantized}) == 1  # one palette


def test_script_figure_names_a_motor_programs_start_by_its_name(trajectory, drawn_tables, tmp_path):
    """A motor program 'swing' was labelled 'sswing' and counted as a controller invocation."""
    whole = read_trajectory(trajectory)
    motor = tmp_path / "with_motor.h5"
    attrs = {**whole.attrs, "switch_controllers": ["A", "swing"]}
    attrs["controller_kinds"] = ["controller", "motor"]
    write_trajectory(motor, dataclasses.replace(whole, controllers=("A", "swing"), attrs=attrs))
    figure = script_path_figure(motor, [drawn_tables["A"]])
    (ax,) = figure.axes
    assert ax.get_title().splitlines()[1] == (
        "1 controller invocation and 1 motor program over 1.00 s"
    )
    assert {"sA", "swing", "dA"} <= {text.get_text() for text in ax.texts}
    labels = legend_labels(figure)
    assert "motor program swing" in labels
    assert "sX: controller X invoked; P: motor program P started" in labels


def test_the_ends_of_a_range_a_path_leaves_are_dashed_and_named():
    """The slew script's path passes 500 deg/s: the dashed lines at ±500 had no legend entry."""
    from matplotlib.figure import Figure

    inside = np.array([[0.0, 0.0], [90.0, 400.0]])
    outside = np.array([[0.0, 0.0], [90.0, 520.0]])
    ax = Figure().add_subplot()
    assert format_state_axes(ax, PENDULUM_AXES, inside) == []
    assert not [line for line in ax.lines if line.get_linestyle() == "--"]
    ax = Figure().add_subplot()
    ((handle, text),) = format_state_axes(ax, PENDULUM_AXES, outside)
    assert text == "ends of the table's ω range (the path leaves it)"
    dashed = [line for line in ax.lines if line.get_linestyle() == "--"]
    assert sorted(line.get_ydata()[0] for line in dashed) == [-500.0, 500.0]
    assert handle.get_linestyle() == "--"


def test_torque_figure_greys_the_nodes_without_a_cost_to_go(drawn_tables, tmp_path):
    """Unreachable nodes were drawn white, as if their torque were 0 N·m."""
    from mosys.io.controller_table import read_controller_table

    table = read_controller_table(drawn_tables["A"])
    value = table.value.copy()
    value[:5, :3] = np.inf
    path = tmp_path / "A.h5"
    write_controller_table(path, dataclasses.replace(table, value=value))
    figure = torque_figure(path)
    ax = figure.axes[0]
    meshes = [c for c in ax.collections if isinstance(c, QuadMesh)]
    assert len(meshes) == 2
    grey = np.ma.getmaskarray(meshes[1].get_array()).reshape(21, 37)
    assert (~grey).sum() == 15 + 3  # the 15 nodes, and -180 deg's 3 again at +180
    assert legend_labels(figure)[0] == "no cost-to-go (15 unreachable nodes)"
    assert not [
        c
        for c in torque_figure(drawn_tables["A"]).axes[0].collections
        if isinstance(c, QuadMesh) and np.ma.is_masked(c.get_array())
    ]


def test_script_figure_refuses_tables_of_which_none_drives_the_script(
    trajectory, drawn_tables, tmp_path
):
    """They drew no destination and said nothing; a directory's tables, some used, still do."""
    import shutil

    from mosys.plots.style import PlotInputError

    other = tmp_path / "Z.h5"
    shutil.copy(drawn_tables["A"], other)
    with pytest.raises(PlotInputError) as error:
        script_path_figure(trajectory, [other])
    assert str(error.value) == (
        f"{trajectory}: none of the tables given (Z) is one of the script's controllers (A, D)"
    )
    script_path_figure(trajectory, [other, drawn_tables["A"]])  # one of them is used


def test_phase_planes_pair_each_coordinate_with_its_rate():
    """A 2-D state is one plane; coordinates followed by their rates give a plane each; any
    other state is refused, naming its variables and units (the car hint for a car's)."""
    from mosys.plots.script import phase_planes
    from mosys.plots.style import PlotInputError

    def axes(*units, names=None):
        names = names or [f"v{i}" for i in range(len(units))]
        return [StateAxis(n, u, 0.0, 1.0, None) for n, u in zip(names, units, strict=True)]

    assert phase_planes(axes("m", "deg")) == [(0, 1)]  # 2-D: as given, whatever its units
    assert phase_planes(axes("deg", "deg", "deg/s", "deg/s")) == [(0, 2), (1, 3)]
    assert phase_planes(axes("deg", "m", "deg/s", "m/s")) == [(0, 2), (1, 3)]
    for units in [("deg", "deg/s", "deg", "deg/s"), ("deg", "deg", "deg/s"), ("deg",), ()]:
        with pytest.raises(PlotInputError, match="coordinates followed by their rates"):
            phase_planes(axes(*units))
    car = axes("m", "m", "deg", "deg", names=["x", "y", "heading", "steer"])
    with pytest.raises(PlotInputError) as error:
        phase_planes(car)
    assert str(error.value) == (
        "a state-space path is drawn for a 2-D state, or for coordinates followed by their "
        "rates (units U then U/s); this state is x, y, heading, steer in m, m, deg, deg "
        "(a car's runs are drawn by mosys plot car)"
    )


def write_double_pendulum_table(path: Path) -> None:
    """A 4-D controller table H (shoulder, elbow and their rates) at path: zero torques."""
    names = ("shoulder", "elbow", "shoulder_rate", "elbow_rate")
    angles = np.arange(-180.0, 91.0, 90.0)
    rates = np.linspace(-200.0, 200.0, 5)
    shape = (4, 4, 5, 5)
    write_controller_table(
        path,
        ControllerTable(
            state_order=names,
            control_names=("shoulder_torque", "elbow_torque"),
            axes=(angles, angles, rates, rates),
            axis_units=("deg", "deg", "deg/s", "deg/s"),
            wrap=(True, True, False, False),
            torque=np.zeros((*shape, 2)),
            value=np.ones(shape),
            control_min=np.array([-40.0, -20.0]),
            control_max=np.array([40.0, 20.0]),
            effort_weight=np.array([0.01, 0.01]),
            dest={"shoulder": -90.0, "elbow": 0.0, "shoulder_rate": 0.0, "elbow_rate": 0.0},
            figure="double_pendulum",
            attrs={"dt": DT},
        ),
    )


def test_a_controller_plot_of_a_four_dimensional_table_is_refused_with_its_dimensions(
    tmp_path, capsys
):
    """A portrait or torque map is drawn over a coordinate and its rate: a double pendulum's
    table is refused, exit 2, naming its state (it used to say 'a pendulum plot needs a 2-D
    controller table' of any figure), and nothing is written."""
    table = tmp_path / "H.h5"
    write_double_pendulum_table(table)
    assert main(["plot", "controller", str(table), "--torque", str(tmp_path / "t.png")]) == 2
    assert capsys.readouterr().err == (
        f"mosys: {table}: a controller's portrait and torque map need a table of 2 state "
        "dimensions (a coordinate and its rate), this one has 4: shoulder, elbow, "
        "shoulder_rate, elbow_rate\n"
    )
    assert not (tmp_path / "t.png").exists()


def test_a_trajectory_without_units_is_drawn_only_as_an_angle_and_its_rate():
    """A file without state units (written before they were kept) is read as an angle and
    its rate; any other width is refused, naming the columns."""
    trajectory = Trajectory(
        t=np.zeros(2),
        state=np.zeros((2, 3)),
        control=np.zeros((2, 1)),
        controller=np.zeros(2, dtype=np.int64),
        state_order=("x", "y", "theta"),
        control_names=("torque",),
        controllers=("A",),
        attrs={},
        motion=None,
    )
    with pytest.raises(PlotInputError) as error:
        script_plots.trajectory_axes(trajectory)
    assert str(error.value) == (
        "a trajectory without state units is drawn as an angle and its rate (2 columns), "
        "this one has x, y, theta"
    )


def test_script_path_of_a_four_dimensional_state_draws_a_plane_per_joint(tmp_path):
    """A double pendulum's script (shoulder, elbow and their rates) is drawn in two panels,
    each coordinate against its rate, with the controller's destination in each and one title
    over both; without its table the axes come from the trajectory's units. Until 2026-12-05 it
    was refused ('a pendulum plot needs a 2-D controller table'), so the pipeline's job that
    draws a script's path and GIF failed, and the GIF was never made."""
    names = ("shoulder", "elbow", "shoulder_rate", "elbow_rate")
    t = DT * np.arange(501)
    state = np.column_stack([-30 - 60 * t, 20 - 20 * t, -60 + 0 * t, -20 + 0 * t])
    trajectory = tmp_path / "hang.h5"
    write_trajectory(
        trajectory,
        Trajectory(
            t=t,
            state=state,
            control=np.zeros((len(t), 2)),
            controller=np.zeros(len(t), dtype=np.int64),
            state_order=names,
            control_names=("shoulder_torque", "elbow_torque"),
            controllers=("H",),
            attrs={"script": "hang.anim"},
            motion=None,
            state_units=("deg", "deg", "deg/s", "deg/s"),
            control_units=("N*m", "N*m"),
        ),
    )
    table = tmp_path / "H.h5"
    write_double_pendulum_table(table)
    figure = script_path_figure(trajectory, [table])
    shoulder, elbow = figure.axes
    assert (shoulder.get_xlabel(), shoulder.get_ylabel()) == (
        "shoulder (deg) — cylindrical",
        "shoulder_rate (deg/s)",
    )
    assert elbow.get_ylabel() == "elbow_rate (deg/s)"
    assert figure.get_suptitle().startswith("State-space path of the animation script hang.anim")
    assert not shoulder.get_title() and not elbow.get_title()
    for ax, destination, start in [
        (shoulder, (-90.0, 0.0), tuple(state[0, [0, 2]])),
        (elbow, (0.0, 0.0), tuple(state[0, [1, 3]])),
    ]:
        texts = {text.get_text(): text.xy for text in ax.texts}
        assert texts["dH"] == destination  # in this panel's plane
        assert texts["sH"] == start
    labels = legend_labels(figure)
    assert len(labels) == len(set(labels))  # each entry once, not once a panel
    assert labels[-1] == "end, t = 0.50 s"
    bare = script_path_figure(trajectory, [])
    assert [ax.get_ylabel() for ax in bare.axes] == ["shoulder_rate (deg/s)", "elbow_rate (deg/s)"]
    assert bare.axes[0].get_ylim()[1] >= 500  # the paper's rate scale, as for the pendulum
    # a table of some of the figure's variables (Luxo's landing table: four of ten) draws on
    # the trajectory's axes, its destination in the panels whose variables it names
    for names_, dest in [(("elbow", "elbow_rate"), 10.0), (("wrist", "wrist_rate"), None)]:
        part = tmp_path / "partial" / "H.h5"
        part.parent.mkdir(exist_ok=True)
        write_controller_table(
            part,
            dataclasses.replace(
                read_controller_table(table),
                state_order=names_,
                axes=read_controller_table(table).axes[1::2],
                axis_units=("deg", "deg/s"),
                wrap=(True, False),
                torque=np.zeros((4, 5, 2)),
                value=np.ones((4, 5)),
                dest={names_[0]: 0.0, names_[1]: 0.0},
            ),
        )
        if dest is None:
            with pytest.raises(PlotInputError, match="differs from that of its controller H"):
                script_path_figure(trajectory, [part])
            continue
        shoulder, elbow = script_path_figure(trajectory, [part]).axes
        assert "dH" not in {t.get_text() for t in shoulder.texts}
        assert {t.get_text(): t.xy for t in elbow.texts}["dH"] == (0.0, 0.0)


def test_a_wide_rate_axis_is_not_ticked_every_100_degrees_per_second():
    """The paper's ±500 deg/s takes a tick every 100; a backflip's ±3,200 took 64, a black
    smear down the axis (Luxo's script path): wide ranges keep matplotlib's own step."""
    from matplotlib.figure import Figure

    for reach, most in [(500.0, 11), (3200.0, 12)]:
        ax = Figure().add_subplot()
        axes = (
            StateAxis("angle", "deg", -180.0, 180.0, 360.0),
            StateAxis("omega", "deg/s", -reach, reach, None),
        )
        format_state_axes(ax, axes)
        ticks = [t for t in ax.get_yticks() if -reach * 1.02 <= t <= reach * 1.02]
        assert 5 <= len(ticks) <= most, ticks


@pytest.mark.parametrize(
    ("labels", "columns"),
    [
        (["short"] * 6, 3),  # fits: as asked
        (["a breakpoint's bounds on several state variables, " * 2] * 6, 1),  # too wide
    ],
)
def test_a_legend_takes_fewer_columns_where_its_columns_are_wider_than_the_figure(labels, columns):
    figure = new_figure(9.12, 7.68)
    figure.add_subplot()
    add_legend(figure, [(Line2D([], []), label) for label in labels], ncols=3)
    (legend,) = figure.legends
    figure.canvas.draw()  # the texts' places
    renderer = figure.canvas.get_renderer()
    starts = {round(text.get_window_extent(renderer).x0) for text in legend.get_texts()}
    assert len(starts) == columns
    assert legend.get_window_extent(renderer).width <= figure.bbox.width


@pytest.mark.parametrize("entries", [6, 60, 300])
def test_a_long_legend_makes_the_figure_taller_not_the_axes_vanish(entries):
    """300 entries in 3 columns left the axes no room, and matplotlib raised; the axes keep
    at least half the height they have without a legend, the figure growing for it."""
    figure = new_figure(9.12, 7.68)
    ax = figure.add_subplot()
    add_legend(figure, [(Line2D([], []), f"controller C{k}") for k in range(entries)], ncols=3)
    height = ax.get_position().height * figure.get_figheight()
    without = 7.68 - MARGIN_TOP - MARGIN_BOTTOM
    assert height >= 0.5 * without - 1e-9
    assert (figure.get_figheight() == 7.68) == (entries == 6)


ANGLE = StateAxis("angle", "deg", -180.0, 180.0, 360.0)
OMEGA = StateAxis("omega", "deg/s", -520.0, 520.0, None)


def test_a_breakpoint_box_is_drawn_where_the_runtime_reads_it():
    view = (-180.0, 180.0)
    assert covered_pieces(75.0, 105.0, ANGLE, view) == [(75.0, 105.0)]
    assert covered_pieces(170.0, 190.0, ANGLE, view) == [(170.0, 180.0), (-180.0, -170.0)]
    assert covered_pieces(435.0, 465.0, ANGLE, view) == [(75.0, 105.0)]  # a turn on
    # the verb fuzz's 7.5e13..1.05e26 deg: every angle, not a box from 7.5e13 (a hang)
    assert covered_pieces(7.5e13, 1.05e26, ANGLE, view) == [view]
    assert covered_pieces(75.0, math.inf, ANGLE, view) == [(75.0, 180.0)]  # one side: as it is
    assert covered_pieces(600.0, 700.0, OMEGA, (-520.0, 520.0)) == []  # off the plot
    assert covered_pieces(-1e300, 1e300, OMEGA, (-520.0, 520.0)) == [(-520.0, 520.0)]


@settings(max_examples=300, deadline=None)
@given(
    low=st.floats(-1e4, 1e4),
    width=st.floats(0.0, 800.0),
    angle=st.floats(-180.0, 180.0, exclude_max=True),
)
def test_an_angle_is_shaded_exactly_where_it_lies_in_the_box(low, width, angle):
    """On a wrap axis, an angle of the view lies in a drawn piece exactly where the runtime's
    test (``inside_region``: modulo the period from the lower bound) puts it in the box."""
    high = low + width
    pieces = covered_pieces(low, high, ANGLE, (-180.0, 180.0))
    shifted = low + (angle - low) % 360.0
    edges = [low, high] + [end for piece in pieces for end in piece]
    assume(all(abs(shifted - edge) > 1e-6 and abs(angle - edge) > 1e-6 for edge in edges))
    assume(abs(shifted - (low + 360.0)) > 1e-6)
    inside = low <= shifted <= high
    assert inside == any(a <= angle <= b for a, b in pieces)


def test_a_breakpoint_off_the_plot_says_so_in_the_legend(trajectory, drawn_tables, tmp_path):
    source = read_trajectory(trajectory)
    written = [{"box": {"omega": [600.0, 700.0]}, "controller": "D", "once": False, "line": 3}]
    path = tmp_path / "off.h5"
    attrs = dict(source.attrs, breakpoints=json.dumps(written))
    write_trajectory(path, dataclasses.replace(source, attrs=attrs))
    figure = script_path_figure(path, [drawn_tables["A"], drawn_tables["D"]])
    (ax,) = figure.axes
    assert not [patch for patch in ax.patches if patch.get_alpha() == pytest.approx(0.18)]
    assert "breakpoint: 600 < omega < 700 → D (outside the plot)" in legend_labels(figure)
