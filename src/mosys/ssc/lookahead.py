"""The lookahead runtime of a vehicle's controller table (``policy lookahead`` in its spec): the
arrays ``kernels.lookahead.simulate_lookahead`` needs, read from the table's attributes."""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from mosys.errors import InputError
from mosys.io.car_scene import controller_table_scene, has_car_scene
from mosys.io.controller_table import ControllerTable
from mosys.kernels.dp import DEAD_END_BOUND
from mosys.kernels.geometry import grown_polygon, pack_polygons
from mosys.ssc.grid import FigureGrid, control_scale, figure_state_names

MAX_SEGMENT_SECONDS = 2.0  # a held sample still in its cell after this long is chosen again
VEHICLE_STATES = ("x", "y", "heading", "steer", "speed")
VEHICLE_INPUTS = ("steer_rate", "wheel_accel")


@dataclass(frozen=True)
class Lookahead:
    """Everything the lookahead kernel takes besides the grid and the state, SI.

    value: (N, 1) cost-to-go, s (a dead end's: ``dp.DEAD_END_BOUND``); known: (N,) finite
    values; minimum_known_weight: the table's ``known_weight`` (0: any); control_samples:
    (U, m) every combination of the table's control samples; pose_slot, outline, obstacle_vertices,
    obstacle_start, domain: the obstacles (``geometry.pose_is_free``; pose_slot -1: none; the
    outline is the body grown by ``kernels.lookahead.CLEARANCE``);
    vehicle_slot: (7,) the state slots of x, y, heading, steer and speed, the input slots of
    steer_rate and wheel_accel; wheelbase and wheel_radius, m; brake: the largest wheel
    deceleration, rad/s²; arrival_box: (3, d) lower, upper and period (> 0: an angle) over the
    controller's axes, SI, of the box around the destination where the vehicle brakes and
    holds; segment_dt: the RK4 step of the lookahead's segments, s (the DP's ``dt``).
    """

    value: np.ndarray
    known: np.ndarray
    minimum_known_weight: float
    control_samples: np.ndarray
    pose_slot: np.ndarray
    outline: np.ndarray
    obstacle_vertices: np.ndarray
    obstacle_start: np.ndarray
    domain: np.ndarray
    vehicle_slot: np.ndarray
    wheelbase: float
    wheel_radius: float
    brake: float
    arrival_box: np.ndarray
    segment_dt: float


@dataclass(frozen=True)
class Arrival:
    """Where a vehicle counts as arrived and how it brakes there, SI: box (3, d) lower, upper
    (±inf where free) and period (> 0: an angle) over the controller's axes; vehicle_slot (7,)
    the state slots of x, y, heading, steer and speed, the input slots of steer_rate and
    wheel_accel; wheelbase and wheel_radius, m; brake: the largest wheel deceleration, rad/s²
    (``kernels.arrival.stops_in_box``)."""

    box: np.ndarray
    vehicle_slot: np.ndarray
    wheelbase: float
    wheel_radius: float
    brake: float


def vehicle_arrival(
    dynamics: ModuleType,
    grid: FigureGrid,
    dest: dict[str, float],
    tolerance: dict[str, float],
    wheel_accel_limit: float,
) -> Arrival:
    """The arrival of a vehicle's lookahead policy: the box of ``tolerance`` (spec units, per
    ``dest`` dimension) around ``dest``, braking at ``wheel_accel_limit`` (spec units: the
    smaller magnitude of the wheel_accel control's range)."""
    names = figure_state_names(dynamics)
    inputs = tuple(dynamics.INPUT_NAMES)
    box = np.zeros((3, len(grid.names)))
    box[0], box[1] = -np.inf, np.inf
    box[2] = np.where(grid.wrap, grid.axis_count * grid.axis_step, 0.0)
    for k, name in enumerate(grid.names):
        if name in tolerance:
            centre = dest[name] * grid.scale[k]
            box[0, k] = centre - tolerance[name] * grid.scale[k]
            box[1, k] = centre + tolerance[name] * grid.scale[k]
    return Arrival(
        box=box,
        vehicle_slot=np.array(
            [names.index(n) for n in VEHICLE_STATES] + [inputs.index(n) for n in VEHICLE_INPUTS],
            dtype=np.int64,
        ),
        wheelbase=float(dynamics.WHEELBASE),
        wheel_radius=float(dynamics.WHEEL_RADIUS),
        brake=float(wheel_accel_limit * control_scale(dynamics, "wheel_accel")),
    )


def lookahead_runtime(table: ControllerTable, dynamics: ModuleType, grid: FigureGrid) -> Lookahead:
    """The lookahead arrays of a table whose attrs say ``policy`` = ``lookahead``."""
    from mosys.kernels.lookahead import CLEARANCE  # here: importing it compiles the runtime

    attrs = table.attrs
    names = figure_state_names(dynamics)
    counts = np.atleast_1d(np.asarray(attrs["control_samples"], dtype=np.int64))
    axes = [
        np.linspace(low, high, int(n))
        for low, high, n in zip(table.control_min, table.control_max, counts, strict=True)
    ]
    scale = np.array([control_scale(dynamics, n) for n in table.control_names])
    samples = np.array(list(itertools.product(*axes)), dtype=np.float64) * scale
    pose_slot = np.array([names.index(n) for n in ("x", "y", "heading")], dtype=np.int64)
    if has_car_scene(attrs):
        scene = controller_table_scene(table)
        try:
            outline = grown_polygon(scene.body_outline, CLEARANCE)
        except ValueError:
            raise InputError(
                f"controller table of {table.figure}: the lookahead runtime needs a convex"
                f" body_outline, got {scene.body_outline.tolist()}"
            ) from None
        domain = scene.domain
        vertices, start = pack_polygons(list(scene.obstacles))
    else:  # no obstacles and no domain polygon: every pose is free
        pose_slot[:] = -1
        outline, domain = np.zeros((1, 2)), np.zeros((0, 2))
        vertices, start = pack_polygons([])
    brake_control = table.control_names.index("wheel_accel")
    arrival = vehicle_arrival(
        dynamics,
        grid,
        table.dest,
        json.loads(attrs["arrival_tolerance"]),
        min(abs(table.control_min[brake_control]), abs(table.control_max[brake_control])),
    )
    value = table.value.reshape(-1)
    if table.dead_end is not None:  # dead ends cost the DP's bound, as in the DP
        value = np.where(table.dead_end.reshape(-1), DEAD_END_BOUND, value)
    return Lookahead(
        value=np.ascontiguousarray(value[:, None]),
        known=np.ascontiguousarray(np.isfinite(value)),
        minimum_known_weight=float(attrs.get("minimum_known_weight", 0.0)),
        control_samples=np.ascontiguousarray(samples),
        pose_slot=pose_slot,
        outline=outline,
        obstacle_vertices=vertices,
        obstacle_start=start,
        domain=domain,
        vehicle_slot=arrival.vehicle_slot,
        wheelbase=arrival.wheelbase,
        wheel_radius=arrival.wheel_radius,
        brake=arrival.brake,
        arrival_box=arrival.box,
        segment_dt=float(attrs["dt"]),
    )
