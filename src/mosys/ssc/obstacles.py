"""The obstacles and domain polygon of a controller spec, checked against the figure and laid out
for the kernels (``kernels.geometry``): states whose body overlaps an obstacle, or whose reference
point lies outside the domain polygon, are removed from the table (the 1990 paper, §6)."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from mosys.kernels.geometry import first_collision, pack_polygons, point_in_polygon
from mosys.parsing.controller import ControllerSpec
from mosys.parsing.tokens import location
from mosys.ssc.grid import FigureGrid, figure_state_names

POSE_NAMES = ("x", "y", "heading")


@dataclass(frozen=True)
class Obstacles:
    """Obstacles in kernel form. pose_slot: (3,) int64 model-state slots of x, y, heading
    (all -1: no obstacles and no domain polygon); outline: (V, 2) the body in its own frame, m;
    vertices (M, 2) and start (K+1,) int64: the obstacles packed (``geometry.pack_polygons``);
    domain: (P, 2), P = 0 for none; names: the obstacles' names."""

    pose_slot: np.ndarray
    outline: np.ndarray
    vertices: np.ndarray
    start: np.ndarray
    domain: np.ndarray
    names: tuple[str, ...]

    @property
    def active(self) -> bool:
        return bool(self.pose_slot[0] >= 0)

    def kernel_arguments(self) -> tuple[np.ndarray, ...]:
        """(pose_slot, outline, obstacle_vertices, obstacle_start, domain), as the kernels take
        them."""
        return self.pose_slot, self.outline, self.vertices, self.start, self.domain

    def polygons(self) -> list[list[list[float]]]:
        """Every obstacle as a list of [x, y] vertices, metres (the table's ``obstacles``)."""
        return [
            self.vertices[self.start[k] : self.start[k + 1]].tolist()
            for k in range(len(self.start) - 1)
        ]

    def collision(self, x: float, y: float, heading: float) -> str | None:
        """The name of the first obstacle the body overlaps at pose (m, m, rad), or None."""
        body = np.empty_like(self.outline)
        hit = first_collision(self.outline, x, y, heading, self.vertices, self.start, body)
        return None if hit < 0 else self.names[hit]

    def in_domain(self, x: float, y: float) -> bool:
        return self.domain.shape[0] == 0 or bool(point_in_polygon(x, y, self.domain))


NO_OBSTACLES = Obstacles(
    pose_slot=np.full(3, -1, dtype=np.int64),
    outline=np.zeros((1, 2)),
    vertices=np.zeros((0, 2)),
    start=np.zeros(1, dtype=np.int64),
    domain=np.zeros((0, 2)),
    names=(),
)


def spec_obstacles(spec: ControllerSpec, dynamics: ModuleType, grid: FigureGrid) -> Obstacles:
    """The spec's ``obstacle`` and ``domain`` lines for ``dynamics``; SpecError naming the line
    when the figure has no body outline, the spec has no ssd for x, y or heading, or an obstacle
    lies beyond the reach of any body whose reference point is in the domain."""
    if not spec.obstacles and spec.domain is None:
        return NO_OBSTACLES
    first = spec.obstacles[0].token if spec.obstacles else spec.domain.token
    if not hasattr(dynamics, "BODY_OUTLINE"):
        raise spec.error(
            first,
            f"obstacle and domain lines only for a figure with a body outline (a vehicle); "
            f"figure '{spec.figure}' has none",
        )
    missing = [name for name in POSE_NAMES if name not in grid.names]
    if missing:
        raise spec.error(
            first, f"ssd lines for x, y and heading with obstacles (no ssd {missing[0]})"
        )
    outline = np.ascontiguousarray(np.array(dynamics.BODY_OUTLINE, dtype=np.float64))
    reach = float(np.hypot(outline[:, 0], outline[:, 1]).max())
    low, high = _reference_box(spec, grid)
    for obstacle in spec.obstacles:
        corners = np.array(obstacle.vertices)
        if np.any(corners.max(axis=0) < low - reach) or np.any(corners.min(axis=0) > high + reach):
            # harmless, and drawn with the scene, but perhaps not where it was meant (it was
            # refused: a scene's rear car moved 0.1 m back stopped the table)
            print(
                f"warning: {location(spec.path, obstacle.token)}: obstacle "
                f"'{obstacle.token.text}' lies beyond the car's reach ({reach:.3g} m) of where "
                f"its reference point can be (the table's axes within the domain: x "
                f"{low[0]:g}..{high[0]:g} m, y {low[1]:g}..{high[1]:g} m): no run can touch it",
                file=sys.stderr,
            )
    names = figure_state_names(dynamics)
    vertices, start = pack_polygons([np.array(o.vertices) for o in spec.obstacles])
    domain = np.zeros((0, 2)) if spec.domain is None else np.array(spec.domain.vertices)
    return Obstacles(
        pose_slot=np.array([names.index(name) for name in POSE_NAMES], dtype=np.int64),
        outline=outline,
        vertices=vertices,
        start=start,
        domain=np.ascontiguousarray(domain, dtype=np.float64),
        names=tuple(o.name for o in spec.obstacles),
    )


def _reference_box(spec: ControllerSpec, grid: FigureGrid) -> tuple[np.ndarray, np.ndarray]:
    """The box (low, high) (2,) m the reference point can occupy: the x and y axes, cut down
    to the domain polygon's bounding box."""
    values = grid.axis_values()
    low = np.array([values[grid.names.index(n)][0] for n in ("x", "y")])
    high = np.array([values[grid.names.index(n)][-1] for n in ("x", "y")])
    if spec.domain is not None:
        polygon = np.array(spec.domain.vertices)
        low = np.maximum(low, polygon.min(axis=0))
        high = np.minimum(high, polygon.max(axis=0))
    return low, high


def blocked_reason(spec: ControllerSpec, obstacles: Obstacles, pose: np.ndarray) -> str:
    """Why a pose (x m, y m, heading rad) is removed: outside the domain polygon, or the name
    and line of the obstacle the body overlaps."""
    x, y, heading = (float(v) for v in pose)
    if not obstacles.in_domain(x, y):
        return f"the reference point ({x:g}, {y:g}) lies outside the domain polygon"
    hit = obstacles.collision(x, y, heading)
    line = next(o.token.line for o in spec.obstacles if o.name == hit)
    return f"the car's outline at ({x:g}, {y:g}) overlaps obstacle '{hit}' (line {line})"
