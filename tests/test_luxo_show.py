"""Luxo's show end to end: the landing controller built from the grounded lamp with
the same DP engine, the motor programs, and the scripted sequence; the targets are checked on
the trajectory file, as a user would."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from mosys.animation.motion_measures import SETTLE_WITHIN, measure, motions
from mosys.animation.motor_program import load_motor_program
from mosys.animation.trajectory_file import run_animation_script
from mosys.dynamics.compile import compile_figure
from mosys.dynamics.load import load_dynamics
from mosys.io.controller_table import read_controller_table
from mosys.io.trajectory import read_trajectory
from mosys.parsing.controller import parse_controller_spec
from mosys.ssc.generate import generate_controller

SPECS = Path(__file__).resolve().parents[1] / "specs"
DT = 0.0005  # s: config/config.yaml's luxo dt
PENETRATION_TOLERANCE = 0.01  # m: the deepest a contact point may go on landing (README)
SHOW = ("hop", "hop", "hop", "long_jump", "backflip", "double_backflip", "backflip_down_step")

pytestmark = pytest.mark.slow  # every test needs the landing controller built


@pytest.fixture(scope="module")
def luxo_results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dynamics and the landing controller, built as the pipeline builds them."""
    root = tmp_path_factory.mktemp("luxo")
    for figure in ("luxo", "luxo_grounded"):
        compile_figure(SPECS / "figures" / f"{figure}.fig", root / "dynamics" / f"{figure}.py")
    spec = parse_controller_spec(SPECS / "controllers" / "luxo" / "land.ssc")
    grounded = load_dynamics(root / "dynamics" / "luxo_grounded.py")
    generate_controller(spec, grounded, root / "controllers" / "land.h5", quiet=True)
    return root


def run(luxo_results: Path, script: Path, name: str):
    out = luxo_results / f"{name}.h5"
    run_animation_script(
        script, luxo_results / "controllers", luxo_results / "dynamics", out, DT, SPECS / "motor"
    )
    return read_trajectory(out)


@pytest.fixture(scope="module")
def show(luxo_results: Path):
    trajectory = run(luxo_results, SPECS / "scripts" / "luxo_show.anim", "show")
    standing = read_controller_table(luxo_results / "controllers" / "land.h5").dest
    return trajectory, {
        m.name + str(i): measure(trajectory, m, standing) for i, m in enumerate(motions(trajectory))
    }


def test_landing_controller_holds_the_standing_pose(luxo_results: Path) -> None:
    """'hold': the destination node stores the torques that balance gravity there."""
    table = read_controller_table(luxo_results / "controllers" / "land.h5")
    grounded = load_dynamics(luxo_results / "dynamics" / "luxo_grounded.py")
    index = tuple(
        int(np.argmin(np.abs(axis - table.dest[name])))
        for axis, name in zip(table.axes, table.state_order, strict=True)
    )
    q = np.radians([table.dest["hip"], table.dest["elbow"]])
    np.testing.assert_allclose(table.torque[index], -grounded.forcing(q, np.zeros(2), np.zeros(2)))
    assert abs(table.torque[index][1]) > 0.1  # the head's weight needs holding


def test_show_runs_the_motions_in_order(show) -> None:
    trajectory, _ = show
    assert [m.name for m in motions(trajectory)] == list(SHOW)
    assert trajectory.motion is not None and trajectory.contacts is not None
    assert trajectory.state_order[:5] == ("x", "y", "base", "hip", "elbow")


def test_every_motion_lands_and_settles_within_two_seconds(show) -> None:
    _, measured = show
    for name, m in measured.items():
        assert m.landed, (name, m)
        assert m.airborne_s > 0.05, (name, m)  # it really left the ground
        assert m.settle_s <= SETTLE_WITHIN, (name, m)
        assert m.max_penetration_m < PENETRATION_TOLERANCE, (name, m)
        assert m.rod_in_ground_m < PENETRATION_TOLERANCE, (name, m)  # no rod through it
        assert not m.limb_touched, (name, m)  # it lands on its base, not on its head


def test_rotations_of_the_flips(show) -> None:
    _, measured = show
    turns = {name.rstrip("0123456789"): m.rotation_deg for name, m in measured.items()}
    assert abs(turns["hop"]) < 30 and abs(turns["long_jump"]) < 30
    assert abs(turns["backflip"] + 360) <= 30
    assert abs(turns["double_backflip"] + 720) <= 30
    assert abs(turns["backflip_down_step"] + 360) <= 30


