"""The lookahead runtime of a car's table (``policy lookahead``): it never drives into an
obstacle, it holds each chosen sample to the DP cell's exit, and it brakes to rest and holds in
the arrival box."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_car import SMALL

from mosys.animation.runner import run_row_bytes
from mosys.cli import main
from mosys.errors import InputError
from mosys.io.car_scene import controller_table_scene
from mosys.io.controller_table import write_controller_table
from mosys.io.start_grid import OUTSIDE_DOMAIN, read_start_grid, write_start_grid
from mosys.kernels.geometry import (
    first_colliding_sample,
    grown_polygon,
    pack_polygons,
    point_in_polygon,
)
from mosys.kernels.lookahead import CLEARANCE, Scene, _swept_free
from mosys.limits import LimitError
from mosys.parsing.controller import parse_controller_text
from mosys.parsing.tokens import SpecError
from mosys.ssc.controller import Controller
from mosys.ssc.generate import generate_controller
from mosys.ssc.parking import NOT_FREE, evaluate_starts
from mosys.ssc.problem import build_problem

ARRIVAL = "policy lookahead x=0.1 y=0.1 heading=4\n"
DT = 0.01
CAR_BODY = np.array([[0.8, -0.85], [0.8, 0.85], [-3.2, 0.85], [-3.2, -0.85]])  # the car's, m
POSE_SLOTS = np.arange(3, dtype=np.int64)  # x, y, heading in a pose (3,)
NO_DOMAIN = np.zeros((0, 2))


@pytest.fixture(scope="module")
def small(car, tmp_path_factory):
    """SMALL (curb, a car in front, a coarse grid) generated with the lookahead policy."""
    path = tmp_path_factory.mktemp("lookahead") / "small.h5"
    spec = parse_controller_text(SMALL + ARRIVAL, "small.ssc")
    table = generate_controller(spec, car, path, quiet=True)
    return Controller("small", table, car)


def poses(controller, states):
    """(N, 3) x, y (m), heading (rad) of model states (N, S)."""
    names = controller.dynamics.STATE_NAMES
    return np.ascontiguousarray(states[:, [names.index(n) for n in ("x", "y", "heading")]])


def test_the_table_records_the_policy_and_its_arrival_box(small):
    assert small.table.attrs["policy"] == "lookahead"
    assert json.loads(small.table.attrs["arrival_tolerance"]) == {
        "x": 0.1,
        "y": 0.1,
        "heading": 4.0,
    }
    policy = small.lookahead
    assert policy is not None
    assert policy.control_samples.shape == (9, 2)  # torq 3 x 3 samples
    # the brake is the smaller wheel_accel limit, rad/s²
    assert policy.brake == pytest.approx(np.radians(200.0))
    heading = small.grid.names.index("heading")
    assert policy.arrival_box[1, heading] == pytest.approx(np.radians(4.0))
    assert np.isinf(policy.arrival_box[1, small.grid.names.index("steer")])


@pytest.mark.parametrize("seed", range(12))
def test_it_never_touches_an_obstacle_or_leaves_the_domain(small, seed):
    """Random free starts, rolling (odd seeds; anywhere in the domain) or at rest within the
    table's axes (even seeds): every step of the run is free, because a sample is taken only
    if the vehicle can brake to rest from its segment's exit; from rest within the axes, the
    run stays within them too."""
    rng = np.random.default_rng(seed)
    obstacles = small.lookahead
    body = controller_table_scene(small.table).body_outline  # the real one, not the grown
    while True:
        start = np.array(
            [
                rng.uniform(-2.5, 2.5) if seed % 2 else rng.uniform(-2, 2),
                rng.uniform(1.0, 2.4) if seed % 2 else rng.uniform(1.0, 2.0),
                rng.uniform(-20, 20),
                rng.uniform(-30, 30),
                rng.uniform(-0.8, 0.8) if seed % 2 else 0.0,
            ]
        )
        state = small.figure_state(start)
        collision, _ = first_colliding_sample(
            poses(small, state[None, :]),
            body,
            obstacles.obstacle_vertices,
            obstacles.obstacle_start,
        )
        if collision < 0 and _in_domain(state, small):
            break
    run = small.simulate(state, 8.0, DT)
    sample, _ = first_colliding_sample(
        poses(small, run.states),
        body,
        obstacles.obstacle_vertices,
        obstacles.obstacle_start,
    )
    assert sample == -1
    assert all(_in_domain(s, small) for s in run.states)
    grid = small.grid
    lower, upper = grid.axis_min, grid.axis_min + grid.axis_step * (grid.axis_count - 1)
    si = run.states[:, grid.state_slot]
    if seed % 2 == 0:  # from rest within the table's axes, it stays within them (to 1 % of a
        slack = 0.01 * grid.axis_step  # grid step: its segments are simulated with the DP's dt)
        assert np.all(si >= lower - slack) and np.all(si <= upper + slack)


def _in_domain(state, controller) -> bool:
    return bool(point_in_polygon(state[0], state[1], controller.lookahead.domain))


def test_controls_are_the_dp_samples_held_for_whole_segments(small):
    run = small.simulate(small.figure_state(np.array([1.0, 1.75, -10.0, 0.0, 0.0])), 4.0, DT)
    samples = small.lookahead.control_samples / small.control_scale
    moving = run.controls[: np.argmax(np.all(run.controls == 0.0, axis=1)) or None]
    states = small.controller_states(run.states)
    ends = {name: (small.table.axes[k][0], small.table.axes[k][-1]) for k, name in
            enumerate(small.state_order)}  # fmt: skip
    for step, control in enumerate(moving):
        after = dict(zip(small.state_order, states[step + 1], strict=True))
        at_an_end = any(  # a control cut so that steer or speed stops at its axis end
            np.isclose(after[name], end) for name in ("steer", "speed") for end in ends[name]
        )
        sample = np.any(np.all(np.isclose(samples, control), axis=1))
        assert sample or at_an_end or control[0] == 0.0
    columns = [small.state_order.index(name) for name in ("steer", "speed")]
    ends = np.array([[ends[name][0] for name in ("steer", "speed")],
                     [ends[name][1] for name in ("steer", "speed")]])  # fmt: skip
    after = states[1:, columns]
    cut = np.any(np.isclose(after, ends[0]) | np.isclose(after, ends[1]), axis=1)
    changes = np.flatnonzero(np.any(np.diff(run.controls, axis=0) != 0.0, axis=1))
    changes = changes[~cut[changes] & ~cut[changes + 1]]  # between whole samples
    assert changes.size > 0
    assert np.all(np.diff(changes) >= 2)  # held for more than one step between choices


def test_in_the_arrival_box_it_brakes_to_rest_and_holds(small):
    """Rolling back at 0.2 m/s 5 cm in front of the destination: full braking stops it 2 cm
    further on, inside the box, so it brakes at once and stays, steering held."""
    start = np.array([0.05, 1.0, 1.0, 10.0, -0.2])
    run = small.simulate(small.figure_state(start), 3.0, DT)
    states = small.controller_states(run.states)
    speed = states[:, small.grid.names.index("speed")]
    assert np.all(np.diff(np.abs(speed)) <= 1e-12)  # only ever slows
    assert speed[-1] == 0.0
    assert np.all(states[:, small.grid.names.index("steer")] == pytest.approx(10.0))
    assert abs(states[-1, 0]) < 0.1 and abs(states[-1, 1] - 1.0) < 0.1


def test_its_choices_do_not_depend_on_the_simulator_step(small):
    """Segments are simulated with the DP's step, so runs at 0.01 s and 0.0025 s make the same
    choices at the same times and end in the same place (to RK4 accuracy); only the step in
    which steer or speed reaches its axis end is cut differently (``_limit_inputs``)."""
    start = small.figure_state(np.array([1.5, 2.0, 5.0, 0.0, 0.0]))
    coarse = small.simulate(start, 4.0, 0.01)
    fine = small.simulate(start, 4.0, 0.0025)
    differ = ~np.isclose(fine.controls[::4], coarse.controls, rtol=1e-7, atol=1e-6)
    states = small.controller_states(coarse.states)[1:]
    columns = [small.state_order.index(name) for name in ("steer", "speed")]
    ends = np.array([[small.table.axes[k][0], small.table.axes[k][-1]] for k in columns])
    reaching = np.any(
        np.isclose(states[:, columns], ends[:, 0]) | np.isclose(states[:, columns], ends[:, 1]),
        axis=1,
    )
    assert np.all(reaching[np.any(differ, axis=1)])
    assert np.sum(np.any(differ, axis=1)) <= 2
    # the cut step ends at the limit either way, a fraction of a step apart in time: 10 µm
    np.testing.assert_allclose(fine.states[-1], coarse.states[-1], atol=1e-4)


def test_lookahead_needs_a_wheel_accel_that_brakes(car):
    spec = parse_controller_text(
        SMALL.replace("torq wheel_accel -200 200 3 0", "torq wheel_accel 0 200 3 0") + ARRIVAL,
        "x.ssc",
    )
    with pytest.raises(SpecError) as error:
        build_problem(spec, car)
    assert str(error.value) == (
        "x.ssc:15:8: expected a wheel_accel range from below 0 to above 0 (line 8): lookahead "
        "brakes by it, found 'lookahead'"
    )


def test_a_car_without_obstacles_parks_in_the_open(car, tmp_path):
    """No obstacle or domain lines: every pose is free, and the arrival box still stops it."""
    text = "\n".join(
        line for line in SMALL.splitlines() if not line.startswith(("obstacle", "domain"))
    )
    spec = parse_controller_text(text + "\n" + ARRIVAL, "open.ssc")
    table = generate_controller(spec, car, tmp_path / "open.h5", quiet=True)
    controller = Controller("open", table, car)
    assert np.all(controller.lookahead.pose_slot == -1)
    run = controller.simulate(controller.figure_state(np.array([0.02, 1.0, 0, 0, 0.2])), 2.0, DT)
    final = controller.controller_states(run.states)[-1]
    assert final[4] == pytest.approx(0.0, abs=1e-9)
    assert abs(final[0]) <= 0.1 and abs(final[1] - 1.0) <= 0.1


def test_a_start_grid_runs_the_starts_that_can_park_and_excludes_the_others(
    small, tmp_path, capsys
):
    """Starts whose pose overlaps the curb or lies outside the domain are excluded (not run),
    with the reason; every start records the table's cost-to-go there; the rate counts only
    the starts that are not excluded; two threads give the same file as one; progress goes to
    stderr unless quiet. The table keeps no cost-to-go to the whole arrival box
    (``arrival_value``), so the grid has none."""
    starts = np.array(
        [
            [1.5, 2.0, 0.0, 0.0, 0.0],
            [-1.0, 1.5, 5.0, 0.0, 0.0],
            [0.0, 0.6, 0.0, 0.0, 0.0],  # the body overlaps the curb
            [0.0, 2.7, 0.0, 0.0, 0.0],  # the reference point is outside the domain
            [2.8, 0.6, 0.0, 0.0, 0.0],  # the body overlaps the curb and the front car
        ]
    )
    one = evaluate_starts(small, starts, 10.0, DT, threads=1)
    shown = capsys.readouterr().err  # progress: the runs done, and the starts not run
    assert "starts: done, 2 runs in " in shown and "(3 starts that cannot park not run)" in shown
    assert one.excluded.tolist() == ["", "", NOT_FREE, NOT_FREE, NOT_FREE]
    assert one.excluded_detail.tolist() == [
        "",
        "",
        "overlaps curb",
        OUTSIDE_DOMAIN,
        "overlaps curb and front",
    ]
    assert not one.parked[2:].any() and not one.collided[2:].any()
    assert np.isnan(one.parking_seconds[2:]).all() and np.isnan(one.path_length[2:]).all()
    assert np.isfinite(one.path_length[:2]).all() and np.all(one.path_length[:2] > 0)
    assert one.cost_to_go.tolist() == [small.cost_to_go(start) for start in starts]
    assert np.isfinite(one.cost_to_go[:2]).all()
    assert one.success_rate == one.parked[:2].mean()
    two = evaluate_starts(small, starts, 10.0, DT, threads=2, quiet=True)
    assert capsys.readouterr().err == ""
    for name in ("parked", "collided", "parking_seconds", "cost_to_go", "path_length"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    write_start_grid(tmp_path / "grid.h5", one)
    back = read_start_grid(tmp_path / "grid.h5")
    assert back.excluded.tolist() == one.excluded.tolist()
    assert back.excluded_detail.tolist() == one.excluded_detail.tolist()
    np.testing.assert_array_equal(back.cost_to_go, one.cost_to_go)
    np.testing.assert_array_equal(back.consistency, one.consistency)
    assert one.arrival_cost_to_go is None and back.arrival_cost_to_go is None


def test_the_dp_ends_a_segment_where_the_runtime_would_brake_into_the_arrival_box(
    small, car, tmp_path
):
    """Rolling forward at 1 m/s 0.5 m behind the destination, full braking (1.047 m/s²) stops
    the car 0.48 m on, inside the arrival box: the lookahead runtime brakes at once, so the DP's
    cost-to-go there is the braking time, 0.955 s (plus at most one DP step, 0.02 s), far less
    than the same table without the runtime's arrival rule (1.16 s), which must land on the node."""
    node = small.cost_to_go(np.array([-0.5, 1.0, 0.0, 0.0, 1.0]))
    braking = 1.0 / (0.3 * np.radians(200.0))
    assert braking <= node <= braking + 0.02 + 1e-9
    plain = parse_controller_text(SMALL, "plain.ssc")
    table = generate_controller(plain, car, tmp_path / "plain.h5", quiet=True)
    without = Controller("plain", table, car)
    assert without.cost_to_go(np.array([-0.5, 1.0, 0.0, 0.0, 1.0])) > node + 0.1


