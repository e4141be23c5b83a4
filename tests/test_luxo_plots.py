"""Luxo's plots (the motion strip of Figure 22, the show GIF, torques and ground forces) from a
short real trajectory: the lamp compiled from specs/figures/luxo.fig, a hop motor program run
from the standing pose by the real kernel, written with its figure_motion and contacts. The
figures are checked through their matplotlib artists (``motion_strip_figure``,
``torques_and_forces_figure``)."""

from __future__ import annotations

import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from conftest import assert_png
from matplotlib.collections import LineCollection
from matplotlib.colors import same_color
from PIL import Image

import mosys.plots.luxo as luxo
import mosys.plots.style as style
from mosys.animation.motion_measures import motions
from mosys.animation.motor_program import BoundMotorProgram
from mosys.dynamics.compile import compile_figure
from mosys.dynamics.figure_motion import figure_contacts, figure_motion
from mosys.dynamics.load import load_dynamics
from mosys.io.trajectory import Trajectory, read_trajectory, write_trajectory
from mosys.parsing.motor import parse_motor_program_text
from mosys.plots.luxo import (
    COM_COLOR,
    HEAD_LENGTH,
    HEAD_MOUTH,
    STILL_DISTANCE,
    contact_labels,
    head_outline,
    motion_strip_figure,
    net_rotation,
    plot_motion_strip,
    plot_torques_and_forces,
    strip_samples,
    torques_and_forces_figure,
    write_show_gif,
)
from mosys.plots.style import POSE_TIMES, pan
from mosys.ssc.grid import control_scale, state_unit

LUXO = Path(__file__).resolve().parents[1] / "specs" / "figures" / "luxo.fig"
DT = 0.001  # s
HOP = """
figure luxo
limit hip_torque=20 elbow_torque=20
gains kp=6 kd=0.25
phase 0.2 hip=30 elbow=95                  # crouch
phase 0.08 hip=41 elbow=64 kp=6 kd=0.3     # push off
phase 0.2 hip=-20 elbow=26                 # in the air
"""
HOP_SECONDS = 0.48
LAND_STEPS = 120  # the last samples, credited to a landing controller in the 'landed' file


