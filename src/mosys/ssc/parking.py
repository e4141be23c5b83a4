"""Did the car park? The outcome of a car trajectory against its controller's obstacles and
destination (the 1990 paper's §6, with the README's parking targets): no collision at any
instant, and the reference point within ``position_m`` of the destination, the heading within
``heading_deg`` and the speed within ``speed_m_s`` of rest from some instant to the end of the
run."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from mosys.io.car_scene import CarScene, car_scene_attributes, controller_table_scene
from mosys.io.start_grid import StartGrid
from mosys.kernels.geometry import first_colliding_sample, pack_polygons
from mosys.ssc.controller import Controller

TOLERANCE = {"position_m": 0.15, "heading_deg": 5.0, "speed_m_s": 0.05}


@dataclass(frozen=True)
class ParkingOutcome:
    """collision_index: the first sample whose outline overlaps an obstacle (-1: none);
    collided_with: that obstacle's name (""); parked: at rest within tolerance from some
    sample to the end, with no collision; parking_seconds: the time of that sample (nan)."""

    collision_index: int
    collided_with: str
    parked: bool
    parking_seconds: float

    def attributes(self) -> dict:
        return {
            "collision_index": self.collision_index,
            "collided_with": self.collided_with,
            "parked": self.parked,
            "parking_seconds": self.parking_seconds,
            "parking_tolerance": json.dumps(TOLERANCE),
        }


def parking_outcome(
    t: np.ndarray, state: np.ndarray, state_order: tuple[str, ...], scene: CarScene
) -> ParkingOutcome:
    """The outcome of a car run: t (N,) s; state (N, d) spec units in ``state_order`` (x, y m;
    heading deg; speed m/s)."""
    column = {name: state[:, state_order.index(name)] for name in ("x", "y", "heading", "speed")}
    poses = np.ascontiguousarray(
        np.column_stack([column["x"], column["y"], np.radians(column["heading"])])
    )
    vertices, start = pack_polygons(list(scene.obstacles))
    sample, obstacle = first_colliding_sample(poses, scene.body_outline, vertices, start)
    destination = scene.destination
    heading_error = (column["heading"] - destination["heading"] + 180.0) % 360.0 - 180.0
    inside = (
        (
            np.hypot(column["x"] - destination["x"], column["y"] - destination["y"])
            <= TOLERANCE["position_m"]
        )
        & (np.abs(heading_error) <= TOLERANCE["heading_deg"])
        & (np.abs(column["speed"]) <= TOLERANCE["speed_m_s"])
    )
    # the first sample from which every later sample is inside
    outside_after = np.flatnonzero(~inside)
    first_inside = 0 if outside_after.size == 0 else int(outside_after[-1]) + 1
    parked = sample < 0 and first_inside < len(t)
    return ParkingOutcome(
        collision_index=int(sample),
        collided_with=scene.obstacle_names[obstacle] if sample >= 0 else "",
        parked=bool(parked),
        parking_seconds=float(t[first_inside]) if parked else math.nan,
    )


def evaluate_starts(
    controller: Controller, starts: np.ndarray, seconds: float, dt: float
) -> StartGrid:
    """Run ``controller`` (a car's) from every start (n, d) in its state order, spec units, for
    ``seconds`` with step ``dt``, and judge each run (``parking_outcome``)."""
    scene = controller_table_scene(controller.table)
    outcomes = []
    for start in starts:
        run = controller.simulate(controller.figure_state(start), seconds, dt)
        t = dt * np.arange(run.states.shape[0])
        state = controller.controller_states(run.states)
        outcomes.append(parking_outcome(t, state, controller.state_order, scene))
    return StartGrid(
        start=np.asarray(starts, dtype=np.float64),
        state_order=controller.state_order,
        parked=np.array([o.parked for o in outcomes], dtype=np.bool_),
        collided=np.array([o.collision_index >= 0 for o in outcomes], dtype=np.bool_),
        parking_seconds=np.array([o.parking_seconds for o in outcomes]),
        attrs={
            "controller": controller.name,
            "simulated_seconds": float(seconds),
            "dt": float(dt),
            "parking_tolerance": json.dumps(TOLERANCE),
            **car_scene_attributes(scene),
        },
    )
