"""A controller's state grid tied to a figure: which figure state slot each axis reads, its unit
and its factor to SI. Shared by controller generation and by the runtime."""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np

DEGREE = math.pi / 180.0


def figure_state_names(dynamics: ModuleType) -> tuple[str, ...]:
    """The model's state variables in state order (for a figure: coordinates, then rates)."""
    return tuple(dynamics.STATE_NAMES)


def state_unit(dynamics: ModuleType, name: str) -> tuple[str, float]:
    """Spec unit of a state variable and its factor to SI: ('deg', π/180), ('deg/s', π/180),
    ('m', 1) or ('m/s', 1)."""
    unit = dynamics.STATE_UNITS[figure_state_names(dynamics).index(name)]
    return unit, DEGREE if unit.startswith("deg") else 1.0


def state_limit(dynamics: ModuleType, name: str) -> float | None:
    """The largest magnitude, SI, that a state variable can take, or None where the model sets
    none: a vehicle's road wheels turn within ±STEER_LIMIT rad."""
    if name == "steer" and hasattr(dynamics, "STEER_LIMIT"):
        return float(dynamics.STEER_LIMIT)
    return None


def control_scale(dynamics: ModuleType, name: str) -> float:
    """The spec unit -> SI factor of a control (π/180 for deg/s or deg/s², else 1); a model
    without INPUT_UNITS takes its controls in SI."""
    units = getattr(dynamics, "INPUT_UNITS", None)
    if units is None:
        return 1.0
    return DEGREE if units[tuple(dynamics.INPUT_NAMES).index(name)].startswith("deg") else 1.0


def control_units(dynamics: ModuleType, names: tuple[str, ...]) -> tuple[str, ...] | None:
    """The spec unit of each named control, from the model's ``INPUT_UNITS`` (None for a
    model that does not list them: the table then names them from what it can tell)."""
    units = getattr(dynamics, "INPUT_UNITS", None)
    if units is None:
        return None
    actuators = tuple(dynamics.INPUT_NAMES)
    return tuple(units[actuators.index(name)] for name in names)


@dataclass(frozen=True)
class FigureGrid:
    """A uniform controller grid over some of a figure's state variables, in SI units, ready for
    the kernels. axis_min, axis_step: (d,) float64 SI; axis_count: (d,) int64; wrap: (d,) bool;
    state_slot: (d,) int64 index of each axis in the model's state; scale: (d,) spec unit
    → SI factors; units: the spec units."""

    names: tuple[str, ...]
    units: tuple[str, ...]
    scale: np.ndarray
    axis_min: np.ndarray
    axis_step: np.ndarray
    axis_count: np.ndarray
    wrap: np.ndarray
    state_slot: np.ndarray

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(int(n) for n in self.axis_count)

    @property
    def node_count(self) -> int:
        return int(np.prod(self.axis_count))

    def axis_values(self) -> tuple[np.ndarray, ...]:
        """The node coordinates of each axis, spec units."""
        return tuple(
            (self.axis_min[k] + self.axis_step[k] * np.arange(self.axis_count[k])) / self.scale[k]
            for k in range(len(self.names))
        )


def figure_grid(
    dynamics: ModuleType,
    names: tuple[str, ...],
    minimum: np.ndarray,
    step: np.ndarray,
    count: np.ndarray,
    wrap: np.ndarray,
) -> FigureGrid:
    """Build a FigureGrid from axes given in spec units (names must be figure state variables)."""
    state_names = figure_state_names(dynamics)
    units_and_scales = [state_unit(dynamics, name) for name in names]
    scale = np.array([s for _, s in units_and_scales], dtype=np.float64)
    return FigureGrid(
        names=tuple(names),
        units=tuple(u for u, _ in units_and_scales),
        scale=scale,
        axis_min=np.ascontiguousarray(np.asarray(minimum, dtype=np.float64) * scale),
        axis_step=np.ascontiguousarray(np.asarray(step, dtype=np.float64) * scale),
        axis_count=np.ascontiguousarray(np.asarray(count, dtype=np.int64)),
        wrap=np.ascontiguousarray(np.asarray(wrap, dtype=np.bool_)),
        state_slot=np.array([state_names.index(name) for name in names], dtype=np.int64),
    )