@pytest.fixture(scope="module")
def lamp(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    out = tmp_path_factory.mktemp("luxo") / "luxo.py"
    compile_figure(LUXO, out)
    return load_dynamics(out)


def hop_trajectory(lamp: ModuleType, controllers, kinds, controller) -> Trajectory:
    """The hop program from the standing pose (base flat at x = 0, hip 0, elbow 120 deg)."""
    program = BoundMotorProgram(parse_motor_program_text(HOP), lamp)
    names = tuple(lamp.STATE_NAMES)
    scale = np.array([state_unit(lamp, name)[1] for name in names])
    standing = np.zeros(len(names))
    standing[names.index("elbow")] = math.radians(120.0)
    run = program.run(standing, DT)
    states = run.states
    t = DT * np.arange(len(states))
    control_names = tuple(name for name in lamp.INPUT_NAMES if name)
    controls = np.vstack([run.controls, run.controls[-1:]])  # the last step's held
    controls = controls / np.array([control_scale(lamp, name) for name in control_names])
    return Trajectory(
        t=t,
        state=states / scale,
        control=controls,
        controller=np.asarray(controller(len(t)), dtype=np.int64),
        state_order=names,
        control_names=control_names,
        controllers=controllers,
        attrs={"controller_kinds": list(kinds), "figure": "luxo", "script": "test_hop.anim"},
        motion=figure_motion(lamp, t, states),
        contacts=figure_contacts(lamp, states),
    )


@pytest.fixture(scope="module")
def hop_path(tmp_path_factory: pytest.TempPathFactory, lamp: ModuleType) -> Path:
    """A trajectory of one motor program, 'hop'."""
    path = tmp_path_factory.mktemp("trajectories") / "hop.h5"
    write_trajectory(path, hop_trajectory(lamp, ("hop",), ["motor"], np.zeros))
    return path


@pytest.fixture(scope="module")
def landed_path(tmp_path_factory: pytest.TempPathFactory, lamp: ModuleType) -> Path:
    """The same samples, the last LAND_STEPS of them credited to a landing controller 'land'."""
    path = tmp_path_factory.mktemp("trajectories") / "landed.h5"

    def controller(count: int) -> np.ndarray:
        return np.where(np.arange(count) < count - LAND_STEPS, 1, 0)

    trajectory = hop_trajectory(lamp, ("land", "hop"), ["controller", "motor"], controller)
    write_trajectory(path, trajectory)
    return path


def legend_labels(legend) -> list[str]:
    return [text.get_text() for text in legend.get_texts()]


def test_the_fixture_is_one_hop(hop_path: Path, landed_path: Path) -> None:
    trajectory = read_trajectory(hop_path)
    assert [(m.name, m.start, m.end) for m in motions(trajectory)] == [
        ("hop", 0, len(trajectory.t))
    ]
    assert trajectory.t[-1] == pytest.approx(HOP_SECONDS)
    landed = read_trajectory(landed_path)
    assert [(m.name, m.start, m.end) for m in motions(landed)] == [("hop", 0, len(landed.t))]


@pytest.mark.parametrize("fixture", ["hop_path", "landed_path"])
def test_motion_strip_draws_the_lamp_every_interval(fixture: str, request) -> None:
    path = request.getfixturevalue(fixture)
    figure = motion_strip_figure(path, "hop", every=0.04)
    ax, colorbar = figure.axes
    trajectory = read_trajectory(path)
    (hop,) = motions(trajectory)
    rotation = net_rotation(trajectory, hop)
    assert ax.get_title() == (
        f"Luxo: hop (net base rotation {rotation:.0f}°)\n".replace("-", "−")
        + "poses every 0.04 s from t = 0.00 s to 0.48 s, the landing included"
    )
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m)", "y (m)")
    assert ax.get_aspect() == 1.0
    assert colorbar.get_ylabel() == "time since the motion began (s)"
    motion = trajectory.motion
    samples = strip_samples(trajectory.t, motion.endpoints, 0, len(trajectory.t) - 1, 0.04)
    assert 3 <= len(samples) <= 13
    lamps = [c for c in ax.collections if isinstance(c, LineCollection)]
    assert len(lamps) == len(samples)  # one lamp (its rods) per pose drawn
    for lamp, sample in zip(lamps, samples, strict=True):
        np.testing.assert_allclose(lamp.get_segments(), motion.endpoints[sample])
    assert same_color(lamps[0].get_color()[0], POSE_TIMES(0.0))  # light to dark
    assert same_color(lamps[-1].get_color()[0], POSE_TIMES(1.0))
    heads = [p for p in ax.patches if p.get_zorder() > 3]
    assert len(heads) == len(samples)  # a lamp shade on each
    (com,) = [line for line in ax.lines if same_color(line.get_color(), COM_COLOR)]
    np.testing.assert_allclose(com.get_xydata(), motion.com)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()  # every pose in view
    drawn = motion.endpoints[samples]
    assert x0 < drawn[..., 0].min() and drawn[..., 0].max() < x1
    assert y0 < drawn[..., 1].min() and drawn[..., 1].max() < y1
    (legend,) = figure.legends
    assert legend_labels(legend) == [
        "ground",
        "Luxo every 0.04 s (once when still), light → dark",
        "centre of mass",
    ]


def test_motion_strip_writes_a_png(hop_path: Path, tmp_path: Path) -> None:
    out = tmp_path / "strip.png"
    plot_motion_strip(hop_path, out, "hop", every=0.04)
    width, height = assert_png(out, least_bytes=20_000)
    assert width > height  # a strip


def test_a_strip_without_a_motion_named_draws_the_first(hop_path: Path) -> None:
    """The default was 'backflip': a show of your own without one failed in the pipeline."""
    from mosys.plots.luxo import motion_strip_figure

    figure = motion_strip_figure(hop_path, None)
    assert figure.axes[0].get_title().startswith("Luxo: hop (")