def test_long_jump_clears_the_ditch_and_the_step_variant_ends_lower(show) -> None:
    trajectory, measured = show
    terrain = np.array(trajectory.motion.terrain)
    ditch_bottom = terrain[:, 1].min()
    jump = measured["long_jump3"]
    assert jump.start_ground_m == 0.0 and jump.end_ground_m == 0.0
    assert jump.lowest_ground_touched_m == 0.0  # nothing touched the ditch or the ledge
    assert ditch_bottom < -0.2
    step = measured["backflip_down_step6"]
    assert step.end_ground_m < step.start_ground_m - 0.1  # on the ledge below the step


def test_motions_reuse_in_a_new_script_without_a_new_controller(luxo_results: Path, tmp_path):
    """A user's own order of the same motions, from a standing start elsewhere on the floor."""
    script = tmp_path / "my_show.anim"
    script.write_text(
        "object luxo figure=luxo\n"
        "state luxo x=1 hip=0 elbow=120\n"
        "swapcon luxo conland.ctab\n"
        "motor luxo backflip\n"
        "sim 3 until=dest\n"
        "motor luxo hop\n"
        "sim 3 until=dest\n"
    )
    trajectory = run(luxo_results, script, "my_show")
    standing = read_controller_table(luxo_results / "controllers" / "land.h5").dest
    measured = [measure(trajectory, m, standing) for m in motions(trajectory)]
    assert [m.motion for m in measured] == ["backflip", "hop"]
    assert all(m.landed for m in measured)
    assert math.isclose(measured[0].rotation_deg, -360, abs_tol=30)


def test_a_motion_that_never_leaves_the_ground_has_no_flight(luxo_results: Path, tmp_path):
    """A keyframed nod from the script's start state, the base resting on the floor with no
    contact force yet: that first sample counted as a flight (airborne 0.0005 s, touch-down at
    0.0005 s, landed), although the lamp never left the ground."""
    motor = tmp_path / "motor" / "luxo"
    motor.mkdir(parents=True)
    (motor / "nod.mot").write_text(
        "figure luxo\nlimit hip_torque=5 elbow_torque=5\ngains kp=6 kd=0.25\n"
        "key 0.0 hip=0 elbow=120\nkey 0.6 hip=12 elbow=105\nkey 1.2 hip=-10 elbow=140\n"
        "key 1.8 hip=0 elbow=120\n"
    )
    script = tmp_path / "nod.anim"
    script.write_text(
        "object luxo figure=luxo\nstate luxo x=1 hip=0 elbow=120\nswapcon luxo conland.ctab\n"
        "motor luxo nod\nsim 3 until=dest\n"
    )
    out = tmp_path / "nod.h5"
    run_animation_script(
        script, luxo_results / "controllers", luxo_results / "dynamics", out, DT, motor.parent
    )
    trajectory = read_trajectory(out)
    standing = read_controller_table(luxo_results / "controllers" / "land.h5").dest
    (nod,) = [measure(trajectory, m, standing) for m in motions(trajectory)]
    assert math.isnan(nod.airborne_s) and math.isnan(nod.touchdown_s) and not nod.landed
    assert nod.max_penetration_m < PENETRATION_TOLERANCE


def test_the_tuning_tool_writes_a_program_that_runs(
    luxo_results: Path, tmp_path, capsys, monkeypatch
):
    """tools/tune_luxo_motion.py (how the programs were made), at a tiny budget: the program it
    writes parses, binds to Luxo, and its parameters read back as written."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "tools" / "tune_luxo_motion.py"
    spec = importlib.util.spec_from_file_location("tune_luxo_motion", path)
    tool = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, tool)  # its dataclass looks itself up there
    spec.loader.exec_module(tool)
    out = tmp_path / "hop.mot"
    argv = ["hop", "--distance=-0.2", "--samples", "4", "--local", "2", "--write", str(out)]
    argv += ["--dynamics", str(luxo_results / "dynamics" / "luxo.py")]
    argv += ["--controller", str(luxo_results / "controllers" / "land.h5")]
    assert tool.main(argv) == 0
    assert "cost " in capsys.readouterr().out
    parameters = tool.program_parameters(str(out))
    assert np.all(parameters >= tool.LOW - 1e-3) and np.all(parameters <= tool.HIGH + 1e-3)
    lamp = load_dynamics(luxo_results / "dynamics" / "luxo.py")
    program = load_motor_program(out, "luxo", lamp)
    assert program.duration() == pytest.approx(parameters[[0, 3, 7]].sum(), abs=1e-3)
