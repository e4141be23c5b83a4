"""The 1990 paper's controller exchange, run from scripts: slew limitation of the controls (§5),
a breakpoint that hands over once (§3.1, the shipped ``pendulum_catch.anim``), and the check that
each new controller takes over inside its domain (Figure 7). On the real pendulum and its
controllers A–F built from the shipped specs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from mosys.animation.trajectory_file import run_animation_script
from mosys.dynamics.compile import compile_figure
from mosys.io.controller_table import read_controller_table
from mosys.io.trajectory import read_trajectory
from mosys.parsing.controller import parse_controller_spec
from mosys.parsing.script import SlewLimit, parse_script_text, render_script
from mosys.parsing.tokens import SpecError
from mosys.ssc.generate import generate_controller

SPECS = Path(__file__).resolve().parents[1] / "specs"
DT = 0.001
SLEW = 100.0  # N m/s: the shipped pendulum_slew.anim's limit


@pytest.fixture(scope="module")
def dynamics_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("dynamics")
    compile_figure(SPECS / "figures" / "link1.fig", directory / "link1.py")
    return directory


def run(tmp_path: Path, dynamics_dir: Path, controllers: Path, text: str, name: str = "s"):
    script = tmp_path / f"{name}.anim"
    script.write_text(text)
    out = tmp_path / f"{name}.h5"
    run_animation_script(script, controllers, dynamics_dir, out, DT, SPECS / "motor")
    return read_trajectory(out)


def run_shipped(tmp_path, dynamics_dir, controllers, name: str):
    out = tmp_path / f"{name}.h5"
    run_animation_script(
        SPECS / "scripts" / f"{name}.anim", controllers, dynamics_dir, out, DT, SPECS / "motor"
    )
    return read_trajectory(out)


def torque(trajectory) -> np.ndarray:
    return trajectory.control[:, trajectory.control_names.index("torque")]


def column(trajectory, name: str) -> np.ndarray:
    return trajectory.state[:, trajectory.state_order.index(name)]


# --------------------------------------------------------------------------- the grammar


def test_slew_and_once_parse_and_render_back():
    text = (
        "state link -135,350\n"
        "slew link torque=40\n"
        "swapcon link conB.ctab\n"
        "when link angle>75 angle<105 swapcon conA.ctab once\n"
        "sim 1\n"
        "slew link torque=off\n"
        "sim 1\n"
    )
    script = parse_script_text(text, "x.anim")
    slews = [c for c in script.commands if isinstance(c, SlewLimit)]
    assert [s.rates for s in slews] == [(("torque", 40.0),), (("torque", math.inf),)]
    again = parse_script_text(render_script(script), "x.anim")
    assert render_script(again) == render_script(script)
    assert again.commands[3].once and again.commands[3].controller == "A"


@pytest.mark.parametrize(
    ("line", "column", "expected"),
    [
        ("slew link torque=-40", 18, "expected a rate > 0 (per second) or 'off' for 'torque'"),
        ("slew link torque=0", 18, "expected a rate > 0"),
        ("slew link torque=", 18, "expected a rate > 0 (per second) or 'off' for 'torque'"),
        ("slew link torque=fast", 18, "expected a number for the slew rate of 'torque'"),
        ("slew link torque=1 torque=2", 20, "expected 'torque=' only once"),
        ("slew link", 10, "expected 'CONTROL=RATE', found end of line"),
        ("slew link 40", 11, "expected 'CONTROL=RATE', found '40'"),
        ("when link angle>75 swapcon conB.ctab twice", 38, "expected 'once' or end of line"),
    ],
)
def test_bad_slew_and_breakpoint_lines_name_line_and_column(line, column, expected):
    text = f"state link -135,350\nswapcon link conB.ctab\n{line}\nsim 1\n"
    with pytest.raises(SpecError) as raised:
        parse_script_text(text, "bad.anim")
    message = str(raised.value)
    assert message.startswith(f"bad.anim:3:{column}: "), message
    assert expected in message, message


def test_a_slew_on_a_control_the_figure_lacks_and_a_breakpoint_on_an_unknown_state_fail_at_the_word(
    tmp_path, dynamics_dir, pendulum_tables
):
    for line, column, expected in (
        ("slew link force=10", 11, "a control of the object's figure (one of torque)"),
        ("when link speed>1 swapcon conA.ctab", 11, "a state variable of the object's figure"),
    ):
        text = f"state link -135,350\nswapcon link conB.ctab\n{line}\nsim 0.1\n"
        out = tmp_path / "never.h5"
        with pytest.raises(SpecError) as raised:
            run(tmp_path, dynamics_dir, pendulum_tables, text, "bad")
        assert str(raised.value).startswith(f"{tmp_path / 'bad.anim'}:3:{column}: ")
        assert expected in str(raised.value)
        assert not out.exists() and not (tmp_path / "bad.h5").exists()


@pytest.mark.parametrize(
    ("values", "why"),
    [("-135", "the only value"), ("-135,350,0", "the first of 3 values")],
)
def test_a_state_of_the_wrong_length_says_how_many_values_it_has(
    tmp_path, dynamics_dir, pendulum_tables, values, why
):
    """It named only the first value, which is not what is wrong."""
    text = f"state link {values}\nswapcon link conB.ctab\nsim 0.1\n"
    with pytest.raises(SpecError) as raised:
        run(tmp_path, dynamics_dir, pendulum_tables, text, "bad")
    assert str(raised.value) == (
        f"{tmp_path / 'bad.anim'}:1:12: expected 2 values in the order angle,omega, "
        f"found '-135' ({why})"
    )
    assert not (tmp_path / "bad.h5").exists()


# --------------------------------------------------------------------------- slew limitation


def test_the_shipped_slew_script_never_changes_the_torque_faster_than_its_limit(
    tmp_path, dynamics_dir, pendulum_tables
):
    limited = run_shipped(tmp_path, dynamics_dir, pendulum_tables, "pendulum_slew")
    free = run_shipped(tmp_path, dynamics_dir, pendulum_tables, "pendulum")
    assert json.loads(limited.attrs["slew"]) == {"torque": SLEW}
    assert json.loads(free.attrs["slew"]) == {}
    step = np.abs(np.diff(torque(limited)))
    assert step.max() <= SLEW * DT * (1 + 1e-9)
    assert abs(torque(limited)[0]) <= SLEW * DT  # from 0 at the start
    # the limit binds: the unlimited script jumps by far more at its exchanges
    assert np.abs(np.diff(torque(free))).max() > 10 * SLEW * DT
    assert np.isclose(step.max(), SLEW * DT)


def test_a_slew_limit_at_infinity_changes_nothing(tmp_path, dynamics_dir, pendulum_tables):
    text = (SPECS / "scripts" / "pendulum.anim").read_text()
    huge = text.replace("swapcon link conB.ctab", "slew link torque=1e300\nswapcon link conB.ctab")
    assert huge != text
    free = run(tmp_path, dynamics_dir, pendulum_tables, text, "free")
    limited = run(tmp_path, dynamics_dir, pendulum_tables, huge, "huge")
    for name in ("t", "state", "control", "controller"):
        np.testing.assert_array_equal(getattr(limited, name), getattr(free, name))
    np.testing.assert_array_equal(limited.motion.endpoints, free.motion.endpoints)


def test_a_slew_limit_the_controllers_can_live_with_still_reaches_every_destination(
    tmp_path, dynamics_dir, pendulum_tables
):
    """Each controller of Figure 15 in turn, for long enough to reach its destination, with
    the shipped limit: every stretch comes within one grid step (10 deg, 50 deg/s) of its
    controller's destination, as it does without the limit."""
    lines = ["state link -135,350", f"slew link torque={SLEW:g}"]
    for name in "BADECF":
        lines += [f"swapcon link con{name}.ctab", "sim 3"]
    trajectory = run(tmp_path, dynamics_dir, pendulum_tables, "\n".join(lines) + "\n")
    assert np.abs(np.diff(torque(trajectory))).max() <= SLEW * DT * (1 + 1e-9)
    angle, omega = column(trajectory, "angle"), column(trajectory, "omega")
    for k, name in enumerate(trajectory.controllers):
        dest = read_controller_table(pendulum_tables / f"{name}.h5").dest
        stretch = trajectory.controller == k
        off_angle = (angle[stretch] - dest["angle"] + 180.0) % 360.0 - 180.0
        off = np.hypot(off_angle / 10.0, (omega[stretch] - dest["omega"]) / 50.0)
        assert off.min() < 1.0, (name, off.min())


