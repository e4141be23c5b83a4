"""The car's scene: the root attributes that carry a car controller's world from its controller
table to the trajectories and start grid made with it, and from those to the plots.

A car controller table's root holds ``body_outline``, ``obstacles`` (JSON), ``obstacle_names``,
``wheelbase`` and ``domain`` (JSON), its destination being the table's ``dest``. A trajectory's
or start grid's root holds ``body_outline``, ``obstacles``, ``obstacle_names``, ``wheelbase`` and
``destination`` (JSON ``{"x": m, "y": m, "heading": deg}``), written by ``car_scene_attributes``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from mosys.errors import InputError
from mosys.io.attributes import string_attr, string_list, string_tuple
from mosys.io.controller_table import ControllerTable

DESTINATION_KEYS = ("x", "y", "heading")


@dataclass(frozen=True)
class CarScene:
    """A car's world. body_outline: (V, 2) m in the car's frame (reference point at the origin,
    heading along +x); obstacles: one (V_k, 2) m polygon each, named by obstacle_names;
    destination: the goal pose, x and y (m), heading (deg); wheelbase: m (NaN where the file
    records none); domain: (D, 2) m, the polygon the reference point must stay in ((0, 2): none)."""

    body_outline: np.ndarray
    obstacles: tuple[np.ndarray, ...]
    obstacle_names: tuple[str, ...]
    destination: dict[str, float]
    wheelbase: float
    domain: np.ndarray


def has_car_scene(attrs: Mapping) -> bool:
    """Whether root attributes carry a scene (a vehicle without obstacles has none)."""
    return "body_outline" in attrs


def read_car_scene(attrs: Mapping, where: str, destination: Mapping | None = None) -> CarScene:
    """The scene in a file's root attributes; ``destination``: the goal pose when the file
    stores it elsewhere (a controller table's ``dest``), else the ``destination`` attribute.
    InputError naming ``where`` (the file) for a missing or malformed attribute."""
    outline = _polygon(where, "body_outline", _json_attr(attrs, where, "body_outline"))
    polygons = _json_attr(attrs, where, "obstacles")
    if not isinstance(polygons, list):
        raise InputError(f"{where}: obstacles must be a list of polygons, got {polygons!r}")
    names = string_tuple(attrs["obstacle_names"]) if len(polygons) else ()
    if len(names) != len(polygons):
        raise InputError(
            f"{where}: {len(polygons)} obstacles but {len(names)} obstacle_names {list(names)}"
        )
    obstacles = tuple(
        _polygon(where, f"obstacle {name}", vertices)
        for name, vertices in zip(names, polygons, strict=True)
    )
    if destination is None:
        destination = _json_attr(attrs, where, "destination")
    try:
        goal = {key: float(destination[key]) for key in DESTINATION_KEYS}
    except (KeyError, TypeError, ValueError):
        raise InputError(
            f'{where}: destination must be {{"x": m, "y": m, "heading": deg}}, got {destination!r}'
        ) from None
    domain = json.loads(string_attr(attrs["domain"])) if "domain" in attrs else []
    return CarScene(
        body_outline=outline,
        obstacles=obstacles,
        obstacle_names=names,
        destination=goal,
        wheelbase=float(attrs["wheelbase"]) if "wheelbase" in attrs else math.nan,
        domain=np.ascontiguousarray(domain, dtype=np.float64).reshape(-1, 2),
    )


def controller_table_scene(table: ControllerTable) -> CarScene:
    """The scene of a car controller table, its destination the table's ``dest``."""
    return read_car_scene(table.attrs, f"controller table of {table.figure}", table.dest)


def car_scene_attributes(scene: CarScene) -> dict:
    """The root attributes a trajectory or start grid stores its scene in; the domain only where
    there is one (the plots draw it, as Figure 17's dashed region; until 2026-12-05 it was left
    out, and starts outside it read as starts in the open street that cannot park)."""
    attributes = {
        "body_outline": json.dumps(scene.body_outline.tolist()),
        "obstacles": json.dumps([polygon.tolist() for polygon in scene.obstacles]),
        "obstacle_names": string_list(scene.obstacle_names),
        "destination": json.dumps(scene.destination),
        "wheelbase": scene.wheelbase,
    }
    if len(scene.domain):
        attributes["domain"] = json.dumps(scene.domain.tolist())
    return attributes


def _json_attr(attrs: Mapping, where: str, name: str):
    if name not in attrs:
        raise InputError(f"{where}: not a car scene (root attributes): missing {name}")
    try:
        return json.loads(string_attr(attrs[name]))
    except json.JSONDecodeError as error:
        raise InputError(f"{where}: root attribute {name} is not valid JSON ({error})") from None


def _polygon(where: str, name: str, vertices) -> np.ndarray:
    try:
        polygon = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError):
        polygon = None
    if polygon is None or polygon.ndim != 2 or polygon.shape[1] != 2 or len(polygon) < 3:
        raise InputError(
            f"{where}: {name} must be a list of at least 3 [x, y] vertices, got {vertices!r}"
        )
    if not np.all(np.isfinite(polygon)):
        raise InputError(f"{where}: {name} has a non-finite vertex")
    return np.ascontiguousarray(polygon)
