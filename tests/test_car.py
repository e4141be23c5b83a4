"""The self-parking car: its figure spec, kinematics, obstacle geometry, the spec lines for
obstacles and the domain, collision removal in the DP, and the parking judgement."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.io.car_scene import CarScene
from mosys.kernels.geometry import (
    box_in_polygon,
    first_collision,
    pack_polygons,
    point_in_polygon,
    polygons_overlap,
    segments_cross,
)
from mosys.kernels.integrate import rk4_scratch, rk4_step
from mosys.parsing.controller import (
    first_self_crossing,
    parse_controller_text,
    render_controller_spec,
)
from mosys.parsing.figure import parse_figure_text
from mosys.parsing.tokens import SpecError
from mosys.parsing.vehicle import Vehicle
from mosys.ssc.generate import generate_controller
from mosys.ssc.parking import parking_outcome
from mosys.ssc.problem import build_problem

CAR_LINE = (
    "vehicle wheelbase=2.5 length=4.0 width=1.7 front_overhang=0.8 wheel_radius=0.3 "
    "steer_limit=35\n"
)


# --- figure spec


def test_car_spec_parses_to_the_documented_geometry():
    vehicle = parse_figure_text(CAR_LINE, "car.fig")
    assert isinstance(vehicle, Vehicle)
    assert vehicle.wheelbase == 2.5 and vehicle.wheel_radius == 0.3
    assert vehicle.steer_limit == pytest.approx(math.radians(35))
    assert vehicle.body_outline == ((0.8, -0.85), (0.8, 0.85), (-3.2, 0.85), (-3.2, -0.85))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "vehicle wheelbase=2.5 length=4.0 width=1.7 front_overhang=0.8 wheel_radius=0.3\n",
            "car.fig:1:79: expected 'steer_limit=' (the largest steering angle of the road "
            "wheels in degrees), found end of line",
        ),
        (
            CAR_LINE.replace("length=4.0", "length=3.0"),
            "car.fig:1:30: expected a length >= wheelbase + front_overhang (3.3 m: the rear "
            "axle lies inside the body), found '3.0'",
        ),
        (
            CAR_LINE.replace("width=1.7", "width=-1"),
            "car.fig:1:40: expected a number > 0 for width, found '-1'",
        ),
        (
            CAR_LINE + "gravity 9.81\n",
            "car.fig:2:1: expected end of file (a vehicle spec has "
            "one 'vehicle' line), found 'gravity'",
        ),
        (
            "rod a length=1 mass=1\n" + CAR_LINE,
            "car.fig:2:1: expected 'vehicle' as the first line of a spec of its own, "
            "found 'vehicle'",
        ),
    ],
)
def test_bad_car_specs_name_the_place(text, message):
    with pytest.raises(SpecError) as error:
        parse_figure_text(text, "car.fig")
    assert str(error.value) == message


# --- kinematics


def simulate(car, state, inputs, seconds, dt=0.001):
    state = np.array(state, dtype=float)
    scratch = rk4_scratch(5)
    for _ in range(round(seconds / dt)):
        rk4_step(car.derivative_into, state, np.asarray(inputs, float), dt, scratch)
    return state


def test_fixed_steer_drives_the_front_wheels_round_a_circle(car):
    """With steer δ and speed v held, the heading turns at v sin δ / L and the front-wheel
    point runs on a circle of radius L / sin δ (a bicycle model)."""
    steer, speed, seconds = math.radians(20), 1.5, 4.0
    end = simulate(car, [0, 0, 0, steer, speed], [0, 0], seconds)
    rate = speed * math.sin(steer) / 2.5
    assert end[2] == pytest.approx(rate * seconds, rel=1e-9)
    radius = 2.5 / math.sin(steer)
    # the circle's centre lies a radius to the left of the front wheels' direction at the start
    centre = np.array([-radius * math.sin(steer), radius * math.cos(steer)])
    assert np.hypot(*(end[:2] - centre)) == pytest.approx(radius, rel=1e-9)


def test_steering_stops_at_its_limit_and_wheel_accel_changes_speed(car):
    end = simulate(car, [0, 0, 0, 0, 0], [math.radians(30), math.radians(100)], 2.0)
    assert end[3] == pytest.approx(math.radians(35), abs=math.radians(0.05))
    assert end[4] == pytest.approx(0.3 * math.radians(100) * 2.0, rel=1e-9)


# --- geometry


def box(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


coordinate = st.floats(-10, 10, allow_nan=False)


@settings(deadline=None)  # the first example compiles the kernel
@given(
    coordinate,
    coordinate,
    st.floats(0.1, 5),
    st.floats(0.1, 5),
    coordinate,
    coordinate,
    st.floats(0.1, 5),
    st.floats(0.1, 5),
)
def test_axis_aligned_boxes_overlap_exactly_when_their_intervals_do(x, y, w, h, u, v, a, b):
    first, second = box(x, y, x + w, y + h), box(u, v, u + a, v + b)
    expected = x <= u + a and u <= x + w and y <= v + b and v <= y + h
    assert polygons_overlap(first, second) == expected
    assert polygons_overlap(second, first) == expected


def test_containment_and_an_l_shaped_obstacle():
    assert polygons_overlap(box(0, 0, 10, 10), box(4, 4, 5, 5))  # one inside the other
    assert not polygons_overlap(ELL, box(2, 2, 3, 3))  # in the notch
    assert point_in_polygon(0.5, 3.0, ELL) and not point_in_polygon(2.0, 2.0, ELL)


ELL = np.array([[0, 0], [4, 0], [4, 1], [1, 1], [1, 4], [0, 4]], dtype=float)


def test_a_box_is_in_a_polygon_only_with_the_polygons_boundary_outside_it():
    square = box(0, 0, 10, 10)
    assert box_in_polygon(2.0, 3.0, 2.0, 3.0, square)
    assert not box_in_polygon(9.0, 11.0, 2.0, 3.0, square)  # across an edge
    assert not box_in_polygon(-1.0, 11.0, -1.0, 11.0, square)  # holds the polygon
    assert not box_in_polygon(2.0, 3.0, 2.0, 3.0, ELL)  # in the notch
    assert not box_in_polygon(0.5, 1.5, 0.5, 1.5, ELL)  # a corner inside, the notch's corner in it
    assert box_in_polygon(0.25, 0.75, 0.25, 3.75, ELL)  # the L's upright
    assert not box_in_polygon(0.0, 0.5, 0.25, 0.75, ELL)  # touching the edge x = 0
    assert box_in_polygon(1.0, 0.0, 1.0, 0.0, ELL)  # empty: nothing to hold


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-1.0, 5.0),
    st.floats(-1.0, 5.0),
    st.floats(0.0, 4.0),
    st.floats(0.0, 4.0),
    st.sampled_from(["ell", "square", "triangle"]),
)
def test_every_point_of_a_box_in_a_polygon_is_in_it(x, y, w, h, shape):
    """What the DP's replay relies on to skip testing each step against the domain: a box that
    box_in_polygon passes holds no point that point_in_polygon finds outside."""
    polygon = {
        "ell": ELL,
        "square": box(0, 0, 4, 4),
        "triangle": np.array([[0, 0], [5, 0], [0, 5]], dtype=float),
    }[shape]
    if not box_in_polygon(x, x + w, y, y + h, polygon):
        return
    for px in np.linspace(x, x + w, 9):
        for py in np.linspace(y, y + h, 9):
            assert point_in_polygon(px, py, polygon)


def test_first_collision_turns_the_body():
    outline = box(-3.2, -0.85, 0.8, 0.85)
    vertices, start = pack_polygons([box(-10, -1, 10, 0)])  # a curb below y = 0
    body = np.empty_like(outline)
    assert first_collision(outline, 0.0, 1.0, 0.0, vertices, start, body) == -1
    # turned 30 degrees, the rear corner swings 3.2 sin 30 = 1.6 m down: into the curb
    assert first_collision(outline, 0.0, 1.0, math.radians(30), vertices, start, body) == 0


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-6.0, 6.0),
    st.floats(-2.0, 4.0),
    st.floats(-math.pi, math.pi),
    st.lists(
        st.tuples(st.floats(-8.0, 8.0), st.floats(-3.0, 5.0), st.floats(0.05, 4.0)),
        min_size=1,
        max_size=4,
    ),
)
def test_first_collision_is_the_first_overlapping_obstacle(x, y, heading, squares):
    """The bounding-box shortcut changes no answer: the first obstacle that polygons_overlap
    finds the placed body overlapping, or -1."""
    from mosys.kernels.geometry import place_outline

    outline = np.array([[-3.2, -0.85], [0.8, -0.85], [0.8, 0.85], [-0.2, 0.85], [-3.2, 0.6]])
    obstacles = [box(cx, cy, cx + side, cy + side / 2) for cx, cy, side in squares]
    vertices, start = pack_polygons(obstacles)
    body = np.empty_like(outline)
    placed = np.empty_like(outline)
    place_outline(outline, x, y, heading, placed)
    expected = next((k for k, b in enumerate(obstacles) if polygons_overlap(placed, b)), -1)
    assert first_collision(outline, x, y, heading, vertices, start, body) == expected


# --- controller spec lines

SMALL = """dyn car
ssd x -2 2 9
ssd y 1 2 5
ssd heading -20 20 3
ssd steer -30 30 3
ssd speed -1 1 3
torq steer_rate -30 30 3 0
torq wheel_accel -200 200 3 0
dest x=0 y=1 heading=0 speed=0
tol 0.001
dt 0.02
obstacle curb -20,-1 20,-1 20,0 -20,0
obstacle front 3.0,0.15 7,0.15 7,1.85 3.0,1.85
domain -3,0.5 3,0.5 3,2.5 -3,2.5
"""


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "obstacle front 3.0,0.15 7,0.15 7,1.85 3.0,1.85",
            "obstacle front 3,0 4,0",
            "x.ssc:13:23: expected a vertex 'x,y' (a polygon has at least 3; 2 given), "
            "found end of line",
        ),
        (
            "obstacle front 3.0,0.15",
            "obstacle curb 3.0,0.15",
            "x.ssc:13:10: expected a name not used by another obstacle (line 12), found 'curb'",
        ),
        (
            "3.0,1.85\ndomain",
            "3.0;1.85\ndomain",
            "x.ssc:13:39: expected a vertex 'x,y' in metres, found '3.0;1.85'",
        ),
        (
            "domain -3,0.5 3,0.5 3,2.5 -3,2.5",
            "domain 0,0 1,0 2,0",
            "x.ssc:14:8: expected vertices enclosing a non-zero area, found '0,0'",
        ),
        (  # a bow-tie encloses no net area: its edges crossing is what is wrong
            "domain -3,0.5 3,0.5 3,2.5 -3,2.5",
            "domain 0,0 1,1 1,0 0,1",
            "x.ssc:14:16: expected a simple polygon (its edges cross or touch here), found '1,0'",
        ),
        (  # it said that edges crossed
            "domain -3,0.5 3,0.5 3,2.5 -3,2.5",
            "domain 0,0 1,0 1,1 1,1 0,1",
            "x.ssc:14:20: expected a vertex other than the one before it, found '1,1'",
        ),
        (
            "domain -3,0.5 3,0.5 3,2.5 -3,2.5",
            "domain 0,0 1,0 1,1 0,0",
            "x.ssc:14:20: expected a vertex other than the first (a polygon closes itself), "
            "found '0,0'",
        ),
        (
            "domain -3,0.5 3,0.5 3,2.5 -3,2.5",
            "domain 0,0 2,0 2,2 1,-1 0,2",
            "x.ssc:14:16: expected a simple polygon (its edges cross or touch here), found '2,2'",
        ),
    ],
)
def test_bad_obstacle_lines_name_the_place(old, new, message):
    with pytest.raises(SpecError) as error:
        parse_controller_text(SMALL.replace(old, new), "x.ssc")
    assert str(error.value) == message


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "obstacle front 3.0,0.15",
            "obstacle front 0.5,0.15",
            "x.ssc:9:6: expected a destination the car can occupy (the car's outline at (0, 1) "
            "overlaps obstacle 'front' (line 13)), found 'x=0'",
        ),
        (
            "ssd speed -1 1 3",
            "ssd sped -1 1 3",
            "x.ssc:6:5: expected a state variable of figure 'car' (one of 'x', 'y', 'heading', "
            "'steer', 'speed'), found 'sped'",
        ),
        (
            "torq wheel_accel -200 200 3 0",
            "torq wheel_accel -200 200 0 0",
            "x.ssc:8:27: expected a whole number >= 1 for samples, found '0'",
        ),
    ],
)
def test_specs_that_do_not_fit_the_car_name_the_line(car, old, new, message):
    text = SMALL.replace(old, new)
    if "dest" in new or "sped" in new:
        text = text.replace("speed=0", "sped=0") if "sped" in new else text
    with pytest.raises(SpecError) as error:
        build_problem(parse_controller_text(text, "x.ssc"), car)
    assert str(error.value) == message


def test_an_obstacle_beyond_the_cars_reach_is_kept_with_a_warning(car, capsys):
    """It was refused, stopping the table: a scene's rear car moved 0.1 m back."""
    far = "obstacle front 30,0.15 34,0.15 34,1.85 30,1.85"
    text = SMALL.replace("obstacle front 3.0,0.15 7,0.15 7,1.85 3.0,1.85", far)
    problem = build_problem(parse_controller_text(text, "x.ssc"), car)
    assert problem is not None
    assert capsys.readouterr().err == (
        "warning: x.ssc:13:10: obstacle 'front' lies beyond the car's reach (3.31 m) of where "
        "its reference point can be (the table's axes within the domain: x -2..2 m, y 1..2 m): "
        "no run can touch it\n"
    )


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("policy", "x.ssc:15:7: expected one of 'interpolate', 'lookahead', found end of line"),
        (
            "policy greedy x=0.1",
            "x.ssc:15:8: expected one of 'interpolate', 'lookahead', found 'greedy'",
        ),
        (
            "policy lookahead",
            "x.ssc:15:17: expected a 'name=tolerance' arrival tolerance of a dest dimension "
            "after 'lookahead', found end of line",
        ),
        (
            "policy lookahead steer=5",
            "x.ssc:15:18: expected a dest name (one of 'x', 'y', 'heading', 'speed') before '=', "
            "found 'steer'",
        ),
        (
            "policy lookahead x=0.1 x=0.2",
            "x.ssc:15:24: expected 'x=' only once, found 'x=0.2'",
        ),
        (
            "policy lookahead x=0",
            "x.ssc:15:20: expected a number > 0 for the tolerance of x, found '0'",
        ),
        (
            "policy lookahead x",
            "x.ssc:15:18: expected a 'name=tolerance' arrival tolerance, found 'x'",
        ),
        (
            "policy lookahead x=0.1 aim=0",
            "x.ssc:15:28: expected an aim above 0 and at most 1, found '0'",
        ),
        (
            "policy lookahead aim=1.5 x=0.1",
            "x.ssc:15:22: expected an aim above 0 and at most 1, found '1.5'",
        ),
        (
            "policy lookahead x=0.1 aim=0.5 aim=0.6",
            "x.ssc:15:32: expected 'aim=' only once, found 'aim=0.6'",
        ),
        (
            "policy lookahead x=0.1 arrival_value aim=0.5 arrival_value",
            "x.ssc:15:46: expected 'arrival_value' only once, found 'arrival_value'",
        ),
        (
            "policy lookahead x=0.1 arrival_values",
            "x.ssc:15:24: expected a 'name=tolerance' arrival tolerance, found 'arrival_values'",
        ),
        (
            "policy interpolate arrival_value",
            "x.ssc:15:20: expected the end of the line after 'interpolate', found 'arrival_value'",
        ),
        (
            "policy lookahead aim=0.5",
            "x.ssc:15:25: expected a 'name=tolerance' arrival tolerance of a dest dimension "
            "after 'lookahead', found end of line",
        ),
        (
            "policy interpolate x=0.1",
            "x.ssc:15:20: expected the end of the line after 'interpolate', found 'x=0.1'",
        ),
        (
            "policy lookahead x=0.1\npolicy interpolate",
            "x.ssc:16:1: expected one 'policy' line only (the first is line 15), found 'policy'",
        ),
    ],
)
def test_bad_policy_lines_name_the_place(line, message):
    with pytest.raises(SpecError) as error:
        parse_controller_text(SMALL + line + "\n", "x.ssc")
    assert str(error.value) == message