# --------------------------------------------------------------------------- breakpoints


def test_the_catch_hands_over_to_b_the_first_time_it_passes_upright_after_the_breakpoint(
    tmp_path, dynamics_dir, pendulum_tables
):
    trajectory = run_shipped(tmp_path, dynamics_dir, pendulum_tables, "pendulum_catch")
    angle, omega = column(trajectory, "angle"), column(trajectory, "omega")
    driver = np.array(trajectory.controllers)[trajectory.controller]
    t = trajectory.t
    in_box = (angle > 75) & (angle < 105)
    armed = t >= 2.0 - 1e-9
    first = int(np.flatnonzero(in_box & armed)[0])  # the first sample in the box once armed
    assert (driver[:first] == "D").all() and (driver[first:] == "B").all()
    assert list(trajectory.attrs["switch_controllers"]) == ["D", "B"]
    assert (in_box & ~armed).any()  # D's cycle went through the box before: no handover then
    assert (~in_box[first:]).any()  # B leaves the box and keeps driving: the handover is for good
    assert abs(angle[-1] - 120.0) < 10.0 and abs(omega[-1]) < 1.0  # at rest near B's 120 deg
    (breakpoint_,) = json.loads(trajectory.attrs["breakpoints"])
    assert breakpoint_ == {
        "box": {"angle": [75.0, 105.0]},
        "controller": "B",
        "once": True,
        "line": 9,
    }


