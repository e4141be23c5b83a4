"""The start-grid result of a car controller (``results/car/start_grid.h5``): which start states
park. Datasets ``start`` (n, d) spec units (columns: root attr ``state_order``), ``parked`` (n,)
bool, ``collided`` (n,) bool, ``parking_seconds`` (n,) float64 (nan: not parked), ``excluded``
(n,) str (why the start cannot park at all, computed; "" for the starts that count and were
run), ``cost_to_go`` (n,) float64 s (the table's, interpolated at the start as the runtime does;
inf: unknown), ``path_length`` (n,) float64 m (the shortest collision-free path the pose search
found; inf: none, nan: the start is not free) and, optionally, ``arrival_cost_to_go`` (n,)
float64 s (the table's cost-to-go to its whole arrival box, ``Controller.arrival_cost_to_go``;
inf: unknown); root attrs ``controller``, ``simulated_seconds``, ``dt`` and the scene
(``io.car_scene``). The success rate counts the starts that are not excluded.

Every dataset also has a ``unit`` (``start`` also ``units``, one per column; booleans ``index``,
``excluded`` ``text``) and the root the provenance attrs (``io.provenance``);
docs/formats/start_grid.md."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from mosys.errors import InputError
from mosys.io.atomic import write_hdf5_atomically
from mosys.io.attributes import (
    INDEX,
    TEXT,
    column_units,
    create_with_unit,
    root_attributes,
    set_column_units,
    string_list,
    string_tuple,
)
from mosys.io.contracts import open_hdf5
from mosys.io.provenance import provenance_attributes
from mosys.parsing import vehicle

STRING = h5py.string_dtype()

NOT_FREE = "start pose overlaps an obstacle or lies outside the domain"  # why a start is
NO_WAY = "no collision-free path to the destination (pose search)"  # excluded (``excluded``)
OUTSIDE_DOMAIN = "reference point outside the domain"  # a NOT_FREE start's ``excluded_detail``
CONSISTENCY_BAND = 0.25  # consistent: |parking time / cost-to-go - 1| <= this (within 25 %)
NOTHING_S = 1e-9  # a parking time and cost-to-go both under this are both none: consistent


def overlap_detail(obstacles: list[str]) -> str:
    """The ``excluded_detail`` of a start pose whose body overlaps the named obstacles (none:
    ``NOT_FREE`` itself, which the pose search's freedom test and this one should not allow)."""
    return "overlaps " + " and ".join(obstacles) if obstacles else NOT_FREE


def consistency_ratios(parking_seconds: np.ndarray, cost_to_go: np.ndarray) -> np.ndarray:
    """Parking time / cost-to-go at the start (both (p,) s) of starts that parked; NaN where the
    table knows no cost-to-go (inf); 1 where both are under ``NOTHING_S`` (a start at the
    destination: nothing promised, nothing taken; 0 / 3e-15 made it inconsistent)."""
    known = np.isfinite(cost_to_go)
    with np.errstate(divide="ignore", invalid="ignore"):  # 0 / 0 at the destination
        ratios = np.where(known, parking_seconds / np.where(known, cost_to_go, 1.0), np.nan)
    return np.where((parking_seconds < NOTHING_S) & (cost_to_go < NOTHING_S), 1.0, ratios)


def consistency_summary(ratios: np.ndarray) -> tuple[float, float, float]:
    """(median, 90th percentile, share within CONSISTENCY_BAND of 1) of parking time /
    cost-to-go ratios (p,); the median and percentile over the finite ratios, the share over
    all (a ratio that is not finite, where the table knows no cost-to-go, is never within the
    band); NaN where there are none."""
    finite = ratios[np.isfinite(ratios)]
    within = float(np.mean(np.abs(ratios - 1.0) <= CONSISTENCY_BAND)) if len(ratios) else np.nan
    if not len(finite):
        return float("nan"), float("nan"), within
    return float(np.median(finite)), float(np.percentile(finite, 90)), within


@dataclass(frozen=True)
class StartGrid:
    """Start states (n, d) spec units in ``state_order`` and their outcomes. state_units: the
    spec unit of each column (``start``'s ``units``); None: the car's (parsing.vehicle) for its
    variables, and a file without them reads as None. excluded_detail: (n,) str, what makes a
    ``NOT_FREE`` start so (``OUTSIDE_DOMAIN`` or ``overlap_detail``), "" for the others; None
    for a file without it (before 2026-12-06)."""

    start: np.ndarray
    state_order: tuple[str, ...]
    parked: np.ndarray
    collided: np.ndarray
    parking_seconds: np.ndarray
    excluded: np.ndarray
    cost_to_go: np.ndarray
    path_length: np.ndarray
    attrs: dict
    state_units: tuple[str, ...] | None = None
    arrival_cost_to_go: np.ndarray | None = None
    excluded_detail: np.ndarray | None = None

    @property
    def counted(self) -> np.ndarray:
        """(n,) bool: the starts that count toward the success rate (not excluded)."""
        return np.asarray(self.excluded == "", dtype=bool)

    @property
    def success_rate(self) -> float:
        """The share of the counted starts that succeeded (NaN: none counted)."""
        counted = self.counted
        return float(self.succeeded[counted].mean()) if counted.any() else float("nan")

    @property
    def succeeded(self) -> np.ndarray:
        """(n,) bool: the counted starts that parked without a collision (a collision never
        counts as parking)."""
        return np.asarray(self.parked & ~self.collided & self.counted, dtype=bool)

    @property
    def consistency(self) -> np.ndarray:
        """(p,) parking time / cost-to-go at the start (both s) of each start that succeeded, in
        grid order: 1 where the run takes as long as the table predicts, NaN where the table
        knows no cost-to-go there (inf)."""
        succeeded = self.succeeded
        return consistency_ratios(self.parking_seconds[succeeded], self.cost_to_go[succeeded])

    @property
    def arrival_consistency(self) -> np.ndarray | None:
        """``consistency`` against the cost-to-go to the whole arrival box; None for a grid
        without ``arrival_cost_to_go``."""
        if self.arrival_cost_to_go is None:
            return None
        succeeded = self.succeeded
        return consistency_ratios(
            self.parking_seconds[succeeded], self.arrival_cost_to_go[succeeded]
        )


def write_start_grid(path: str | Path, grid: StartGrid) -> None:
    """Write a start grid atomically."""

    def fill(h5: h5py.File) -> None:
        start = h5.create_dataset("start", data=np.asarray(grid.start, dtype=np.float64))
        set_column_units(start, start_units(grid))
        create_with_unit(h5, "parked", np.asarray(grid.parked, dtype=np.bool_), INDEX)
        create_with_unit(h5, "collided", np.asarray(grid.collided, dtype=np.bool_), INDEX)
        create_with_unit(h5, "parking_seconds", np.asarray(grid.parking_seconds, float), "s")
        excluded = np.asarray(grid.excluded, dtype=object)
        create_with_unit(h5, "excluded", excluded, TEXT, dtype=STRING)
        create_with_unit(h5, "cost_to_go", np.asarray(grid.cost_to_go, float), "s")
        create_with_unit(h5, "path_length", np.asarray(grid.path_length, float), "m")
        if grid.arrival_cost_to_go is not None:
            arrival = np.asarray(grid.arrival_cost_to_go, float)
            create_with_unit(h5, "arrival_cost_to_go", arrival, "s")
        if grid.excluded_detail is not None:
            detail = np.asarray(grid.excluded_detail, dtype=object)
            create_with_unit(h5, "excluded_detail", detail, TEXT, dtype=STRING)
        h5.attrs["state_order"] = string_list(grid.state_order)
        for key, value in grid.attrs.items():
            h5.attrs[key] = value
        h5.attrs.update(provenance_attributes())  # this process wrote it, whatever was read

    write_hdf5_atomically(path, fill)


def start_units(grid: StartGrid) -> tuple[str, ...] | None:
    """The spec unit of each start column: ``grid.state_units``, else the car's for the car's
    variables (parsing.vehicle), else None (unknown: ``unit`` ``spec``)."""
    if grid.state_units is not None:
        return tuple(grid.state_units)
    units = dict(zip(vehicle.STATE_NAMES, vehicle.STATE_UNITS, strict=True))
    if all(name in units for name in grid.state_order):
        return tuple(units[name] for name in grid.state_order)
    return None


DATASETS = (
    "start",
    "parked",
    "collided",
    "parking_seconds",
    "excluded",
    "cost_to_go",
    "path_length",
)


def _texts(h5: h5py.File, name: str, path: str | Path) -> np.ndarray:
    """The dataset ``name`` (n,) as Python strings; InputError if it does not hold strings."""
    try:
        return h5[name].asstr()[()].astype(object)
    except TypeError:  # h5py: asstr() of a dataset that does not hold strings
        raise InputError(f"{path}: /{name} must hold strings (h5py.string_dtype())") from None


def read_start_grid(path: str | Path) -> StartGrid:
    """Read a start grid written by ``write_start_grid``; InputError naming the file and the
    datasets (or ``state_order``) it lacks, a text dataset that does not hold strings, or that
    it cannot be read (``contracts.open_hdf5``)."""
    with open_hdf5(path) as h5:
        for kind, names, present in (
            ("datasets", DATASETS, h5),
            ("root attributes", ("state_order",), h5.attrs),
        ):
            absent = [name for name in names if name not in present]
            if absent:
                raise InputError(f"{path}: not a start grid ({kind}): missing {', '.join(absent)}")
        return StartGrid(
            start=h5["start"][()],
            state_order=string_tuple(h5.attrs["state_order"]),
            parked=h5["parked"][()],
            collided=h5["collided"][()],
            parking_seconds=h5["parking_seconds"][()],
            excluded=_texts(h5, "excluded", path),
            cost_to_go=h5["cost_to_go"][()],
            path_length=h5["path_length"][()],
            attrs=root_attributes(h5, ("state_order",)),
            state_units=column_units(h5["start"]),
            arrival_cost_to_go=h5["arrival_cost_to_go"][()] if "arrival_cost_to_go" in h5 else None,
            excluded_detail=(
                _texts(h5, "excluded_detail", path) if "excluded_detail" in h5 else None
            ),
        )