def test_a_policy_line_round_trips_and_lookahead_needs_a_vehicle(link1):
    spec = parse_controller_text(SMALL + "policy lookahead x=0.1 heading=4\n", "x.ssc")
    assert spec.policy.kind == "lookahead"
    assert spec.policy.arrival == (("x", 0.1), ("heading", 4.0))
    again = parse_controller_text(render_controller_spec(spec), "x.ssc")
    assert again.policy.arrival == spec.policy.arrival
    assert spec.policy.aim == again.policy.aim == 1.0
    aimed = parse_controller_text(SMALL + "policy lookahead x=0.1 aim=0.25 heading=4\n", "x.ssc")
    assert (aimed.policy.arrival, aimed.policy.aim) == (spec.policy.arrival, 0.25)
    again = parse_controller_text(render_controller_spec(aimed), "x.ssc")
    assert again.policy == aimed.policy
    assert not aimed.policy.arrival_value
    both = parse_controller_text(SMALL + "policy lookahead arrival_value x=0.1 aim=0.5\n", "x.ssc")
    assert (both.policy.arrival, both.policy.aim, both.policy.arrival_value) == (
        (("x", 0.1),),
        0.5,
        True,
    )
    again = parse_controller_text(render_controller_spec(both), "x.ssc")
    assert again.policy == both.policy
    pendulum = parse_controller_text(
        "dyn link1\nssd angle -180 170 36 wrap\nssd omega -500 500 21\n"
        "torq torque -10 10 11 0.1\ndest angle=0 omega=0\npolicy lookahead angle=5\n",
        "x.ssc",
    )
    with pytest.raises(SpecError) as error:
        build_problem(pendulum, link1)
    assert str(error.value) == (
        "x.ssc:6:8: expected 'interpolate': figure 'link1' is not a vehicle, found 'lookahead'"
    )


