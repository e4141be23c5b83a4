"""The reachability search (kernels.pose_reach): path lengths in free space, a box the car cannot
turn around in against the same box opened, the real parking scene, the probe from a query whose
cell was not reached, determinism, and the size check before any allocation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import SPECS

from mosys.kernels.geometry import pack_polygons
from mosys.kernels.pose_reach import PoseReach, pose_reach
from mosys.parsing.controller import parse_controller_spec
from mosys.parsing.figure import parse_figure_spec

CAR = parse_figure_spec(SPECS / "figures" / "car.fig")
OUTLINE = np.array(CAR.body_outline)  # front bumper +0.8 m, rear -3.2 m, half width 0.85 m
NO_OBSTACLES = pack_polygons([])


def square(low: float, high: float) -> np.ndarray:
    return np.array([[low, low], [high, low], [high, high], [low, high]], dtype=float)


def reach(destination, queries, obstacles, domain, **options) -> PoseReach:
    return pose_reach(
        np.asarray(destination, dtype=float),
        np.asarray(queries, dtype=float),
        OUTLINE,
        *obstacles,
        domain,
        CAR.wheelbase,
        CAR.steer_limit,
        **options,
    )


@pytest.fixture(scope="module")
def parking():
    """(destination, obstacles, domain) of specs/controllers/car/park.ssc."""
    spec = parse_controller_spec(SPECS / "controllers" / "car" / "park.ssc")
    dest = spec.destination_values()
    destination = np.array([dest["x"], dest["y"], math.radians(dest["heading"])])
    assert destination.tolist() == [0.0, 1.15, 0.0]
    assert [o.name for o in spec.obstacles] == ["curb", "rear_car", "front_car"]
    obstacles = pack_polygons([np.array(o.vertices) for o in spec.obstacles])
    return destination, obstacles, np.array(spec.domain.vertices)


def drive(pose: list[float], steer: float, s: float) -> list[float]:
    """The pose (x m, y m, heading rad) after the front wheels roll s m (negative: backward) at
    a constant steer (rad): the vehicle's equations, by RK4 in 1 mm steps."""

    def rate(p: np.ndarray) -> np.ndarray:
        return np.array(
            [math.cos(p[2] + steer), math.sin(p[2] + steer), math.sin(steer) / CAR.wheelbase]
        )

    p = np.array(pose, dtype=float)
    n = round(abs(s) / 0.001)
    h = s / n
    for _ in range(n):
        k1 = rate(p)
        k2 = rate(p + h / 2 * k1)
        k3 = rate(p + h / 2 * k2)
        k4 = rate(p + h * k3)
        p = p + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return p.tolist()


def test_free_space_path_lengths_and_every_free_pose_reachable():
    rng = np.random.default_rng(1)
    scattered = np.column_stack(
        [rng.uniform(-2.9, 2.9, (200, 2)), rng.uniform(-math.pi, math.pi, 200)]
    )
    one_step = [  # where one primitive from the destination ends
        drive([0.0, 0.0, 0.0], CAR.steer_limit, 0.15),
        drive([0.0, 0.0, 0.0], -CAR.steer_limit, -0.15),
        [0.15, 0.0, 0.0],
    ]
    special = [[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-0.3, 0.0, 0.0], *one_step]
    result = reach([0.0, 0.0, 0.0], special + scattered.tolist(), NO_OBSTACLES, square(-3, 3))
    assert abs(result.path_length[0] - 2.0) <= 2 * 0.15
    # 0.3 m straight back: 2 steps, no fewer can cover it
    assert result.path_length[1:6].tolist() == [0.0, 0.3, 0.15, 0.15, 0.15]
    assert result.free.all()
    assert result.reachable.all()
    assert np.isfinite(result.path_length).all()


def box_walls(open_right: bool) -> tuple[np.ndarray, np.ndarray]:
    """Walls 0.2 m thick around x 0..6 m, y 0..2.2 m; open_right: no wall at x = 6 m."""
    walls = [
        [[-0.2, -0.2], [6.2, -0.2], [6.2, 0.0], [-0.2, 0.0]],
        [[-0.2, 2.2], [6.2, 2.2], [6.2, 2.4], [-0.2, 2.4]],
        [[-0.2, 0.0], [0.0, 0.0], [0.0, 2.2], [-0.2, 2.2]],
        [[6.0, 0.0], [6.2, 0.0], [6.2, 2.2], [6.0, 2.2]],
    ]
    return pack_polygons([np.array(w) for w in walls[: 3 if open_right else 4]])


