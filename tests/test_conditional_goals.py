"""Conditional goals (the 1990 paper's §3: "given more than one destination state, perform the
easiest motion"): specs with several ``dest`` lines, the DP towards the union of their nodes,
the table's ``destinations``/``destination_index``, and the runtime and portrait that use them.

The known answer: a uniform rod pinned at one end with gravity 0 is a double integrator in its
angle. Mass 3 kg and length 1 m give an inertia of m l²/3 = 1 kg m² about the pin, so the
angular acceleration in rad/s² is the torque in N·m: with |torque| <= 1 and K = 0 (pure time),
the minimum time from (x, v) to rest at a is the textbook bang-bang answer, with
U = 1 rad/s² = 57.3 deg/s² (``minimum_time``).
"""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from mosys.dynamics.compile import compile_figure
from mosys.dynamics.load import load_dynamics
from mosys.io.controller_table import read_controller_table
from mosys.kernels.dp_destinations import destination_indices
from mosys.parsing.controller import parse_controller_spec, parse_controller_text
from mosys.parsing.tokens import SpecError
from mosys.ssc.controller import Controller
from mosys.ssc.generate import generate_controller

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"

FREE_ROD = """\
gravity 0
rod link length=1 mass=3       # uniform: m l²/3 = 1 kg m² about the pin
pin link at=0,0 angle=angle rate=omega actuator=torque
"""
# Two goals at rest, +45 and -45 degrees, on a non-wrapping angle axis; steps 1.5 deg, 2.5 deg/s.
TWO_GOALS = """\
dyn free_rod
ssd angle -90 90 121
ssd omega -90 90 73
torq torque -1 1 3 0
dest angle=45 omega=0
dest angle=-45 omega=0
hold
dt 0.01
"""
GOALS = (45.0, -45.0)  # deg, in dest line order
U = np.degrees(1.0)  # deg/s²: the largest angular acceleration
ANGLE_MAX, RATE_MAX = 90.0, 90.0
ANGLE_STEP, RATE_STEP = 1.5, 2.5


def minimum_time(x: np.ndarray, v: np.ndarray, goal: float) -> np.ndarray:
    """Minimum time (s) from angle x (deg) and rate v (deg/s) to rest at ``goal`` (deg) with
    |acceleration| <= U: full acceleration one way, then full the other (bang-bang)."""
    y = x - goal
    above = y + v * np.abs(v) / (2 * U) > 0  # past the switching curve: brake first
    return np.where(
        above,
        (v + 2 * np.sqrt(np.abs(U * y + v**2 / 2))) / U,
        (-v + 2 * np.sqrt(np.abs(-U * y + v**2 / 2))) / U,
    )


def stays_inside(x: np.ndarray, v: np.ndarray, goal: float) -> np.ndarray:
    """Whether the bang-bang path from (x, v) to ``goal`` keeps at least one grid step inside
    the table's domain: its fastest speed (at the start or at the switch) and its extreme
    angles (the start, and the turning point where it brakes to a stop) — the DP cannot follow
    a path that leaves the domain, and is not asked to."""
    y = x - goal
    sign = np.where(y + v * np.abs(v) / (2 * U) > 0, 1.0, -1.0)
    peak = np.maximum(np.abs(v), np.sqrt(np.abs(sign * U * y + v**2 / 2)))
    stop = x + v * np.abs(v) / (2 * U)
    return (
        (peak <= RATE_MAX - RATE_STEP)
        & (np.abs(stop) <= ANGLE_MAX - ANGLE_STEP)
        & (np.abs(x) <= ANGLE_MAX - ANGLE_STEP)
    )


@pytest.fixture(scope="module")
def free_rod(tmp_path_factory):
    directory = tmp_path_factory.mktemp("dynamics")
    (directory / "free_rod.fig").write_text(FREE_ROD)
    compile_figure(directory / "free_rod.fig", directory / "free_rod.py")
    return load_dynamics(directory / "free_rod.py")


