"""Boxes over a figure's state (spec units in, SI out): the state-space breakpoints of scripts
(paper §3.1) and the arrival box that ends ``sim ... until=dest``."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from mosys.kernels.regions import region_membership
from mosys.ssc.grid import figure_state_names, state_unit

# a figure at rest: every rate of the figure below this, SI (m/s, rad/s)
REST_RATE = 0.01
# arrival: each controller dimension within this fraction of its grid step of the destination
ARRIVAL_STEPS = 0.02

Bounds = Mapping[str, tuple[float, float]]  # state variable -> (low, high), spec units


@dataclass(frozen=True)
class Regions:
    """K boxes over a model's state of S entries, SI: lower, upper (K, S) (±inf: unbounded);
    period (S,) 2π for angle coordinates (compared modulo it when both bounds are finite)."""

    lower: np.ndarray
    upper: np.ndarray
    period: np.ndarray

    def __len__(self) -> int:
        return self.lower.shape[0]

    def membership(self, state: np.ndarray) -> np.ndarray:
        """(K,) bool: whether ``state`` (S,) SI lies in each box."""
        out = np.empty(len(self), dtype=np.bool_)
        region_membership(np.ascontiguousarray(state), self.lower, self.upper, self.period, out)
        return out

    def without(self, k: int) -> Regions:
        """These boxes but the k-th."""
        return Regions(
            np.delete(self.lower, k, axis=0), np.delete(self.upper, k, axis=0), self.period
        )

    def joined(self, other: Regions) -> Regions:
        """These boxes, then ``other``'s (over the same state)."""
        return Regions(
            np.concatenate((self.lower, other.lower)),
            np.concatenate((self.upper, other.upper)),
            self.period,
        )


def state_periods(dynamics: ModuleType) -> np.ndarray:
    """(S,) 2π for each angle coordinate of the model, 0 for every other state variable."""
    names = figure_state_names(dynamics)
    is_angle = getattr(dynamics, "Q_IS_ANGLE", ())
    period = np.zeros(len(names))
    period[: len(is_angle)] = np.where(np.array(is_angle, dtype=bool), 2.0 * math.pi, 0.0)
    return period


def regions(dynamics: ModuleType, boxes: Iterable[Bounds]) -> Regions:
    """Regions from boxes given as {state variable: (low, high)} in spec units; variables a box
    does not name are unbounded. ValueError for a name the model does not have."""
    names = figure_state_names(dynamics)
    rows = list(boxes)
    lower = np.full((len(rows), len(names)), -np.inf)
    upper = np.full((len(rows), len(names)), np.inf)
    for k, box in enumerate(rows):
        for name, (low, high) in box.items():
            slot = names.index(name)
            scale = state_unit(dynamics, name)[1]
            lower[k, slot], upper[k, slot] = low * scale, high * scale
    return Regions(lower, upper, state_periods(dynamics))