# --------------------------------------------------------------------------- domains at exchange


def test_a_controller_taking_over_outside_its_domain_is_recorded_and_warned_of(
    tmp_path, dynamics_dir, pendulum_tables, capsys
):
    """N: controller A's spec over omega within +-200 deg/s only; the script hands it the
    pendulum at 350 deg/s (outside its axes) and later, inside, hands back to B and A."""
    spec = (SPECS / "controllers" / "pendulum" / "A.ssc").read_text()
    spec = spec.replace("ssd omega -500.0 500.0 21", "ssd omega -200.0 200.0 21")
    (tmp_path / "N.ssc").write_text(spec)
    controllers = tmp_path / "controllers"
    controllers.mkdir()
    for name in "AB":
        (controllers / f"{name}.h5").write_bytes((pendulum_tables / f"{name}.h5").read_bytes())
    from mosys.dynamics.load import load_dynamics

    link1 = load_dynamics(dynamics_dir / "link1.py")
    generate_controller(parse_controller_spec(tmp_path / "N.ssc"), link1, controllers / "N.h5")
    capsys.readouterr()
    trajectory = run(
        tmp_path,
        dynamics_dir,
        controllers,
        "state link -135,350\nswapcon link conN.ctab\nsim 0.3\nswapcon link conA.ctab\nsim 0.3\n",
    )
    assert list(trajectory.attrs["domain_violation_controllers"]) == ["N"]
    assert list(trajectory.attrs["domain_violation_times"]) == [0.0]
    err = capsys.readouterr().err
    assert "s.anim:2: at t=0 s controller N takes over at (angle=-135, omega=350)" in err
    assert "beyond the table's axes: outside its domain" in err
    inside = run(
        tmp_path, dynamics_dir, controllers, "state link -135,150\nswapcon link N\nsim 0.1\n"
    )
    assert len(inside.attrs["domain_violation_times"]) == 0


def test_until_dest_stops_at_whichever_destination_is_reached(tmp_path, dynamics_dir):
    """G (two destinations: upright and hanging at rest): ``until=dest`` counts the box of
    either. At rest at either destination the sim stops at once; from 30 deg off hanging, G
    settles 4.8 deg short of hanging (its interpolated torque balances gravity there, as any
    table without exact holding torques does) and runs its full time."""
    from mosys.dynamics.load import load_dynamics

    link1 = load_dynamics(dynamics_dir / "link1.py")
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "G.ssc")
    generate_controller(spec, link1, tmp_path / "G.h5", quiet=True)
    for start, stops in (("90,0", True), ("-90,0", True), ("-60,0", False)):
        text = f"state link {start}\nswapcon link G\nsim 2 until=dest\n"
        trajectory = run(tmp_path, dynamics_dir, tmp_path, text)
        assert (trajectory.t[-1] == 0.0) == stops, start