def test_known_weight_only_drops_exits_so_values_only_grow(small, car, tmp_path):
    """known_weight 0.8: an exit whose known corners carry less than 80 % of its weight does not
    count, so no node's cost-to-go falls below the same table's without it (within the sweeps'
    tolerance); the nodes left without a trusted way on are dead ends, marked in /dead_end and
    inf, and the table records the share."""
    spec = parse_controller_text(SMALL + ARRIVAL + "known_weight 0.8\n", "trusted.ssc")
    trusted = generate_controller(spec, car, tmp_path / "trusted.h5", quiet=True)
    assert trusted.attrs["minimum_known_weight"] == 0.8
    assert trusted.dead_end is not None and trusted.dead_end.shape == trusted.value.shape
    assert np.isinf(trusted.value[trusted.dead_end]).all()
    assert trusted.attrs["dead_end_nodes"] == int(trusted.dead_end.sum())
    both = np.isfinite(trusted.value) & np.isfinite(small.table.value)
    assert both.sum() > 0.5 * np.isfinite(small.table.value).sum()
    tolerance = float(trusted.attrs["tolerance"])
    assert np.all(trusted.value[both] >= small.table.value[both] - 2 * tolerance)
    assert small.table.dead_end is None  # a table without known_weight has no /dead_end


