"""A state that blows up (issue 27): the integrating kernels stop at a NaN, inf or huge state
(``kernels.soundness.state_is_sound``), and ``mosys run`` exits 2 with the script's file and line,
the time and the state, writing nothing; never a signal or a traceback. And the interpolation
keeps its indices on the grid whatever the coordinates (NaN, inf, huge)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.animation.motor_program import BoundMotorProgram
from mosys.cli import main
from mosys.dynamics.compile import compile_figure
from mosys.errors import NonFiniteStateError
from mosys.kernels.interpolate import clamp_to_domain, interpolate_into
from mosys.kernels.soundness import STATE_LIMIT, state_is_sound
from mosys.parsing.motor import parse_motor_program_text
from mosys.ssc.controller import Controller

SPECS = Path(__file__).resolve().parents[1] / "specs"
DT = 0.001


def run_script(tmp_path: Path, text: str, dynamics: Path, controllers: Path, motor=None, dt=DT):
    """``mosys run`` on a script of ``text`` in-process: (exit code, the output path)."""
    script = tmp_path / "blow_up.anim"
    script.write_text(text)
    out = tmp_path / "blow_up.h5"
    argv = ["run", str(script), "--controllers", str(controllers)]
    argv += ["--dynamics-dir", str(dynamics), "--dt", str(dt), "-o", str(out)]
    if motor is not None:
        argv += ["--motor-dir", str(motor)]
    return main(argv), script, out


def assert_nothing_written(out: Path) -> None:
    assert list(out.parent.glob(f"*{out.name}*")) == []  # no output, no .partial either


def test_the_reproducer_exits_2_without_a_signal(tmp_path, pendulum):
    """Issue 27's script (a huge starting rate; the wrap angle it drives then indexed the table
    far off its grid: SIGSEGV) as the workflow runs it: exit 2, a message naming the line."""
    script = tmp_path / "huge.anim"
    script.write_text("state link 0,1e300\nswapcon link conA.ctab\nsim 0.01\n")
    out = tmp_path / "huge.h5"
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from mosys.cli import main; sys.exit(main())"]
        + ["run", str(script), "--controllers", str(pendulum / "controllers")]
        + ["--dynamics-dir", str(pendulum / "dynamics"), "--dt", "0.001", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    message = result.stderr.strip().splitlines()[-1]
    assert message.startswith(f"{script}:3:1: the state lies beyond ±1e+150 (SI) at t = 0 s ")
    assert "under controller A (angle=0 deg, omega=1e+300 deg/s)" in message
    assert_nothing_written(out)


@pytest.mark.parametrize(
    "edit",
    [
        {"f_0 = -GRAVITY*": "f_0 = -1e300*GRAVITY*"},
        {
            "mass_link = 1.0\n": "mass_link = 1e-300\n",
            "inertia_link = 0.08333333333333333\n": "inertia_link = 8.333333333333333e-302\n",
        },
    ],
    ids=["gravity 1e300", "mass 1e-300"],
)
def test_a_figure_that_blows_up_stops_the_sim_line(tmp_path, pendulum, edit, capsys):
    """link1 with an absurd gravity (1e300 × 9.81 m/s² in its equations) or mass (1e-300 kg, its
    inertia with it), under controller A: exit 2 at the ``sim`` line, after the first step (the
    start is sound). The figure parser caps both, and loading refuses a module whose constants
    lie outside the caps, so the equations are edited: a dynamics module can still carry
    anything."""
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    module = dynamics / "link1.py"
    compile_figure(SPECS / "figures" / "link1.fig", module)
    text = module.read_text()
    for old, new in edit.items():
        assert old in text
        text = text.replace(old, new)
    module.write_text(text)
    code, script, out = run_script(
        tmp_path,
        "state link -90,0\nswapcon link conA.ctab\nsim 0.1\n",
        dynamics,
        pendulum / "controllers",
    )
    assert code == 2
    message = capsys.readouterr().err.strip().splitlines()[-1]
    assert message.startswith(f"{script}:3:1: the state ")
    assert "at t = 0.001 s under controller A (angle=" in message
    assert_nothing_written(out)


@pytest.mark.parametrize(
    ("program", "line"),
    [
        ("phase 0.1 torque=1e200\n", 4),  # a constant torque beyond reason
        ("gains kp=1e12 kd=0\nkey 0 angle=-90\nkey 0.5 angle=0\n", 4),  # a servo unstable at dt
    ],
)
def test_a_motor_program_that_blows_up_stops_the_motor_line(
    tmp_path, pendulum, program, line, capsys
):
    motor = tmp_path / "motor"
    (motor / "link1").mkdir(parents=True)
    (motor / "link1" / "wild.mot").write_text(f"figure link1\n{program}")
    code, script, out = run_script(
        tmp_path,
        "state link -90,0\nswapcon link conA.ctab\nsim 0.01\nmotor link wild\nsim 0.1\n",
        pendulum / "dynamics",
        pendulum / "controllers",
        motor,
        dt=0.01,
    )
    assert code == 2
    message = capsys.readouterr().err.strip().splitlines()[-1]
    assert message.startswith(f"{script}:{line}:1: the state ")
    assert " under motor program wild (angle=" in message
    assert_nothing_written(out)


def test_a_motor_program_reports_when_and_where(link1):
    """``BoundMotorProgram.run``: NonFiniteStateError with the time from the run's start (the
    state after the step where it blew up) and that state."""
    program = parse_motor_program_text("figure link1\nphase 0.1 torque=1e200\n", "wild.mot")
    bound = BoundMotorProgram(program, link1)
    with pytest.raises(NonFiniteStateError) as caught:
        bound.run(np.array([-math.pi / 2, 0.0]), 0.01)
    assert caught.value.t == pytest.approx(0.01)
    assert not state_is_sound(caught.value.state)


def test_a_sound_run_takes_every_step(link1, pendulum):
    """The checks stop nothing else: controller A from a usual start runs all its steps."""
    controller = Controller.load(pendulum / "controllers" / "A.h5", link1)
    run = controller.simulate(controller.figure_state(np.array([-135.0, 350.0])), 0.5, DT)
    assert run.controls.shape[0] == 500
    assert np.isfinite(run.states).all()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 2 * STATE_LIMIT])
def test_a_controller_run_from_an_unsound_state_takes_no_step(link1, pendulum, bad):
    controller = Controller.load(pendulum / "controllers" / "A.h5", link1)
    start = np.array([0.0, bad])
    with pytest.raises(NonFiniteStateError) as caught:
        controller.simulate(start, 0.1, DT)
    assert caught.value.t == 0.0
    np.testing.assert_array_equal(caught.value.state, start)


@pytest.mark.parametrize("y", ["1e300", "-1e200"])
def test_the_car_lookahead_stops_at_a_huge_start(tmp_path, car_park, y, capsys):
    code, script, out = run_script(
        tmp_path,
        f"state car 1,{y},0,0,0\nswapcon car conpark.ctab\nsim 1\n",
        car_park / "dynamics",
        car_park / "controllers",
        dt=0.01,
    )
    assert code == 2
    message = capsys.readouterr().err.strip().splitlines()[-1]
    assert message.startswith(f"{script}:3:1: the state lies beyond ±1e+150 (SI) at t = 0 s ")
    assert "under controller park (x=1 m, y=" in message
    assert_nothing_written(out)


def test_the_car_lookahead_kernel_stops_at_a_nan_start(car, car_park):
    controller = Controller.load(car_park / "controllers" / "park.h5", car)
    start = controller.figure_state(np.array([1.0, 1.5, 0.0, 0.0, 0.0]))
    start[controller.grid.state_slot[4]] = np.nan  # the speed
    with pytest.raises(NonFiniteStateError, match="became non-finite at t = 0 s"):
        controller.simulate(start, 1.0, 0.01)


# -- interpolation on any input ----------------------------------------------------------------

WILD = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([np.nan, np.inf, -np.inf, 1e300, -1e300, 2.0**53, -(2.0**52) - 0.5]),
)


@settings(max_examples=300, deadline=None)
@given(
    coordinates=st.lists(WILD, min_size=2, max_size=2),
    wrap=st.lists(st.booleans(), min_size=2, max_size=2),
)
def test_interpolation_stays_on_the_grid_whatever_the_coordinates(coordinates, wrap):
    """A 2-D grid of 4 x 3 nodes whose table is fenced by sentinels on both sides: whatever the
    coordinates, the clamped copy is NaN only where the input is, and the interpolant is NaN or
    a convex blend of the real nodes (never a sentinel: no index off the grid)."""
    axis_min = np.array([-1.0, 0.0])
    axis_step = np.array([0.5, 2.0])
    axis_count = np.array([4, 3], dtype=np.int64)
    wrap = np.array(wrap)
    state = np.array(coordinates, dtype=np.float64)
    clamped = np.empty(2)
    inside = clamp_to_domain(axis_min, axis_step, axis_count, wrap, state, clamped)
    np.testing.assert_array_equal(np.isnan(clamped), np.isnan(state))
    if np.isnan(state).any():
        assert not inside
    fenced = np.full((3 * 12, 1), 1e9)  # sentinels before and after the 12 real nodes
    fenced[12:24, 0] = np.arange(12.0)
    table = fenced[12:24]  # a view: reading off the grid would read a sentinel
    assert table.base is fenced
    known = np.ones(12, dtype=np.bool_)
    out = np.empty(1)
    interpolate_into(axis_min, axis_step, axis_count, wrap, table, known, clamped, out)
    assert np.isnan(out[0]) or 0.0 <= out[0] <= 11.0


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf, 1e300])
def test_a_lost_wrap_coordinate_interpolates_to_nan(value):
    table = np.arange(8.0).reshape(8, 1)
    out = np.empty(1)
    interpolate_into(
        np.array([0.0]),
        np.array([1.0]),
        np.array([8], dtype=np.int64),
        np.array([True]),
        table,
        np.ones(8, dtype=np.bool_),
        np.array([value]),
        out,
    )
    assert np.isnan(out[0])


def test_luxos_contacts_blow_up_at_a_coarse_step(tmp_path, capsys):
    """Luxo's stiff ground contacts (penalty springs in its equations) under a 50 ms step: the
    hop's state blows up in the air-to-ground contact; exit 2 at the motor line, nothing
    written. (At the shipped 0.5 ms step the same script runs; the kernel family of Luxo's
    contacts is the motor program's and the controller's, covered above for link1.)"""
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    compile_figure(SPECS / "figures" / "luxo.fig", dynamics / "luxo.py")
    script = tmp_path / "hop.anim"
    script.write_text(
        "object luxo figure=luxo\nstate luxo x=-0.085 hip=0 elbow=120\nmotor luxo hop\n"
    )
    out = tmp_path / "hop.h5"
    argv = ["run", str(script), "--controllers", str(tmp_path), "--dynamics-dir", str(dynamics)]
    argv += ["--motor-dir", str(SPECS / "motor"), "-o", str(out)]
    assert main([*argv, "--dt", "0.05"]) == 2
    message = capsys.readouterr().err.strip().splitlines()[-1]
    assert message.startswith(
        f"{script}:3:1: the state became non-finite at t = 0.15 s under motor program hop (x="
    )
    assert "vx=nan m/s" in message
    assert_nothing_written(out)
    assert main([*argv, "--dt", "0.0005"]) == 0


def test_a_coordinate_at_an_axis_end_as_the_spec_writes_it_is_inside():
    """The car's speed axis, ``ssd speed -0.9 0.9 7``, ends at -0.9 + 6 x 0.3, which rounds to
    0.8999999999999999: a start at 0.9 m/s was 'beyond the table's axes: outside its domain'.
    Within a billionth of a step of an end a coordinate lies on it; beyond that it is moved and
    flagged, as before."""
    axis_min, axis_step = np.array([-0.9]), np.array([0.3])
    axis_count, wrap = np.array([7], dtype=np.int64), np.zeros(1, dtype=np.bool_)
    top = axis_min[0] + axis_step[0] * 6
    assert top < 0.9  # the rounding this is about
    clamped = np.empty(1)
    for value, inside in [(0.9, True), (-0.9 - 1e-12, True), (0.9 + 1e-6, False), (-1.0, False)]:
        state = np.array([value])
        assert clamp_to_domain(axis_min, axis_step, axis_count, wrap, state, clamped) == inside
        assert clamped[0] == (top if value > 0 else -0.9)  # moved onto the end either way