def test_obstacles_need_a_vehicle(link1):
    spec = parse_controller_text(
        "dyn link1\nssd angle -180 170 36 wrap\nssd omega -500 500 21\n"
        "torq torque -10 10 11 0.1\ndest angle=0 omega=0\nobstacle wall 0,0 1,0 1,1\n",
        "x.ssc",
    )
    with pytest.raises(SpecError) as error:
        build_problem(spec, link1)
    assert str(error.value) == (
        "x.ssc:6:10: expected obstacle and domain lines only for a figure with a body outline "
        "(a vehicle); figure 'link1' has none, found 'wall'"
    )


# --- generation


def brute_force_free(problem):
    """Free nodes by an independent test: separating axes of two convex rectangles."""
    grid = problem.grid
    axes = np.meshgrid(*grid.axis_values(), indexing="ij")
    x, y, heading = (axes[grid.names.index(n)].ravel() for n in ("x", "y", "heading"))
    heading = np.radians(heading)
    outline = problem.obstacles.outline
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    body_x = x[:, None] + c * outline[:, 0] - s * outline[:, 1]
    body_y = y[:, None] + s * outline[:, 0] + c * outline[:, 1]
    free = np.ones(x.size, dtype=bool)
    for polygon in problem.obstacles.polygons():
        p = np.array(polygon)
        separated = (body_x.max(1) < p[:, 0].min()) | (body_x.min(1) > p[:, 0].max())
        separated |= (body_y.max(1) < p[:, 1].min()) | (body_y.min(1) > p[:, 1].max())
        for ax, ay, low, high in ((c, s, -3.2, 0.8), (-s, c, -0.85, 0.85)):
            projection = (p[None, :, 0] - x[:, None]) * ax + (p[None, :, 1] - y[:, None]) * ay
            separated |= (projection.max(1) < low) | (projection.min(1) > high)
        free &= separated
    domain = np.array(problem.spec.domain.vertices)
    inside = (x >= domain[:, 0].min()) & (x <= domain[:, 0].max())
    inside &= (y >= domain[:, 1].min()) & (y <= domain[:, 1].max())
    return free & inside