def test_a_step_that_clips_an_obstacle_between_its_ends_is_not_free():
    """A thin wall 5 cm wide at x 2..2.05: a 4 m body stepping 4.7 m along +x starts clear of
    it (its nose at 1.8 m) and ends past it (its tail at 2.5 m) — both ends free, the step not
    (``_swept_free`` tests every 5 mm of travel); a step that stops short of the wall is free."""
    outline = CAR_BODY
    wall = [np.array([[2.0, -5.0], [2.05, -5.0], [2.05, 5.0], [2.0, 5.0]])]
    vertices, start = pack_polygons(wall)
    slots = np.arange(3, dtype=np.int64)
    before, past, short = np.array([1.0, 0.0, 0.0]), np.array([5.7, 0.0, 0.0]), np.zeros(3)
    short[0] = 1.15
    body, domain = np.empty_like(outline), np.zeros((0, 2))
    for pose in (before, past, short):
        assert first_colliding_sample(pose[None, :], outline, vertices, start)[0] == -1
    scene = Scene(slots, outline, vertices, start, domain)
    assert not _swept_free(before, past, scene, body)
    assert _swept_free(before, short, scene, body)


def test_a_polygon_grows_by_its_margin_on_every_side():
    """A rectangle grows by the margin on each side, whichever way round its vertices run; a
    right triangle's corners move along their bisectors; a polygon that is not convex is
    refused."""
    for outline in (CAR_BODY, CAR_BODY[::-1]):
        grown = grown_polygon(outline, 0.005)
        np.testing.assert_allclose(grown, outline + 0.005 * np.sign(outline))
    triangle = grown_polygon(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), 0.1)
    np.testing.assert_allclose(
        triangle, [[-0.1, -0.1], [1.1 + 0.1 * 2**0.5, -0.1], [-0.1, 1.1 + 0.1 * 2**0.5]]
    )
    with pytest.raises(ValueError, match="not convex"):
        grown_polygon(np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.2], [1.0, 2.0]]), 0.1)


