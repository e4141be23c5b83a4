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

from mosys.errors import InputError
from mosys.io.car_scene import CarScene, car_scene_attributes, controller_table_scene
from mosys.io.progress import Progress
from mosys.io.start_grid import NO_WAY, NOT_FREE, OUTSIDE_DOMAIN, StartGrid, overlap_detail
from mosys.kernels.geometry import (
    first_colliding_sample,
    pack_polygons,
    place_outline,
    point_in_polygon,
    polygons_overlap,
)
from mosys.limits import check_job
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


def classify_starts(controller: Controller, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Why each start (n, d) in the controller's state order, spec units, cannot park at all:
    (n,) str, "" for none, ``NOT_FREE`` or ``NO_WAY``, computed by ``kernels.pose_reach`` (a
    search over poses with the steer axis's largest angle, forward and back); and the length of
    the shortest path it found (n,) m (inf: none; nan: not free)."""
    from mosys.kernels.pose_reach import PoseSearchError, pose_reach

    scene = controller_table_scene(controller.table)
    order = controller.state_order
    if "steer" not in order:  # the search turns the wheels as far as the table's steer axis
        raise InputError(
            f"controller {controller.name}: the pose search needs the table's steer axis (its "
            f"state: {', '.join(order)})"
        )
    poses = starts[:, [order.index(name) for name in ("x", "y", "heading")]].copy()
    poses[:, 2] = np.radians(poses[:, 2])
    destination = scene.destination
    vertices, start = pack_polygons(list(scene.obstacles))
    try:
        reach = pose_reach(
            np.array([destination["x"], destination["y"], math.radians(destination["heading"])]),
            poses,
            scene.body_outline,
            vertices,
            start,
            scene.domain,
            float(controller.table.attrs["wheelbase"]),
            math.radians(float(np.max(np.abs(controller.table.axes[order.index("steer")])))),
        )
    except PoseSearchError as error:  # a lattice too big for memory, a destination not free
        raise InputError(f"controller {controller.name}: the pose search: {error}") from None
    reason = np.where(~reach.free, NOT_FREE, np.where(~reach.reachable, NO_WAY, ""))
    return reason.astype(object), reach.path_length


def not_free_details(
    scene: CarScene, starts: np.ndarray, order: tuple[str, ...], excluded: np.ndarray
) -> np.ndarray:
    """What makes each ``NOT_FREE`` start (n, d) in ``order``, spec units, so: (n,) str,
    ``OUTSIDE_DOMAIN`` where the reference point lies outside the scene's domain, else
    ``overlap_detail`` of every obstacle the body overlaps there (the tests of
    ``geometry.pose_is_free_at``, one by one); "" for the other starts."""
    detail = np.full(len(starts), "", dtype=object)
    body = np.empty_like(scene.body_outline)
    columns = [order.index(name) for name in ("x", "y", "heading")]
    for i in np.flatnonzero(excluded == NOT_FREE):
        x, y, heading = starts[i, columns]
        if scene.domain.shape[0] > 0 and not point_in_polygon(x, y, scene.domain):
            detail[i] = OUTSIDE_DOMAIN
            continue
        place_outline(scene.body_outline, x, y, math.radians(heading), body)
        detail[i] = overlap_detail(
            [
                name
                for name, polygon in zip(scene.obstacle_names, scene.obstacles, strict=True)
                if polygons_overlap(body, polygon)
            ]
        )
    return detail


def evaluate_starts(
    controller: Controller,
    starts: np.ndarray,
    seconds: float,
    dt: float,
    threads: int = 1,
    quiet: bool = False,
) -> StartGrid:
    """Run ``controller`` (a car's) from every start (n, d) in its state order, spec units, for
    ``seconds`` with step ``dt``, and judge each run (``parking_outcome``), ``threads`` runs at
    once, showing progress (runs done, rate and ETA, on stderr) unless ``quiet``. Starts that
    cannot park at all (``classify_starts``) are not run."""
    from concurrent.futures import ThreadPoolExecutor

    starts = np.asarray(starts, dtype=np.float64)
    steps = seconds / dt
    state_size = len(controller.dynamics.STATE_NAMES) + len(controller.state_order)
    run_bytes = steps * 8.0 * (2 * state_size + 8) + controller.run_work_bytes(steps)
    check_job(
        "mosys starts",
        f"{seconds:g} s at dt {dt:g} s per start, {threads} at once",
        steps,
        threads * run_bytes,
    )
    scene = controller_table_scene(controller.table)
    excluded, path_length = classify_starts(controller, starts)

    def outcome(start: np.ndarray) -> ParkingOutcome:
        run = controller.simulate(controller.figure_state(start), seconds, dt)
        t = dt * np.arange(run.states.shape[0])
        state = controller.controller_states(run.states)
        return parking_outcome(t, state, controller.state_order, scene)

    included = np.flatnonzero(excluded == "")
    progress = Progress("starts", included.size, "runs")
    outcomes = {}
    with ThreadPoolExecutor(max_workers=max(1, threads)) as pool:
        for i, run in zip(included, pool.map(outcome, starts[included]), strict=True):
            outcomes[i] = run
            if not quiet:
                progress.update(len(outcomes))
    if not quiet:
        progress.finish(f"({len(starts) - included.size} starts that cannot park not run)")
    skipped = ParkingOutcome(-1, "", False, math.nan)
    runs = [outcomes.get(i, skipped) for i in range(len(starts))]
    return StartGrid(
        start=starts,
        state_order=controller.state_order,
        parked=np.array([o.parked for o in runs], dtype=np.bool_),
        collided=np.array([o.collision_index >= 0 for o in runs], dtype=np.bool_),
        parking_seconds=np.array([o.parking_seconds for o in runs]),
        excluded=excluded,
        excluded_detail=not_free_details(scene, starts, controller.state_order, excluded),
        cost_to_go=np.array([controller.cost_to_go(start) for start in starts]),
        path_length=path_length,
        arrival_cost_to_go=None
        if controller.table.arrival_value is None
        else np.array([controller.arrival_cost_to_go(start) for start in starts]),
        attrs={
            "controller": controller.name,
            "simulated_seconds": float(seconds),
            "dt": float(dt),
            "parking_tolerance": json.dumps(TOLERANCE),
            **car_scene_attributes(scene),
        },
    )
