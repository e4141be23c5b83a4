"""State-space breakpoints at run time (paper §3.1, the script's ``when``): while the state lies
in a breakpoint's box its controller drives, elsewhere the last ``swapcon``'s; and ``sim ...
until=dest`` stops in the active controller's arrival box. On the real pendulum and its
controllers A (to angle 0) and B (to angle 120)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mosys.animation.trajectory_file import run_animation_script
from mosys.dynamics.compile import compile_figure
from mosys.dynamics.load import load_dynamics
from mosys.io.trajectory import read_trajectory
from mosys.parsing.controller import parse_controller_spec
from mosys.ssc.generate import generate_controller
from mosys.ssc.regions import Regions

SPECS = Path(__file__).resolve().parents[1] / "specs"
DT = 0.001


@pytest.fixture(scope="module")
def dynamics_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("dynamics")
    compile_figure(SPECS / "figures" / "link1.fig", directory / "link1.py")
    return directory


@pytest.fixture(scope="module")
def a_and_b(tmp_path_factory: pytest.TempPathFactory, link1) -> Path:
    """Controllers A and B (the two the breakpoint test swaps), built from their specs."""
    directory = tmp_path_factory.mktemp("controllers")
    for name in "AB":
        spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / f"{name}.ssc")
        generate_controller(spec, link1, directory / f"{name}.h5", quiet=True)
    return directory


def run(tmp_path: Path, dynamics_dir: Path, controllers: Path, text: str):
    script = tmp_path / "breakpoint.anim"
    script.write_text(text)
    out = tmp_path / "breakpoint.h5"
    run_animation_script(script, controllers, dynamics_dir, out, DT, SPECS / "motor")
    return read_trajectory(out)


def test_the_breakpoint_controller_drives_exactly_while_the_state_is_in_its_box(
    tmp_path, dynamics_dir, a_and_b
):
    trajectory = run(
        tmp_path,
        dynamics_dir,
        a_and_b,
        "state link -135,350\n"
        "swapcon link conA.ctab\n"
        "when link angle>-60 angle<-20 swapcon conB.ctab\n"
        "sim 2\n",
    )
    angle = trajectory.state[:, trajectory.state_order.index("angle")]
    driver = np.array(trajectory.controllers)[trajectory.controller]
    inside = (angle > -60) & (angle < -20)
    # each sample's driver is chosen from the state at that sample (the last holds the final state)
    expected = np.where(inside, "B", "A")[:-1]
    assert inside.any() and (~inside).any()  # the swing passes through the box and leaves it
    np.testing.assert_array_equal(driver[:-1], expected)


def test_sim_until_dest_stops_at_rest_in_the_destination(tmp_path, dynamics_dir):
    """Controller A with 'hold' (without it, A's interpolated torques balance gravity 7 degrees
    short of its destination, and 'until=dest' would run the whole time)."""
    spec_path = tmp_path / "H.ssc"
    spec_path.write_text((SPECS / "controllers" / "pendulum" / "A.ssc").read_text() + "hold\n")
    link1 = load_dynamics(dynamics_dir / "link1.py")
    generate_controller(parse_controller_spec(spec_path), link1, tmp_path / "H.h5", quiet=True)
    trajectory = run(
        tmp_path,
        dynamics_dir,
        tmp_path,
        "state link -135,350\nswapcon link conH.ctab\nsim 5 until=dest\n",
    )
    end = dict(zip(trajectory.state_order, trajectory.state[-1], strict=True))
    assert trajectory.t[-1] < 4.0  # stopped early
    assert abs(end["angle"]) <= 0.02 * 10.0  # ARRIVAL_STEPS grid steps of 10 deg
    assert abs(end["omega"]) <= np.degrees(0.01)  # at rest: REST_RATE


@pytest.mark.parametrize("once", [" once", ""])
def test_a_breakpoint_written_many_times_acts_as_written_once(
    tmp_path, dynamics_dir, a_and_b, once
):
    """2,000 copies of a ``when`` line: every ``once`` copy fires at the same instant and is
    spent, a standing copy drives as one does; the motion is the one of a single line, bit for
    bit. (The verb fuzz's 10,000 copies took 32 s: the boxes were made again at every hand-over;
    now 1.8 s.)"""
    head = "state link -135,350\nswapcon link conA.ctab\n"
    line = f"when link angle>-60 angle<-20 swapcon conB.ctab{once}\n"
    tail = "sim 2\nwhen link angle>100 angle<140 swapcon conA.ctab once\nsim 1\n"
    (tmp_path / "single").mkdir()
    (tmp_path / "many").mkdir()
    single = run(tmp_path / "single", dynamics_dir, a_and_b, head + line + tail)
    many = run(tmp_path / "many", dynamics_dir, a_and_b, head + line * 2000 + tail)
    np.testing.assert_array_equal(many.state, single.state)
    assert np.array(many.controllers)[many.controller].tolist() == (
        np.array(single.controllers)[single.controller].tolist()
    )
    assert set(np.array(single.controllers)[single.controller]) == {"A", "B"}


def test_regions_without_one_box_and_joined() -> None:
    lower = np.array([[0.0, -1.0], [1.0, -2.0], [2.0, -3.0]])
    boxes = Regions(lower, lower + 1.0, np.array([2 * np.pi, 0.0]))
    fewer = boxes.without(1)
    np.testing.assert_array_equal(fewer.lower, lower[[0, 2]])
    np.testing.assert_array_equal(fewer.upper, lower[[0, 2]] + 1.0)
    both = fewer.joined(boxes)
    assert len(both) == 5
    np.testing.assert_array_equal(both.lower, np.concatenate((lower[[0, 2]], lower)))
    np.testing.assert_array_equal(both.membership(np.array([1.5, -1.5])), [0, 0, 0, 1, 0])
    np.testing.assert_array_equal(boxes.lower, lower)  # unchanged