def test_the_runtime_tests_the_body_grown_by_its_clearance(small, tmp_path):
    """The lookahead's outline is the table's body grown by CLEARANCE; a table whose body is not
    convex is refused by name (an InputError: exit 2 at the command line)."""
    body = controller_table_scene(small.table).body_outline
    np.testing.assert_allclose(small.lookahead.outline, grown_polygon(body, CLEARANCE))
    dent = [[0, -0.85], [0.8, 0], [0, 0.85], [-3.2, 0.85], [-3.2, -0.85], [-0.1, 0]]
    attrs = {**small.table.attrs, "body_outline": json.dumps(dent)}
    path = tmp_path / "dented.h5"
    write_controller_table(path, dataclasses.replace(small.table, attrs=attrs))
    with pytest.raises(InputError, match="the lookahead runtime needs a convex body_outline"):
        Controller.load(path, small.dynamics)


def test_a_corner_clipped_between_two_tests_is_caught():
    """A step of 4.95 mm (one test, at its end) carries the body's front-left corner 0.25 mm
    into a wall's corner halfway and out again: both ends are free, and the real body, tested
    every 5 mm, misses it; the grown body (CLEARANCE) does not."""
    nose = CAR_BODY[1]  # (0.8, 0.85): the body's front-left corner at the pose (0, 0, 0)
    wall = [np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) + nose]
    vertices, start = pack_polygons(wall)
    before, after = np.array([-0.0015, 0.002, 0.0]), np.array([0.002, -0.0015, 0.0])
    middle = (0.5 * (before + after))[None, :]
    body = np.empty_like(CAR_BODY)
    assert first_colliding_sample(middle, CAR_BODY, vertices, start)[0] == 0
    scene = Scene(POSE_SLOTS, CAR_BODY, vertices, start, NO_DOMAIN)
    assert _swept_free(before, after, scene, body)  # the gap CLEARANCE closes
    grown = grown_polygon(CAR_BODY, CLEARANCE)
    assert not _swept_free(before, after, scene._replace(outline=grown), body)