@pytest.fixture(scope="module")
def two_goals(free_rod, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("controllers") / "two.h5"
    spec = parse_controller_text(TWO_GOALS, "two.ssc")
    generate_controller(spec, free_rod, path, quiet=True)
    return path


# --------------------------------------------------------------------------- 1. known answer


def analytic_answer(two_goals):
    """The table, and at each node: the two goals' exact minimum times (2, n, m), the index of
    the quicker, the shorter and longer time, and whether the quicker path stays inside the
    domain."""
    table = read_controller_table(two_goals)
    x, v = np.meshgrid(*table.axes, indexing="ij")
    times = np.stack([minimum_time(x, v, goal) for goal in GOALS])
    quicker = np.argmin(times, axis=0)
    fair = np.where(quicker == 0, stays_inside(x, v, GOALS[0]), stays_inside(x, v, GOALS[1]))
    return table, times, quicker, times.min(axis=0), times.max(axis=0), fair


def test_each_node_heads_for_the_analytically_quicker_goal(two_goals):
    """Where the two bang-bang times differ by more than 15 % of the shorter, destination_index
    names the quicker goal. The DP reaches a single node with an interpolation error of the
    order of 25 % (median; tests/test_dp.py), but the problem is mirror-symmetric, so the two
    goals' errors largely cancel in the comparison: measured, no node disagrees above a 10 %
    difference and about a dozen (on the basin border) between 5 and 10 %. Nodes whose quicker
    path would leave the domain are left out (the DP must take a slower way there)."""
    table, times, quicker, shorter, longer, fair = analytic_answer(two_goals)
    compared = fair & np.isfinite(table.value) & (longer - shorter > 0.15 * shorter)
    assert compared.sum() > 5000  # most of the 121 x 73 nodes
    np.testing.assert_array_equal(table.destination_index[compared], quicker[compared])
    # both basins are there, each about half the nodes (the problem is symmetric)
    counts = np.bincount(table.destination_index[table.destination_index >= 0])
    assert counts.size == 2 and abs(int(counts[0]) - int(counts[1])) <= 2


def test_value_is_the_quicker_goals_time(two_goals):
    """The cost-to-go is the time to the nearer goal, within the interpolating DP's error: never
    more than 2 % below the exact minimum, over it by < 35 % (median) and < 50 % (95th
    percentile) where the exact time is over 0.5 s; and where one goal takes at least 1.5 times
    the other, below the slower goal's exact time (a DP towards one goal alone could not)."""
    table, times, quicker, shorter, longer, fair = analytic_answer(two_goals)
    fair &= np.isfinite(table.value)
    inner = fair & (shorter > 0.5)
    relative = (table.value[inner] - shorter[inner]) / shorter[inner]
    assert relative.min() > -0.02
    assert 0.0 < np.median(relative) < 0.35
    assert np.percentile(relative, 95) < 0.5
    lopsided = fair & (longer > 1.5 * shorter)
    assert lopsided.sum() > 1000
    assert np.all(table.value[lopsided] < longer[lopsided])
    # every destination node costs 0 and names its own line
    for k, goal in enumerate(GOALS):
        node = (np.argmin(np.abs(table.axes[0] - goal)), np.argmin(np.abs(table.axes[1])))
        assert table.value[node] == 0.0
        assert table.destination_index[node] == k


# --------------------------------------------------------------------------- 2. closed loop

STARTS = [  # (angle deg, omega deg/s), the dest line its optimal path ends at
    ((-10.0, 60.0), 0),  # left of centre but swinging right fast: +45 is quicker
    ((10.0, -60.0), 1),
    ((-30.0, 0.0), 1),
    ((30.0, 0.0), 0),
    ((80.0, -20.0), 0),
    ((-60.0, 40.0), 1),
]


@pytest.mark.parametrize(("start", "expected"), STARTS)
def test_a_start_in_each_basin_comes_to_rest_at_its_destination(
    free_rod, two_goals, start, expected
):
    controller = Controller.load(two_goals, free_rod)
    table = controller.table
    node = tuple(
        int(np.argmin(np.abs(axis - value))) for axis, value in zip(table.axes, start, strict=True)
    )
    assert table.destination_index[node] == expected
    assert controller.heading_for(np.array(start)) == expected
    run = controller.simulate(controller.figure_state(np.array(start)), 5.0, 0.001)
    end = controller.controller_states(run.states)[-1]
    assert abs(end[0] - GOALS[expected]) < 0.5 * ANGLE_STEP
    assert abs(end[1]) < 0.5 * RATE_STEP
    # the arrival box is the destination the state heads for, and the run ends in it
    box = controller.arrival_box(run.states[0])
    assert box["angle"][0] < GOALS[expected] < box["angle"][1]
    boxes = controller.arrival_boxes()
    assert [
        low < goal < high
        for (low, high), goal in zip((b["angle"] for b in boxes), GOALS, strict=True)
    ] == [True, True]
    low, high = box["angle"]
    assert low <= end[0] <= high


def test_one_arrival_box_needs_the_state_when_there_are_several(free_rod, two_goals):
    controller = Controller.load(two_goals, free_rod)
    assert controller.destinations == (
        {"angle": 45.0, "omega": 0.0},
        {"angle": -45.0, "omega": 0.0},
    )
    with pytest.raises(ValueError, match="has 2 destinations"):
        controller.arrival_box()


# --------------------------------------------------------------------------- 3. parse errors


def test_two_identical_destinations_are_an_error_at_the_second(tmp_path):
    path = tmp_path / "twice.ssc"
    path.write_text(TWO_GOALS.replace("dest angle=-45 omega=0", "dest omega=0 angle=45"))
    with pytest.raises(SpecError) as error:
        parse_controller_spec(path)
    assert str(error.value) == (
        f"{path}:6:1: expected a destination different from line 5's, found 'dest'"
    )


def test_lookahead_takes_one_destination(tmp_path):
    path = tmp_path / "lookahead.ssc"
    path.write_text(TWO_GOALS + "policy lookahead angle=1\n")
    with pytest.raises(SpecError) as error:
        parse_controller_spec(path)
    assert str(error.value) == (
        f"{path}:9:8: expected 'interpolate' with several dest lines (lines 5, 6): lookahead "
        "brakes to rest at one destination, found 'lookahead'"
    )


def test_hold_needs_every_destination_at_rest(free_rod, tmp_path):
    text = TWO_GOALS.replace("dest angle=-45 omega=0", "dest angle=-45")
    spec = parse_controller_text(text, "moving.ssc")
    with pytest.raises(SpecError) as error:
        generate_controller(spec, free_rod, tmp_path / "moving.h5", quiet=True)
    assert str(error.value) == (
        "moving.ssc:7:1: expected a 'dest' that names the rate 'omega' (= 0) for 'hold' "
        "(line 6 does not), found 'hold'"
    )
    assert not (tmp_path / "moving.h5").exists()


# --------------------------------------------------------------------------- 4. the contract


def test_table_records_every_destination_and_each_nodes_choice(two_goals):
    with h5py.File(two_goals, "r") as h5:
        assert json.loads(h5.attrs["destinations"]) == [
            {"angle": 45.0, "omega": 0.0},
            {"angle": -45.0, "omega": 0.0},
        ]
        assert json.loads(h5.attrs["dest"]) == {"angle": 45.0, "omega": 0.0}
        index = h5["destination_index"]
        assert index.dtype == np.int64
        assert index.shape == h5["value"].shape
        value = h5["value"][()]
        index = index[()]
    assert set(np.unique(index)) <= {-1, 0, 1}
    np.testing.assert_array_equal(index == -1, np.isinf(value))
    assert (index == -1).any()  # states that cannot stop inside the domain
    table = read_controller_table(two_goals)
    assert table.destinations == ({"angle": 45.0, "omega": 0.0}, {"angle": -45.0, "omega": 0.0})
    assert "destinations" not in table.attrs
    np.testing.assert_array_equal(table.destination_index, index)


def test_a_single_destination_table_has_neither(free_rod, tmp_path):
    spec = parse_controller_text(TWO_GOALS.replace("dest angle=-45 omega=0\n", ""), "one.ssc")
    generate_controller(spec, free_rod, tmp_path / "one.h5", quiet=True)
    with h5py.File(tmp_path / "one.h5", "r") as h5:
        assert "destinations" not in h5.attrs
        assert "destination_index" not in h5
    table = read_controller_table(tmp_path / "one.h5")
    assert table.destinations is None and table.destination_index is None
    assert table.all_destinations == ({"angle": 45.0, "omega": 0.0},)


# --------------------------------------------------------------------------- the kernel


def test_destination_shares_solve_loops_of_exits():
    """Six nodes in a row: 0 and 4 are destinations (lines 0 and 1), 5 unreachable; the best
    exits of 1, 2 and 3 split between their neighbours, 1 <-> 2 <-> 3 looping: shares
    a = share of line 0 solve a1 = (a2 + 1)/2, a2 = (a1 + a3)/2, a3 = a2/4."""
    corners = np.array([[[0, 0]], [[2, 0]], [[1, 3]], [[2, 4]], [[4, 4]], [[5, 5]]], np.int32)
    corners -= np.arange(6, dtype=np.int32)[:, None, None]  # offsets from each node
    weights = np.array(
        [[[0, 0]], [[0.5, 0.5]], [[0.5, 0.5]], [[0.25, 0.75]], [[0, 0]], [[0, 0]]], np.float32
    )
    row_of = np.arange(6, dtype=np.int64)
    best_control = np.zeros(6, np.int64)
    value = np.array([0.0, 2.0, 3.0, 2.0, 0.0, np.inf])
    label = np.array([0, -1, -1, -1, 1, -1], np.int64)
    share = np.empty((6, 2))
    out = np.empty(6, np.int64)
    sweeps = destination_indices(
        corners,
        weights,
        np.zeros((6, 1), np.bool_),
        row_of,
        row_of,
        best_control,
        np.isfinite(value),
        0,
        value,
        label,
        np.array([6, 1], np.int64),
        1e-12,
        1000,
        np.empty(6, np.int64),
        share,
        out,
    )
    assert 1 < sweeps < 1000
    np.testing.assert_allclose(share[:, 0], [1.0, 0.7, 0.4, 0.1, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(share[1:4].sum(axis=1), 1.0, atol=1e-9)
    np.testing.assert_array_equal(out, [0, 0, 1, 1, 1, -1])


# --------------------------------------------------------------------------- G and its portrait


@pytest.fixture(scope="module")
def pendulum_g(link1, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("controllers") / "G.h5"
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "G.ssc")
    generate_controller(spec, link1, path, quiet=True)
    return path


def test_pendulum_g_rests_upright_or_hanging(pendulum_g, link1):
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "G.ssc")
    a = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")

    def grid(s):
        return [(d.name, d.minimum, d.maximum, d.samples, d.wrap) for d in s.state] + [
            (c.name, c.minimum, c.maximum, c.samples, c.effort_weight) for c in s.controls
        ]

    assert grid(spec) == grid(a)  # A's grid and torques
    assert spec.all_destination_values() == [
        {"angle": 90.0, "omega": 0.0},
        {"angle": -90.0, "omega": 0.0},
    ]
    controller = Controller.load(pendulum_g, link1)
    index = controller.table.destination_index
    assert (index >= 0).all()  # every state of A's domain reaches one or the other
    angle, rate = controller.table.axes
    at_rest = index[:, int(np.argmin(np.abs(rate)))]

    def heads(a: float) -> int:
        return int(at_rest[int(np.argmin(np.abs(angle - a)))])

    # at rest, the pendulum just off hanging goes down, just off upright goes up
    assert [heads(a) for a in (-100.0, -80.0, 80.0, 100.0)] == [1, 1, 0, 0]


def test_portrait_tints_each_basin(pendulum_g, link1):
    from matplotlib.collections import QuadMesh

    from mosys.plots.controller import portrait_figure

    figure = portrait_figure(pendulum_g, link1)
    (ax,) = figure.axes
    assert ax.get_title() == (
        "Controller G: 2 destinations, the cheapest from each state\n"
        "closed-loop paths, 3 s from each of 8 start states"
    )
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    index = read_controller_table(pendulum_g).destination_index
    shown = np.asarray(mesh.get_array()).reshape(index.shape[1], index.shape[0] + 1)
    np.testing.assert_array_equal(shown[:, :-1], index.T)  # one cell per node
    np.testing.assert_array_equal(shown[:, -1], index[0])  # -180 again at +180: cylindrical
    labels = [text.get_text() for text in figure.legends[0].get_texts()]
    assert labels == [
        "start state (one colour per path)",
        "destinations",
        "basin → θ = 90 deg, ω = 0 deg/s",
        "basin → θ = -90 deg, ω = 0 deg/s",
    ]
    circles = [line for line in ax.lines if line.get_marker() == "o" and line.get_zorder() == 6]
    assert sorted((line.get_xdata()[0], line.get_ydata()[0]) for line in circles) == [
        (-90.0, 0.0),
        (90.0, 0.0),
    ]


def test_torque_table_marks_every_destination(pendulum_g):
    """It marked only the first (90 deg), and its title named that one alone."""
    from mosys.plots.controller import torque_figure

    figure = torque_figure(pendulum_g)
    ax = figure.axes[0]
    assert ax.get_title() == (
        "Controller G: torque table, 36 × 21 nodes\n2 destinations, the cheapest from each state"
    )
    circles = [line for line in ax.lines if line.get_marker() == "o" and line.get_zorder() == 6]
    assert sorted((line.get_xdata()[0], line.get_ydata()[0]) for line in circles) == [
        (-90.0, 0.0),
        (90.0, 0.0),
    ]
    assert [text.get_text() for text in figure.legends[0].get_texts()][-1] == "destinations"


def test_a_single_destination_portrait_has_no_basins(link1, tmp_path):
    from matplotlib.collections import QuadMesh

    from mosys.plots.controller import portrait_figure

    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")
    generate_controller(spec, link1, tmp_path / "A.h5", quiet=True)
    figure = portrait_figure(tmp_path / "A.h5", link1)
    assert not [c for c in figure.axes[0].collections if isinstance(c, QuadMesh)]
    labels = [text.get_text() for text in figure.legends[0].get_texts()]
    assert labels == ["start state (one colour per path)", "destination"]


def test_the_pendulum_table_lists_both_destinations_and_counts_either(pendulum_g, link1):
    from mosys.paper_tables.pendulum import pendulum_rows

    (row,) = pendulum_rows([str(pendulum_g)], link1.__file__, "test").to_dict("records")
    assert (row["dest_angle_deg"], row["dest_omega_deg_s"]) == ("90 / -90", "0 / 0")
    assert row["reach_share"] == 1.0  # each start arrives at one destination or the other