def test_states_in_collision_are_removed_and_cost_inf(car, tmp_path):
    spec = parse_controller_text(SMALL, "small.ssc")
    problem = build_problem(spec, car)
    expected = brute_force_free(problem)
    assert 0 < expected.sum() < expected.size
    np.testing.assert_array_equal(problem.node_valid, expected)
    table = generate_controller(spec, car, tmp_path / "small.h5", quiet=True)
    assert table.attrs["table_states"] == expected.sum()
    assert table.attrs["removed_nodes"] == expected.size - expected.sum()
    assert np.all(np.isinf(table.value.ravel()[~expected]))
    assert np.isfinite(table.value).sum() > 0
    for key in ("wheelbase", "wheel_radius", "body_outline", "obstacles"):
        assert key in table.attrs


# --- parking judgement


def scene():
    return CarScene(
        body_outline=box(-3.2, -0.85, 0.8, 0.85),
        obstacles=(box(-20, -1, 20, 0), box(3, 0.15, 7, 1.85)),
        obstacle_names=("curb", "front"),
        destination={"x": 0.0, "y": 1.0, "heading": 0.0},
        wheelbase=2.5,
        domain=np.zeros((0, 2)),
    )


ORDER = ("x", "y", "heading", "steer", "speed")


def test_a_run_that_comes_to_rest_in_the_space_is_parked_from_its_arrival():
    t = np.linspace(0, 10, 101)
    x = np.clip(2.0 - 0.4 * t, 0.05, None)
    speed = np.where(x > 0.05, -0.4, 0.0)
    state = np.column_stack([x, np.ones_like(t), np.zeros_like(t), np.zeros_like(t), speed])
    outcome = parking_outcome(t, state, ORDER, scene())
    assert outcome.parked and outcome.collision_index == -1
    assert outcome.parking_seconds == pytest.approx(t[np.argmax(x <= 0.05)])