def test_motion_strip_names_the_motions_there_are(hop_path: Path, tmp_path: Path) -> None:
    out = tmp_path / "strip.png"
    with pytest.raises(
        ValueError, match=r"no motion called 'backflip' \(--motion\); its motions: hop$"
    ):
        plot_motion_strip(hop_path, out, "backflip")
    with pytest.raises(ValueError, match="every must be a positive number of seconds, got 0"):
        plot_motion_strip(hop_path, out, "hop", every=0)
    assert not out.exists()


def test_a_motion_run_twice_is_picked_by_its_count(lamp: ModuleType) -> None:
    """``--motion hop`` drew the first of two hops and nothing drew the second."""

    def controller(count: int) -> np.ndarray:  # hop, land, hop, land: a quarter each
        return (np.arange(count) * 4 // count) % 2

    trajectory = hop_trajectory(lamp, ("hop", "land"), ["motor", "controller"], controller)
    halfway = -(-len(trajectory.t) // 2)  # the first sample with 4 k // count = 2
    first, second = (luxo.find_motion(trajectory, name) for name in ("hop", "hop:2"))
    assert (first.start, second.start) == (0, halfway)
    assert luxo.find_motion(trajectory, "hop:1") == first
    for wrong in ("hop:3", "hop:0", "hop:x", "land"):
        with pytest.raises(ValueError) as raised:
            luxo.find_motion(trajectory, wrong, "show.h5")
        assert str(raised.value) == (
            f"show.h5: no motion called {wrong!r} (--motion); its motions: hop (runs 2 times: "
            "hop:1..hop:2)"
        )


@pytest.mark.parametrize("fixture", ["hop_path", "landed_path"])
def test_torques_and_forces_figure(fixture: str, request) -> None:
    path = request.getfixturevalue(fixture)
    figure = torques_and_forces_figure(path)
    timeline, torques, forces = figure.axes
    trajectory = read_trajectory(path)
    assert timeline.get_title() == "Luxo's joint torques and ground forces: test_hop.anim"
    assert [text.get_text() for text in timeline.texts] == ["hop"]  # the motion, named
    expected = ["motor program driving"]
    if fixture == "landed_path":
        expected.append("then controller land")
    assert legend_labels(timeline.get_legend()) == expected
    names = list(trajectory.control_names)
    assert torques.get_legend().get_title().get_text() == "actuator"
    assert legend_labels(torques.get_legend()) == names
    for j, name in enumerate(names):
        (line,) = [line for line in torques.lines if line.get_label() == name]
        np.testing.assert_array_equal(line.get_ydata(), trajectory.control[:, j])
    assert torques.get_ylabel() == "joint torque (N·m)"
    weight = float(np.sum(trajectory.motion.rod_mass) * trajectory.motion.gravity)
    assert forces.get_legend().get_title().get_text() == "contact point"
    assert legend_labels(forces.get_legend()) == [
        "base front edge",
        "base back edge",
        "head",
        f"Luxo's weight, {weight:.1f} N",
    ]
    magnitude = np.linalg.norm(trajectory.contacts.force, axis=2)
    for c, label in enumerate(["base front edge", "base back edge", "head"]):
        (line,) = [line for line in forces.lines if line.get_label() == label]
        np.testing.assert_array_equal(line.get_ydata(), magnitude[:, c])
    assert magnitude.max() > weight  # the push off
    assert forces.get_yscale() == "symlog"
    assert forces.get_xlabel() == "time t (s)"
    assert forces.get_xlim() == pytest.approx((0.0, HOP_SECONDS))


def test_torques_and_forces_writes_a_png(landed_path: Path, tmp_path: Path) -> None:
    out = tmp_path / "torques.png"
    plot_torques_and_forces(landed_path, out)
    assert_png(out, least_bytes=20_000)


@pytest.mark.parametrize("fixture", ["hop_path", "landed_path"])
def test_show_gif_has_a_frame_per_step(fixture: str, request, tmp_path: Path) -> None:
    out = tmp_path / "show.gif"
    write_show_gif(request.getfixturevalue(fixture), out, fps=25)
    assert 10_000 < out.stat().st_size < 5_000_000
    with Image.open(out) as gif:
        assert gif.format == "GIF"
        assert gif.n_frames == round(HOP_SECONDS * 25) + 1  # t = 0, 0.04, ..., 0.48 s
        assert gif.info["duration"] == 40  # ms: real time
    assert not list(tmp_path.glob(".*.partial"))


def test_show_gif_keeps_to_max_frames(hop_path: Path, tmp_path: Path) -> None:
    out = tmp_path / "show.gif"
    write_show_gif(hop_path, out, fps=100, max_frames=5)
    with Image.open(out) as gif:
        assert gif.n_frames == 5
        assert gif.info["duration"] == 120  # ms: the step widened to 0.48 s / 4
    with pytest.raises(ValueError, match="fps must be a positive whole number"):
        write_show_gif(hop_path, out, fps=0)


def test_show_gif_follows_a_lamp_wider_than_the_view(
    landed_path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a view 0.3 m wide (narrower than the lamp), the figure up to 1.6 times taller than wide
    monkeypatch.setattr(luxo, "FOLLOW_WIDTH", 0.3)
    monkeypatch.setattr(luxo, "ASPECT_RANGE", (0.3, 1.6))  # the window's height / width
    monkeypatch.setattr(style, "ASPECT_RANGE", (0.3, 1.6))  # the view's (style.fit_aspect)
    views = []

    def recorded_pan(view, x):
        views.append(pan(view, x))
        return views[-1]

    monkeypatch.setattr(luxo, "pan", recorded_pan)
    out = tmp_path / "follow.gif"
    write_show_gif(landed_path, out, fps=25)
    with Image.open(out) as gif:
        assert gif.n_frames == len(views) > 1
    assert any(view is not None for view in views)  # it panned


def test_pan_recentres_the_view_when_the_lamp_leaves_its_middle_half() -> None:
    assert pan((0.0, 4.0), 1.0) is None
    assert pan((0.0, 4.0), 3.0) is None
    assert pan((0.0, 4.0), 3.5) == (1.5, 5.5)
    assert pan((0.0, 4.0), -1.0) == (-3.0, 1.0)


def test_contact_labels_name_luxos_contact_points(lamp: ModuleType) -> None:
    rods = [lamp.ROD_NAMES[rod] for rod in lamp.CONTACT_ROD]
    assert contact_labels(rods, lamp.CONTACT_FRACTION) == [
        "base front edge",
        "base back edge",
        "head",
    ]
    assert contact_labels(["lower"], [0.5]) == ["lower at 0.5 of its length"]


def test_head_outline_is_a_shade_at_the_upper_rods_end() -> None:
    shade = head_outline(np.array([0.0, 0.0]), np.array([0.0, -0.25]))  # pointing down
    np.testing.assert_allclose(shade[[1, 2]].mean(axis=0), [0.0, -0.25], atol=1e-12)
    assert np.linalg.norm(shade[1] - shade[2]) == pytest.approx(2 * HEAD_MOUTH)
    assert shade[[0, 3]].mean(axis=0)[1] == pytest.approx(-0.25 + HEAD_LENGTH)
    assert head_outline(np.zeros((7, 2)), np.ones((7, 2))).shape == (7, 4, 2)


def test_net_rotation_is_the_base_angles_change(hop_path: Path) -> None:
    trajectory = read_trajectory(hop_path)
    (hop,) = motions(trajectory)
    base = trajectory.state[:, trajectory.state_order.index("base")]
    assert net_rotation(trajectory, hop) == pytest.approx(base[-1] - base[0])


def test_strip_samples_draw_a_still_lamp_once() -> None:
    t = np.arange(101) * 0.01
    still = np.zeros((101, 3, 2, 2))
    np.testing.assert_array_equal(strip_samples(t, still, 0, 100, 0.05), [0, 100])
    moving = still + (t * 10 * STILL_DISTANCE / 0.05)[:, None, None, None]  # 10x the threshold
    samples = strip_samples(t, moving, 10, 90, 0.05)
    np.testing.assert_array_equal(samples, np.arange(10, 91, 5))
