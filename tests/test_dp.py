"""The DP of §3.5 against known answers."""

from __future__ import annotations

import numpy as np
import pytest

from mosys.io.controller_table import read_controller_table
from mosys.parsing.controller import parse_controller_text
from mosys.ssc.generate import generate_controller
from mosys.ssc.problem import build_problem
from mosys.ssc.solution import solve

DOUBLE_INTEGRATOR_SPEC = """
dyn double_integrator
ssd x -2 2 41
ssd v -2 2 41
torq force -1 1 3 0
dest x=0 v=0
"""


def minimum_time_to_the_origin(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Bang-bang minimum time to the origin of x'' = u, |u| <= 1 (the textbook solution)."""
    above = x + v * np.abs(v) / 2 > 0
    return np.where(
        above, v + 2 * np.sqrt(np.abs(x + v**2 / 2)), -v + 2 * np.sqrt(np.abs(-x + v**2 / 2))
    )


def minimum_time_to_the_line(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Minimum time to reach x = 0 at any speed: full force towards the line."""
    return np.where(x > 0, v + np.sqrt(v**2 + 2 * np.abs(x)), -v + np.sqrt(v**2 + 2 * np.abs(x)))


def generate(double_integrator, path, text):
    spec = parse_controller_text(text, "double_integrator.ssc")
    return generate_controller(spec, double_integrator, path, quiet=True)


@pytest.fixture(scope="module")
def to_the_line(double_integrator, tmp_path_factory):
    """dest names x only: every node with x = 0, whatever its speed, is a destination."""
    path = tmp_path_factory.mktemp("dp") / "line.h5"
    return generate(double_integrator, path, DOUBLE_INTEGRATOR_SPEC.replace(" v=0", ""))


@pytest.fixture(scope="module")
def to_the_origin(double_integrator, tmp_path_factory):
    path = tmp_path_factory.mktemp("dp") / "origin.h5"
    generate(double_integrator, path, DOUBLE_INTEGRATOR_SPEC)
    return read_controller_table(path)


def test_cost_to_go_matches_the_minimum_time_to_a_line(to_the_line):
    x, v = np.meshgrid(*to_the_line.axes, indexing="ij")
    exact = minimum_time_to_the_line(x, v)
    reachable = np.isfinite(to_the_line.value)
    # where full force reaches the line without leaving the domain (|v| <= 2 on the way)
    compared = reachable & (exact > 0.2) & (x != 0) & (np.abs(x) <= 1.0) & (np.abs(v) <= 1.0)
    relative = np.abs(to_the_line.value - exact)[compared] / exact[compared]
    assert np.median(relative) < 0.005
    assert relative.max() < 0.1
    # every destination node costs 0; states that must leave the domain to stop are unreachable
    assert np.all(to_the_line.value[x == 0] == 0)
    assert reachable[(np.abs(x) <= 1.0) & (np.abs(v) <= 1.0)].all()
    # only states that cannot stop inside the domain are unreachable (stopping point past ±2 m)
    cannot_stop = np.abs(x + v * np.abs(v) / 2) > 2.0
    assert (~reachable).any()
    assert np.all(cannot_stop[~reachable])


def test_single_node_destination_converges_with_the_grid(
    double_integrator, to_the_origin, tmp_path
):
    """Reaching one node exactly is the hard case for an interpolating DP (the paper's method):
    the cost-to-go overestimates the exact minimum time, and less so on a finer grid."""
    finer = generate(
        double_integrator,
        tmp_path / "finer.h5",
        DOUBLE_INTEGRATOR_SPEC.replace("41", "81") + "dt 0.0005\n",
    )
    errors = []
    for table in (to_the_origin, finer):
        x, v = np.meshgrid(*table.axes, indexing="ij")
        inner = (np.abs(x) <= 1.0) & (np.abs(v) <= 1.0) & (minimum_time_to_the_origin(x, v) > 0.5)
        exact = minimum_time_to_the_origin(x, v)[inner]
        assert np.isfinite(table.value[inner]).all()
        errors.append(np.median((table.value[inner] - exact) / exact))
    assert 0 < errors[1] < errors[0] < 0.35


def test_policy_is_bang_bang_on_the_right_side_of_the_switching_curve(to_the_origin):
    table = to_the_origin
    x, v = np.meshgrid(*table.axes, indexing="ij")
    switching = x + v * np.abs(v) / 2
    force = table.torque[..., 0]
    inner = (np.abs(x) <= 1.5) & (np.abs(v) <= 1.0) & np.isfinite(table.value)
    assert np.all(force[(switching > 0.3) & inner] == -1.0)
    assert np.all(force[(switching < -0.3) & inner] == 1.0)


def test_table_meets_the_contract(to_the_origin):
    """The table as read back from disk has the contract's layout."""
    table = to_the_origin
    assert table.state_order == ("x", "v")
    assert table.torque.shape == (41, 41, 1)
    assert table.value.shape == (41, 41)
    assert table.axis_units == ("m", "m/s")
    assert table.attrs["residual"] < table.attrs["tolerance"]
    for key in ("format_version", "spec_sha256", "generation_seconds", "iterations"):
        assert key in table.attrs


def test_unreachable_states_keep_infinite_cost(double_integrator, tmp_path):
    """With force limited to [0.5, 1] the mass always accelerates to the right: from x > 0 moving
    right it can never come back to the origin."""
    spec = parse_controller_text(
        DOUBLE_INTEGRATOR_SPEC.replace("torq force -1 1 3 0", "torq force 0.5 1 2 0"),
        "one_way.ssc",
    )
    table = generate_controller(spec, double_integrator, tmp_path / "one_way.h5", quiet=True)
    x, v = np.meshgrid(*table.axes, indexing="ij")
    assert np.all(np.isinf(table.value[(x > 0.05) & (v >= 0)]))
    assert table.attrs["unreachable_nodes"] == int(np.isinf(table.value).sum())
    assert table.attrs["unreachable_nodes"] > 0


def test_same_spec_gives_the_same_table_bit_for_bit(double_integrator, tmp_path):
    spec = parse_controller_text(DOUBLE_INTEGRATOR_SPEC, "double_integrator.ssc")
    first = generate_controller(spec, double_integrator, tmp_path / "a.h5", quiet=True)
    second = generate_controller(spec, double_integrator, tmp_path / "b.h5", quiet=True)
    assert np.array_equal(first.value, second.value)
    assert np.array_equal(first.torque, second.torque)


def test_dp_is_general_in_state_dimensions_and_controls(tmp_path):
    """A 4-D state (the double pendulum's two angles and rates) with two controls: the table has
    the contract's shape, the destination nodes cost 0 and its neighbourhood reaches them."""
    from conftest import SPECS

    from mosys.dynamics.compile import compile_figure
    from mosys.dynamics.load import load_dynamics

    compile_figure(SPECS / "figures" / "double_pendulum.fig", tmp_path / "double_pendulum.py")
    dynamics = load_dynamics(tmp_path / "double_pendulum.py")
    spec = parse_controller_text(
        "dyn double_pendulum\n"
        "ssd shoulder -180 90 4 wrap\n"
        "ssd elbow -180 90 4 wrap\n"
        "ssd shoulder_rate -200 200 5\n"
        "ssd elbow_rate -200 200 5\n"
        "torq shoulder_torque -40 40 3 0.01\n"
        "torq elbow_torque -20 20 3 0.01\n"
        "dest shoulder=-90 elbow=0 shoulder_rate=0 elbow_rate=0\n"
        "dt 0.002\n"
        "maxiter 300\n",
        "hang.ssc",
    )
    table = generate_controller(spec, dynamics, tmp_path / "hang.h5", quiet=True)
    assert table.state_order == ("shoulder", "elbow", "shoulder_rate", "elbow_rate")
    assert table.torque.shape == (4, 4, 5, 5, 2)
    assert table.value[1, 2, 2, 2] == 0.0  # shoulder -90, elbow 0, at rest
    assert np.isfinite(table.value).sum() > table.value.size // 2
    assert np.all(np.abs(table.torque[..., 0]) <= 40) and np.all(np.abs(table.torque[..., 1]) <= 20)


def solve_double_integrator(double_integrator, quiet=True, warm=None):
    """The double integrator's DP to the origin (``ssc.solution.solve``): (spec, solution)."""
    spec = parse_controller_text(DOUBLE_INTEGRATOR_SPEC, "double_integrator.ssc")
    problem = build_problem(spec, double_integrator)
    return spec, solve(
        problem,
        double_integrator,
        spec.tolerance,
        spec.max_iterations,
        spec.dt,
        quiet=quiet,
        warm=warm,
    )


def test_sweeps_from_a_warm_start_above_the_cost_to_go_end_at_the_cold_values(double_integrator):
    """Values 1 s above the cost-to-go everywhere: the sweeps end at the nodes the DP from the
    bound reaches, within its tolerance of its values, with the same controls nearly
    everywhere; started from the DP's own values, one Bellman sweep finds nothing to lower."""
    spec, cold = solve_double_integrator(double_integrator)
    _, warm = solve_double_integrator(double_integrator, warm=cold.value + 1.0)
    finite = np.isfinite(cold.value)
    assert np.array_equal(np.isfinite(warm.value), finite)
    assert np.max(np.abs(warm.value[finite] - cold.value[finite])) <= 2 * spec.tolerance
    assert np.mean(warm.best_control[finite] == cold.best_control[finite]) > 0.95
    _, settled = solve_double_integrator(double_integrator, warm=cold.value)
    assert settled.iterations == 1 < cold.iterations  # started where the DP ended


def test_a_warm_start_below_the_cost_to_go_is_caught_and_the_sweeps_start_again(
    double_integrator, capsys
):
    """Values at half the cost-to-go: some node is left below what its best control gives
    (``dp.best_controls``'s excess), so the sweeps run again from the bound: the DP's own values,
    bit for bit, and a line on stderr saying so."""
    _, cold = solve_double_integrator(double_integrator)
    _, again = solve_double_integrator(double_integrator, quiet=False, warm=0.5 * cold.value)
    np.testing.assert_array_equal(again.value, cold.value)
    np.testing.assert_array_equal(again.best_control, cold.best_control)
    assert "the warm start lay below the cost-to-go (by up to " in capsys.readouterr().err


def test_value_iterations_eta_is_an_upper_bound(capsys):
    """Value iteration stops when it converges, well short of its cap: its ETA, the cap at the
    rate so far, is said to be at most that (a 16 s DP printed 'ETA 2883.3 s')."""
    from mosys.io.progress import Progress

    capped = Progress("value iteration", 3000, "sweeps", interval=0.0, at_most=True)
    capped.update(8, "largest change 3.2 s")
    line = capsys.readouterr().err
    assert line.startswith("value iteration: 8/3000 sweeps, 3000 at most (")
    assert ", ETA at most " in line and line.rstrip().endswith(" s), largest change 3.2 s")
    Progress("starts", 100, "runs", interval=0.0).update(8)
    assert "ETA at most" not in capsys.readouterr().err


def test_a_progress_lines_note_follows_a_comma_or_stands_in_brackets(capsys):
    """A search's last line ran two fields together: 'done, 30 generations in 0.24 s best
    fitness 6.052'."""
    from mosys.io.progress import Progress

    Progress("search", 30, "generations").finish("best fitness 6.052")
    assert capsys.readouterr().err.endswith(" s, best fitness 6.052\n")
    Progress("starts", 3, "runs").finish("(1 start that cannot park not run)")
    assert capsys.readouterr().err.endswith(" s (1 start that cannot park not run)\n")
    Progress("exits", 3, "segments").finish()
    assert capsys.readouterr().err.endswith(" s\n")
    Progress("first population", 1, "rounds", interval=0.0).update(1)  # all done: finish says
    assert capsys.readouterr().err == ""