def test_a_run_that_touches_an_obstacle_is_a_failure_even_if_it_ends_parked():
    t = np.linspace(0, 10, 101)
    y = np.where(t < 5, 1.0 - 0.5 * np.sin(np.pi * t / 5), 1.0)  # dips into the curb
    state = np.column_stack(
        [np.zeros_like(t), y, np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)]
    )
    outcome = parking_outcome(t, state, ORDER, scene())
    assert not outcome.parked
    assert outcome.collided_with == "curb"
    assert 0 < outcome.collision_index < 50


def transitions_of(problem, car, classes):
    """The exit transitions of ``problem``, its classes replayed or (None) every node
    integrated, and each exit's corners (absolute flat node indices) and weights (R, U, K)."""
    from mosys.kernels.dp_exits import exit_transitions_template
    from mosys.kernels.specialise import specialise
    from mosys.ssc.exits import compute_transitions, exit_transition_arguments

    kernel = specialise(exit_transitions_template, car, parallel=True)
    arguments = exit_transition_arguments(problem, car, problem.spec.dt)
    transitions = compute_transitions(
        kernel, arguments, problem, problem.node_valid, classes, quiet=True
    )
    nodes = np.flatnonzero(transitions.row_of >= 0)
    own = transitions.shape_row_of is None  # each node its own shapes (integrated)
    shapes = transitions.row_of[nodes] if own else transitions.shape_row_of[nodes]
    corners = nodes[:, None, None] + transitions.exit_index[shapes]
    weights = transitions.exit_weight[shapes]
    return transitions, np.where(weights > 0, corners, -1), weights