@settings(max_examples=300, deadline=None)
@given(
    corner=st.tuples(st.floats(-0.02, 0.02), st.floats(-0.02, 0.02)),
    heading=st.floats(-0.3, 0.3),
    move=st.tuples(st.floats(-0.05, 0.05), st.floats(-0.05, 0.05), st.floats(-0.03, 0.03)),
)
def test_a_step_free_for_the_grown_body_is_free_all_along(corner, heading, move):
    """A square obstacle with a corner within 2 cm of the body's front-left corner, the body
    stepping up to 5 cm and 1.7 degrees, as a DP step does: if ``_swept_free`` passes the step
    with the grown body, the real body is free at 2,000 poses along it."""
    nose = CAR_BODY[1]
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) + nose + np.array(corner)
    vertices, start = pack_polygons([square])
    before = np.array([0.0, 0.0, heading])
    after = before + np.array(move)
    grown, body = grown_polygon(CAR_BODY, CLEARANCE), np.empty_like(CAR_BODY)
    if first_colliding_sample(before[None, :], grown, vertices, start)[0] >= 0:
        return  # the run only steps from poses the grown body tested free
    if not _swept_free(before, after, Scene(POSE_SLOTS, grown, vertices, start, NO_DOMAIN), body):
        return
    along = before + np.linspace(0.0, 1.0, 2001)[:, None] * (after - before)
    assert first_colliding_sample(along, CAR_BODY, vertices, start)[0] == -1


def test_with_nothing_admissible_it_brakes_to_rest_and_stays(small):
    """The car rolling at 2 cm/s with its nose 3 mm from the front car (closer than CLEARANCE):
    no sample is admissible, so it brakes, choosing again every step, and comes to rest within
    two steps without rolling back (the braking input was once held for a whole DP step,
    overshooting rest: the car rocked to and fro and crept into the car behind it)."""
    state = small.figure_state(np.array([3.0 - 0.8 - 0.003, 1.0, 0.0, 0.0, 0.02]))
    run = small.simulate(state, 1.0, DT)
    speed = small.controller_states(run.states)[:, small.state_order.index("speed")]
    assert np.all(speed >= 0.0)
    assert np.all(speed[2:] == 0.0)
    x = small.controller_states(run.states)[:, small.state_order.index("x")]
    assert x.max() - x[0] < 0.2e-3  # v²/2a: 0.19 mm


