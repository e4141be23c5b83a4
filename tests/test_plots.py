"""The pendulum plots: the cylindrical path splitting (hypothesis), and every plot kind writing a
real, non-blank PNG or animated GIF from tables and a trajectory built here, from the real
specs, with a stand-in for the generated pendulum dynamics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from mosys.cli import main
from mosys.io.trajectory import FigureMotion, Trajectory, write_trajectory
from mosys.parsing.controller import parse_controller_spec
from mosys.plots.pendulum import (
    StateAxis,
    cylinder_pieces,
    plot_portrait,
    plot_script,
    plot_torque,
    portrait_starts,
    split_at_wraps,
    write_script_gif,
)
from mosys.ssc.controller import Controller
from mosys.ssc.generate import generate_controller

ROOT = Path(__file__).resolve().parents[1]
PENDULUM_SPECS = ROOT / "specs" / "controllers" / "pendulum"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PENDULUM_AXES = (
    StateAxis("angle", "deg", -180.0, 180.0, 360.0),
    StateAxis("omega", "deg/s", -500.0, 500.0, None),
)


# --------------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def dynamics(link1):
    """The real pendulum dynamics, compiled from specs/figures/link1.fig (conftest)."""
    return link1


@pytest.fixture(scope="module")
def tables(dynamics, tmp_path_factory) -> dict[str, Path]:
    """Controllers A (rest at 0 deg) and D (periodic: 0 deg at 300 deg/s), from the real specs."""
    directory = tmp_path_factory.mktemp("controllers")
    paths = {}
    for name in "AD":
        paths[name] = directory / f"{name}.h5"
        spec = parse_controller_spec(PENDULUM_SPECS / f"{name}.ssc")
        generate_controller(spec, dynamics, paths[name], quiet=True)
    return paths


@pytest.fixture(scope="module")
def trajectory(dynamics, tables, tmp_path_factory) -> Path:
    """A two-controller script: from (-135 deg, 350 deg/s), A for 0.5 s, then D for 0.5 s."""
    dt = 0.001
    controllers = [Controller.load(tables[name], dynamics) for name in "AD"]
    state = controllers[0].figure_state(np.array([-135.0, 350.0]))
    figure_states, controls, index = [], [], []
    for k, controller in enumerate(controllers):
        run = controller.simulate(state, 0.5, dt)
        figure_states.append(run.states[:-1])
        controls.append(run.controls)
        index.append(np.full(len(run.controls), k))
        state = run.states[-1]
    figure_states.append(state[None])
    controls.append(controls[-1][-1:])
    index.append(index[-1][-1:])
    figure_states = np.concatenate(figure_states)
    t = dt * np.arange(len(figure_states))
    angle = figure_states[:, 0]
    endpoints = np.zeros((len(t), 1, 2, 2))  # rod pinned at the origin, 1 m long
    endpoints[:, 0, 1] = np.column_stack([np.cos(angle), np.sin(angle)])
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
            state=controllers[0].controller_states(figure_states),
            control=np.concatenate(controls),
            controller=np.concatenate(index),
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


def assert_real_png(path: Path) -> None:
    """A PNG file, not blank: many colours."""
    assert path.read_bytes()[:8] == PNG_MAGIC
    with Image.open(path) as image:
        assert image.format == "PNG"
        colors = image.convert("RGB").getcolors(maxcolors=1 << 20)
        assert len(colors) > 20, f"{path} looks blank: {len(colors)} colours"


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


@given(wrapped_paths())
@settings(max_examples=300, deadline=None)
def test_split_at_wraps_has_no_jumps_and_loses_no_points(case):
    angle, period = case
    slices = split_at_wraps(angle, period)
    pieces = [angle[s] for s in slices]
    joined = np.concatenate(pieces) if pieces else np.empty(0)
    np.testing.assert_array_equal(joined, angle)
    for piece in pieces:
        assert len(piece) > 0
        assert np.all(np.abs(np.diff(piece)) <= period / 2)
    for before, after in zip(slices[:-1], slices[1:], strict=True):
        assert before.stop == after.start  # splits only where it must: at a jump
        assert abs(angle[after.start] - angle[before.stop - 1]) > period / 2


def test_split_at_wraps_counts_the_wraps_of_a_spinning_pendulum():
    unwrapped = np.linspace(-170.0, 170.0 + 2 * 360.0, 500)  # two whole turns, counter-clockwise
    wrapped = -180.0 + np.mod(unwrapped + 180.0, 360.0)
    assert len(split_at_wraps(wrapped, 360.0)) == 3
    assert split_at_wraps(np.empty(0), 360.0) == []


def test_split_at_wraps_rejects_bad_arguments():
    with pytest.raises(ValueError, match="period must be positive"):
        split_at_wraps(np.zeros(3), 0.0)
    with pytest.raises(ValueError, match="1-D"):
        split_at_wraps(np.zeros((3, 2)), 360.0)


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
def test_portrait_writes_a_png(dynamics, tables, tmp_path, name):
    out = tmp_path / f"portrait_{name}.png"
    plot_portrait(tables[name], dynamics, out)
    assert_real_png(out)
    assert_no_partials(tmp_path)


def test_torque_writes_a_png(tables, tmp_path):
    out = tmp_path / "plots" / "torque_A.png"  # the directory is made as needed
    plot_torque(tables["A"], out)
    assert_real_png(out)
    assert_no_partials(out.parent)


def test_script_writes_a_png_with_and_without_the_tables(trajectory, tables, tmp_path):
    with_tables = tmp_path / "script.png"
    plot_script(trajectory, [tables["A"], tables["D"]], with_tables)
    assert_real_png(with_tables)
    without_tables = tmp_path / "script_bare.png"
    plot_script(trajectory, [], without_tables)
    assert_real_png(without_tables)
    assert with_tables.read_bytes() != without_tables.read_bytes()  # dA, dD drawn only with tables


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
        last = np.asarray(gif.convert("RGB"))
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 20
    assert np.any(first != last)  # the pendulum moved


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
    for name in ("portrait.png", "torque.png", "script.png", "script.gif"):
        assert (tmp_path / name).stat().st_size > 1000


def test_cli_portrait_without_dynamics_exits_2_and_writes_nothing(tables, tmp_path, capsys):
    out = tmp_path / "portrait.png"
    with pytest.raises(SystemExit) as exit_:
        main(["plot", "controller", str(tables["A"]), "--portrait", str(out)])
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