@pytest.mark.parametrize("policy", ["", "policy lookahead x=0.3 y=0.2 heading=10\n"])
def test_replaying_each_class_gives_the_transitions_of_integrating_every_node(car, policy):
    """The car's equations read neither x nor y, so each (heading, steer, speed) class is
    integrated once and replayed at its nodes, with the obstacles, the domain and the arrival
    box tested at each node: the same exits as integrating from every node, to rounding."""
    from mosys.ssc.exits import MotionClasses

    problem = build_problem(parse_controller_text(SMALL + policy, "small.ssc"), car)
    classes = MotionClasses.of(problem, car)
    assert classes is not None and classes.representative.size == 3 * 3 * 3
    replayed, replayed_corners, replayed_weights = transitions_of(problem, car, classes)
    integrated, corners, weights = transitions_of(problem, car, None)
    assert replayed.exit_index.shape[0] == 27  # one shape per class
    cost = integrated.segment_cost
    finite = np.isfinite(cost)
    assert 0 < finite.sum() < cost.size  # obstacles and the domain discard some segments
    np.testing.assert_array_equal(np.isfinite(replayed.segment_cost), finite)
    np.testing.assert_allclose(replayed.segment_cost[finite], cost[finite], rtol=1e-12)
    np.testing.assert_array_equal(replayed.to_destination, integrated.to_destination)
    passing = finite & ~integrated.to_destination
    for exit_corners, exit_weights, other_corners, other_weights in zip(
        replayed_corners[passing],
        replayed_weights[passing],
        corners[passing],
        weights[passing],
        strict=True,
    ):  # the same corners with the same weights, in whatever order
        assert dict(zip(exit_corners, exit_weights, strict=True)) == pytest.approx(
            dict(zip(other_corners, other_weights, strict=True)), abs=1e-6
        )
    if policy:  # some segments end braking into the arrival box, at the destination
        assert integrated.to_destination.sum() > 0