def test_where_no_exit_is_trusted_it_chooses_by_any_known_corner(small, car):
    """A runtime that trusts no exit (a known weight above 1, which no exit carries) does not
    brake and stand where the trusted values end: it chooses among its admissible samples by
    the paper's rule (any known corner, renormalised), so its first segment is the one the
    table's own runtime (known weight 0) takes, and it drives on, touching nothing."""
    start = small.figure_state(np.array([1.5, 2.0, 5.0, 0.0, 0.0]))
    wary = Controller("wary", small.table, car)
    wary.lookahead = dataclasses.replace(small.lookahead, minimum_known_weight=1.5)
    assert small.lookahead.minimum_known_weight == 0.0
    ordinary, run = small.simulate(start, 8.0, DT), wary.simulate(start, 8.0, DT)
    first = np.flatnonzero(np.any(ordinary.controls != ordinary.controls[0], axis=1))[0]
    np.testing.assert_array_equal(run.controls[:first], ordinary.controls[:first])
    assert np.any(run.controls[:, 1] != 0.0)  # it drives
    path = poses(wary, run.states)
    assert np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)) > 0.5
    body = controller_table_scene(small.table).body_outline
    lookahead = wary.lookahead
    hit, _ = first_colliding_sample(
        path, body, lookahead.obstacle_vertices, lookahead.obstacle_start
    )
    assert hit == -1


def test_a_start_grid_whose_pose_search_would_not_fit_in_memory_is_refused(car, tmp_path):
    """A domain 6 km wide needs a pose lattice of terabytes: ``evaluate_starts`` says so, as an
    InputError naming the controller (exit 2 at the command line), before allocating."""
    text = SMALL.replace(
        "domain -3,0.5 3,0.5 3,2.5 -3,2.5", "domain -3000,0.5 3000,0.5 3000,2500 -3000,2500"
    )
    spec = parse_controller_text(text + ARRIVAL, "wide.ssc")
    wide = Controller("wide", generate_controller(spec, car, tmp_path / "wide.h5", quiet=True), car)
    with pytest.raises(InputError, match=r"^controller wide: the pose search: the lattice would"):
        evaluate_starts(wide, np.array([[1.5, 2.0, 0.0, 0.0, 0.0]]), 1.0, DT)


def test_a_start_grid_counts_the_lookaheads_own_memory_before_it_runs(small, car, monkeypatch):
    """A lookahead run allocates more than its records: each thread's copy of the cost-to-go
    and the run's put-back log (``Controller.run_work_bytes``). With the memory limit between
    the records alone and the records with that work, the start grid is refused, naming both
    counts of threads, before any run; the same limit takes one thread's records alone."""
    starts = np.array([[1.5, 2.0, 0.0, 0.0, 0.0]])
    seconds, threads = 10.0, 2
    steps = round(seconds / DT)
    records = steps * 8.0 * (2 * (len(car.STATE_NAMES) + len(small.state_order)) + 8)
    work = small.run_work_bytes(steps)
    nodes = small.lookahead.value.shape[0]
    assert work == 8 * nodes + nodes + 16 * min(nodes, steps << len(small.grid.names))
    gib = float(1 << 30)
    monkeypatch.setenv("MOSYS_MAX_MEMORY_GIB", repr(threads * (records + work / 2) / gib))
    with pytest.raises(LimitError, match=r"^mosys starts: expected a job that fits in .*2 at once"):
        evaluate_starts(small, starts, seconds, DT, threads=threads)
    monkeypatch.setenv("MOSYS_MAX_MEMORY_GIB", repr((records + work) / gib * 1.001))
    assert evaluate_starts(small, starts, seconds, DT, threads=1).parked.shape == (1,)


