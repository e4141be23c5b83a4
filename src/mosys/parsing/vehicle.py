"""The built-in vehicle of a figure spec (``.fig``): the car of the 1990 paper's §6.

A figure spec whose first line is ``vehicle`` describes a car instead of a tree of rods::

    vehicle wheelbase=2.5 length=4.0 width=1.7 front_overhang=0.8 wheel_radius=0.3 steer_limit=35

Lengths in metres, ``steer_limit`` in degrees (radians in the parsed ``Vehicle``). The state
variables (``x``, ``y``, ``heading``, ``steer``, ``speed``) and controls (``steer_rate``,
``wheel_accel``) are fixed by the data contract; the equations are in the README.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from mosys.parsing.tokens import (
    Line,
    SpecError,
    Token,
    format_number,
    parse_number,
    value_token,
)

STATE_NAMES = ("x", "y", "heading", "steer", "speed")
STATE_UNITS = ("m", "m", "deg", "deg", "m/s")
INPUT_NAMES = ("steer_rate", "wheel_accel")
INPUT_UNITS = ("deg/s", "deg/s^2")

_OPTIONS = {
    "wheelbase": "the distance from the rear axle to the front axle in metres",
    "length": "the body's length in metres",
    "width": "the body's width in metres",
    "front_overhang": "the distance from the front axle to the front bumper in metres",
    "wheel_radius": "the front wheels' radius in metres",
    "steer_limit": "the largest steering angle of the road wheels in degrees",
}
LENGTH_RANGE = (1e-6, 1e6)  # m: every length option (the car's equations divide by them)


@dataclass(frozen=True)
class Vehicle:
    """A car with front-wheel steering, its reference point midway between the front wheels.

    ``wheelbase``, ``length``, ``width``, ``front_overhang``, ``wheel_radius``: metres;
    ``steer_limit``: radians, the road wheels turn within ±steer_limit."""

    path: str
    wheelbase: float
    length: float
    width: float
    front_overhang: float
    wheel_radius: float
    steer_limit: float
    spec_sha256: str
    token: Token = field(compare=False, repr=False)

    @property
    def name(self) -> str:
        return Path(self.path).stem

    @property
    def body_outline(self) -> tuple[tuple[float, float], ...]:
        """The body's corners (x, y) in metres in the car's frame (reference point at the
        origin, heading along +x), counter-clockwise from the front right."""
        front = self.front_overhang
        rear = self.front_overhang - self.length
        half = self.width / 2.0
        return ((front, -half), (front, half), (rear, half), (rear, -half))


def is_vehicle_spec(lines: list[Line]) -> bool:
    """True when the spec's first line is a ``vehicle`` line."""
    return bool(lines) and lines[0].keyword.text == "vehicle"


def parse_vehicle(lines: list[Line], path: str, spec_sha256: str) -> Vehicle:
    """Parse the lines of a vehicle spec (the first is its ``vehicle`` line)."""
    line = lines[0]
    if len(lines) > 1:
        extra = lines[1].keyword
        raise SpecError.at(path, extra, "end of file (a vehicle spec has one 'vehicle' line)")
    reader = line.reader()
    found = reader.key_values(_OPTIONS)
    values: dict[str, float] = {}
    for key, description in _OPTIONS.items():
        if key not in found:
            raise SpecError(path, line.number, line.end_column, f"'{key}=' ({description})", None)
        token = value_token(found[key][0], key)
        value = parse_number(token, path, key)
        if not value > 0 or not math.isfinite(value):
            raise SpecError.at(path, token, f"a number > 0 for {key}")
        low, high = LENGTH_RANGE
        if key != "steer_limit" and not low <= value <= high:
            raise SpecError.at(path, token, f"a number from {low:g} to {high:g} for {key}")
        values[key] = value
    if values["wheelbase"] + values["front_overhang"] > values["length"]:
        token = value_token(found["length"][0], "length")
        raise SpecError.at(
            path,
            token,
            f"a length >= wheelbase + front_overhang "
            f"({values['wheelbase'] + values['front_overhang']:g} m: the rear axle lies inside "
            "the body)",
        )
    if values["steer_limit"] >= 90:
        raise SpecError.at(
            path, value_token(found["steer_limit"][0], "steer_limit"), "a steer_limit below 90"
        )
    return Vehicle(
        path=path,
        wheelbase=values["wheelbase"],
        length=values["length"],
        width=values["width"],
        front_overhang=values["front_overhang"],
        wheel_radius=values["wheel_radius"],
        steer_limit=math.radians(values["steer_limit"]),
        spec_sha256=spec_sha256,
        token=line.keyword,
    )


def render_vehicle_spec(vehicle: Vehicle) -> str:
    """Spec text that parses back to ``vehicle`` (``steer_limit`` round-trips through degrees)."""
    lengths = " ".join(
        f"{key}={format_number(getattr(vehicle, key))}" for key in _OPTIONS if key != "steer_limit"
    )
    steer_limit = format_number(math.degrees(vehicle.steer_limit))
    return f"vehicle {lengths} steer_limit={steer_limit}\n"