@pytest.mark.parametrize("open_right", [False, True])
def test_turning_around_in_a_closed_box_is_impossible_and_possible_once_opened(open_right):
    # The box is 2.2 m wide, the car 4.0 m long: to turn from heading 0 to heading pi it must
    # pass heading ±pi/2, where it spans 4 m in y, so in the closed box no path exists at all.
    # Opened, it can drive out into the 7 m x 10 m beyond, turn there and come back in.
    domain = np.array([[-1.0, -4.0], [13.0, -4.0], [13.0, 6.4], [-1.0, 6.4]])
    queries = [[2.0, 1.1, math.pi], [5.0, 1.1, 0.0], [3.0, 1.1, math.pi / 2]]
    result = reach(
        [4.5, 1.1, 0.0], queries, box_walls(open_right), domain, cell=0.1, heading_cells=72
    )
    assert result.free.tolist() == [True, True, False]
    assert result.reachable.tolist() == [open_right, True, False]
    assert np.isnan(result.path_length[2])
    if open_right:  # the heading turns at most sin(steer_max) / wheelbase rad per metre
        turn = math.pi - math.radians(2.5)  # the query's cell's pose: <= half a bin off
        assert result.path_length[0] >= turn * CAR.wheelbase / math.sin(CAR.steer_limit)
    else:
        assert result.path_length[0] == np.inf
        assert result.cells_reached <= 61 * 23 * 72  # the box's cells, at most


def test_the_parking_scene(parking):
    destination, obstacles, domain = parking
    queries = [
        [3.0, 3.0, 0.0],  # in the lane beside the space
        [4.0, 1.15, 0.0],  # the body overlaps the front car
        [0.0, 1.15, 0.0],  # the destination itself
        [0.0, 1.15, math.radians(10.0)],  # the rear wheel over the curb (park.ssc)
        [0.0, 4.2, 0.0],  # the reference point outside the domain
        HOLE,
    ]
    result = reach(destination, queries, obstacles, domain)
    assert 4.0 <= result.path_length[0] <= 20.0
    assert result.free.tolist() == [True, False, True, False, False, True]
    assert result.reachable.tolist() == [True, False, True, False, False, True]
    assert np.isnan(result.path_length[[1, 3, 4]]).all()
    assert result.path_length[2] == 0.0


# A free pose in the open lane whose lattice cell the search leaves unreached (a cell holds one
# pose, so scattered cells of free space are never landed in); one primitive from the pose
# itself lands in a reached cell.
HOLE = [0.75, 3.15, math.radians(40.0)]
BOX = np.array([[-2.25, 0.5], [8.0, 0.5], [8.0, 4.0], [-2.25, 4.0]])  # a domain of known size


def test_a_probe_from_the_query_fills_a_hole_of_the_lattice(parking):
    destination, obstacles, _ = parking
    # HOLE is a hole of the lattice over BOX (its origin and extent)
    result = reach(destination, [[3.0, 3.0, 0.0], HOLE], obstacles, BOX, probe_levels=0)
    assert result.free.tolist() == [True, True]
    assert result.reachable.tolist() == [True, False]
    assert 4.0 <= result.path_length[0] <= 20.0


def test_the_same_inputs_give_the_same_answer(parking):
    destination, obstacles, domain = parking
    rng = np.random.default_rng(2)
    queries = np.column_stack(
        [rng.uniform(-2.25, 8.0, 300), rng.uniform(0.5, 4.0, 300), rng.uniform(-1.0, 1.0, 300)]
    )
    first = reach(destination, queries, obstacles, domain, cell=0.1, heading_cells=72)
    again = reach(destination, queries, obstacles, domain, cell=0.1, heading_cells=72)
    assert first.path_length.tobytes() == again.path_length.tobytes()
    assert np.array_equal(first.free, again.free)
    assert first.cells_reached == again.cells_reached
    assert first.reachable.any() and not first.reachable.all()


def test_a_lattice_too_big_is_refused_before_allocating(parking):
    destination, obstacles, domain = parking
    # 1e-5 m cells: 1.025e6 x 3.5e5 x 144 cells, some 2e15 bytes: allocating would fail
    with pytest.raises(ValueError, match=r"would take \d+ bytes \(\d+ cells requested") as error:
        reach(destination, [[3.0, 3.0, 0.0]], obstacles, domain, cell=1e-5, max_bytes=10**6)
    assert "max_bytes 1000000" in str(error.value)
    # the defaults over BOX: 205 x 70 x 144 cells of 40 bytes
    with pytest.raises(ValueError, match=r"would take 82656000 bytes \(2066400 cells requested"):
        reach(destination, [[3.0, 3.0, 0.0]], obstacles, BOX, max_bytes=82655999)


def test_a_destination_that_is_not_free_is_refused(parking):
    _, obstacles, domain = parking
    with pytest.raises(ValueError, match="destination .* is not free"):
        reach([4.0, 1.15, 0.0], [[3.0, 3.0, 0.0]], obstacles, domain)