def test_a_script_counts_the_lookaheads_own_memory_before_it_runs(
    small, car, tmp_path, monkeypatch, capsys
):
    """``mosys run`` counts a lookahead table's work beside the run's records too: with the
    limit between them it refuses the ``sim`` line (exit 2) and writes nothing."""
    controllers = tmp_path / "controllers"
    controllers.mkdir()
    write_controller_table(controllers / "small.h5", small.table)
    script = tmp_path / "park.anim"
    script.write_text("state car 1.5,2,0,0,0\nswapcon car consmall.ctab\nsim 2\n")
    out = tmp_path / "park.h5"
    steps = round(2.0 / DT)
    records = steps * run_row_bytes(car)
    limit = (records + small.run_work_bytes(steps) / 2) / float(1 << 30)
    monkeypatch.setenv("MOSYS_MAX_MEMORY_GIB", repr(limit))
    argv = ["run", str(script), "--controllers", str(controllers), "--dt", str(DT), "-o", str(out)]
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    shutil.copy(car.__file__, dynamics / "car.py")  # the module is a content-addressed copy
    argv += ["--dynamics-dir", str(dynamics)]
    assert main(argv) == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .splitlines()[-1]
        .startswith(f"{script}:3:1: expected a job that fits in")
    )
    assert not out.exists()


def test_an_aim_shrinks_the_dps_arrival_box_so_values_only_grow(small, car, tmp_path):
    """aim=0.5: the DP ends its segments in half the arrival box, a smaller target, so no node's
    cost-to-go falls below the same table's aiming at the whole box (within the sweeps'
    tolerance), some rise, and the runtime still brakes in the whole box. Asked for
    (``arrival_value``), the table keeps the cost-to-go to the whole box too
    (``/arrival_value``): the values of the table aiming at it, which keeps them as its own
    ``/value``, at the same nodes and within the tolerance (its sweeps start from the aimed
    values: ``ssc.solution.arrival_solution``); not asked for, it keeps none."""
    spec = parse_controller_text(SMALL + ARRIVAL.replace("\n", " aim=0.5 arrival_value\n"), "a")
    generate_controller(spec, car, tmp_path / "a.h5", quiet=True)
    aimed = Controller.load(tmp_path / "a.h5", car)
    tolerance = float(small.table.attrs["tolerance"])
    whole = np.isfinite(small.table.value)
    assert np.array_equal(np.isfinite(aimed.table.arrival_value), whole)
    np.testing.assert_allclose(
        aimed.table.arrival_value[whole], small.table.value[whole], rtol=0, atol=tolerance
    )
    assert small.table.arrival_value is None
    state = np.array([0.3, 1.1, 7.0, 5.0, 0.1])  # between nodes, near the destination
    assert aimed.arrival_cost_to_go(state) == pytest.approx(small.cost_to_go(state), abs=tolerance)
    assert aimed.arrival_cost_to_go(state) < aimed.cost_to_go(state)
    assert small.arrival_cost_to_go(state) == math.inf  # no /arrival_value: none known
    assert (aimed.table.attrs["arrival_aim"], small.table.attrs["arrival_aim"]) == (0.5, 1.0)
    np.testing.assert_array_equal(aimed.lookahead.arrival_box, small.lookahead.arrival_box)
    both = np.isfinite(aimed.table.value) & np.isfinite(small.table.value)
    assert both.sum() > 0.9 * np.isfinite(small.table.value).sum()
    assert np.all(aimed.table.value[both] >= small.table.value[both] - 2 * tolerance)
    assert np.sum(aimed.table.value[both] > small.table.value[both] + 0.05) > 10