def test_mosys_dp_tells_removed_nodes_from_unreachable_ones(car, tmp_path, capsys):
    """Its line counted the nodes removed for obstacles or the domain as unreachable: '1035827
    unreachable' for a table of which 980,350 nodes were removed and 55,477 states were out of
    reach."""
    import shutil

    from mosys.cli import main
    from mosys.io.controller_table import read_controller_table

    spec = tmp_path / "small.ssc"
    spec.write_text(SMALL)
    out = tmp_path / "small.h5"
    (tmp_path / "dynamics").mkdir()
    shutil.copy(car.__file__, tmp_path / "dynamics" / "car.py")  # the fixture's, compiled
    argv = ["dp", str(spec), "--dynamics-dir", str(tmp_path / "dynamics"), "--quiet"]
    assert main([*argv, "-o", str(out)]) == 0
    attrs = read_controller_table(out).attrs
    removed, states = int(attrs["removed_nodes"]), int(attrs["table_states"])
    out_of_reach = int(attrs["unreachable_nodes"]) - removed
    assert removed > 0 and 0 <= out_of_reach <= states
    assert (
        f", {out_of_reach} of {states} table states unreachable ({removed} nodes removed), "
    ) in capsys.readouterr().out


@settings(max_examples=300, deadline=None)
@given(
    points=st.lists(
        st.tuples(st.integers(-3, 3), st.integers(-3, 3)), min_size=3, max_size=7, unique=True
    ),
    turn=st.integers(0, 6),
)
def test_a_polygons_verdict_does_not_depend_on_where_or_which_way_its_vertices_start(points, turn):
    """On a small integer grid vertices often lie exactly on other edges: a side of 0 counted
    as negative, so [(0,0),(4,0),(4,4),(2,0),(0,4)] was refused and its reverse accepted. Simple
    or not, the same polygon read backwards or from another vertex is judged the same, and
    as the runtime's exact segment test (kernels.geometry.segments_cross) judges it."""
    vertices = [(float(x), float(y)) for x, y in points]
    simple = first_self_crossing(vertices) is None
    turned = vertices[turn % len(vertices) :] + vertices[: turn % len(vertices)]
    assert (first_self_crossing(turned) is None) == simple
    assert (first_self_crossing(vertices[::-1]) is None) == simple
    n = len(vertices)
    edges = [(*vertices[i], *vertices[(i + 1) % n]) for i in range(n)]
    meets = any(
        segments_cross(*edges[i], *edges[j])
        for j in range(n)
        for i in range(j - 1)
        if not (i == 0 and j == n - 1)
    )
    assert simple == (not meets)