@pytest.mark.parametrize("seed", range(6))
def test_a_choice_that_costs_more_than_promised_raises_the_runs_table_there(seed):
    """``_learn`` (the runtime's LRTA* step) on a 3-D grid with some unknown nodes: where the
    best choice costs more than the interpolation promises, the known corners around the state
    rise (only they, none falls) until the interpolation there equals the choice's cost; where
    it costs less, or nothing is admissible (inf), or too little weight is known, nothing
    changes. Each node it raises is logged once, with its value before: putting the log back
    gives the table bit for bit, after any number of raises."""
    from mosys.kernels.interpolate import (
        clamp_to_domain,
        grid_strides,
        interpolate_with,
        interpolation_scratch,
    )
    from mosys.kernels.lookahead import _learn

    rng = np.random.default_rng(seed)
    axis_min, axis_step = np.array([0.0, -1.0, 0.0]), np.array([0.5, 0.25, 0.1])
    axis_count = np.array([5, 9, 4], np.int64)
    wrap = np.zeros(3, np.bool_)
    strides = np.empty(3, np.int64)
    grid_strides(axis_count, strides)
    nodes = int(np.prod(axis_count))
    known = rng.random(nodes) > 0.2
    scratch, clamped, out = interpolation_scratch(3), np.empty(3), np.empty(1)

    def promised(value, state):
        clamp_to_domain(axis_min, axis_step, axis_count, wrap, state, clamped)
        weight = interpolate_with(
            axis_min, axis_step, axis_count, wrap, strides, value, known, clamped, scratch, out
        )
        return out[0], weight

    touched = np.zeros(nodes, np.bool_)
    undo_index, undo_value = np.empty(nodes, np.int64), np.empty(nodes)

    def learn(value, state, cost, minimum=0.0, logged=0):
        return _learn(axis_min, axis_step, axis_count, wrap, strides, value, known, minimum,
                      state, cost, scratch, clamped, out, touched, undo_index, undo_value,
                      logged)  # fmt: skip

    def put_back(value, logged):
        value[undo_index[:logged], 0] = undo_value[:logged]
        touched[:] = False

    for _ in range(20):
        value = rng.uniform(0, 10, (nodes, 1))
        state = axis_min + axis_step * (axis_count - 1) * rng.random(3)
        before, weight = promised(value, state)
        if weight == 0.0:
            continue
        for cost, minimum in ((before - 1.0, 0.0), (np.inf, 0.0), (before + 3.0, weight + 0.01)):
            learned = value.copy()
            assert learn(learned, state, cost, minimum) == 0
            np.testing.assert_array_equal(learned, value)
        learned = value.copy()
        logged = learn(learned, state, before + 3.0)
        assert promised(learned, state)[0] == pytest.approx(before + 3.0, abs=1e-9)
        rise = (learned - value)[:, 0]
        assert np.all(rise >= 0) and not np.any(rise[~known])
        assert 1 <= np.count_nonzero(rise) <= 8  # the state's corners only
        # the raised nodes are logged (and perhaps a known corner of zero weight, raised by 0)
        assert set(np.flatnonzero(rise)) <= set(undo_index[:logged])
        assert known[undo_index[:logged]].all() and logged <= 8
        top = axis_min + axis_step * (axis_count - 1)
        for _ in range(5):  # more raises around it: each node logged once
            moved = np.clip(state + rng.normal(0, 0.3, 3), axis_min, top)
            logged = learn(learned, moved, promised(learned, moved)[0] + 1.0, 0.0, logged)
        assert len(set(undo_index[:logged])) == logged
        put_back(learned, logged)
        np.testing.assert_array_equal(learned, value)


def test_a_run_puts_back_what_it_learned_so_runs_do_not_depend_on_each_other(small):
    """A run learns on its thread's copy of the table and puts it back before it returns: the
    table and the copy are as they were, bit for bit, and the run again is the same run."""
    start = small.figure_state(np.array([1.5, 1.8, 10.0, 0.0, 0.0]))
    value = small.lookahead.value.copy()
    first = small.simulate(start, 8.0, DT).states
    np.testing.assert_array_equal(small.lookahead.value, value)
    np.testing.assert_array_equal(small._learning_values(), value)
    np.testing.assert_array_equal(small.simulate(start, 8.0, DT).states, first)


def test_a_start_grid_none_of_which_can_park_says_so(small, car, tmp_path, capsys):
    """A grid off the domain ran nothing and wrote its file without a word."""
    from mosys.cli import main
    from mosys.io.controller_table import write_controller_table

    table = tmp_path / "small.h5"
    write_controller_table(table, small.table)
    argv = ["starts", str(table), "--dynamics", car.__file__, "--x", "90", "91", "2"]
    argv += ["--y", "50", "51", "2", "--heading", "0", "--steer", "0", "--quiet"]
    assert main([*argv, "-o", str(tmp_path / "g.h5")]) == 0
    assert capsys.readouterr().err == (
        "warning: none of the 4 starts can park (each lies on an obstacle or off the domain, "
        "or no path leads from it): none was run\n"
    )
