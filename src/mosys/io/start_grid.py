"""The start-grid result of a car controller (``results/car/start_grid.h5``): which start states
park. Datasets ``start`` (n, d) spec units (columns: root attr ``state_order``), ``parked`` (n,)
bool, ``collided`` (n,) bool, ``parking_seconds`` (n,) float64 (nan: not parked); root attrs
``controller``, ``simulated_seconds``, ``dt`` and the scene (``io.car_scene``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from mosys.errors import InputError
from mosys.io.atomic import write_atomically
from mosys.io.attributes import string_tuple


@dataclass(frozen=True)
class StartGrid:
    """Start states (n, d) spec units in ``state_order`` and their outcomes."""

    start: np.ndarray
    state_order: tuple[str, ...]
    parked: np.ndarray
    collided: np.ndarray
    parking_seconds: np.ndarray
    attrs: dict

    @property
    def success_rate(self) -> float:
        return float(self.parked.mean()) if self.parked.size else float("nan")


def write_start_grid(path: str | Path, grid: StartGrid) -> None:
    """Write a start grid atomically."""

    def write(partial: Path) -> None:
        with h5py.File(partial, "w") as h5:
            h5.create_dataset("start", data=np.asarray(grid.start, dtype=np.float64))
            h5.create_dataset("parked", data=np.asarray(grid.parked, dtype=np.bool_))
            h5.create_dataset("collided", data=np.asarray(grid.collided, dtype=np.bool_))
            h5.create_dataset("parking_seconds", data=np.asarray(grid.parking_seconds, float))
            h5.attrs["state_order"] = list(grid.state_order)
            for key, value in grid.attrs.items():
                h5.attrs[key] = value

    write_atomically(path, write)


DATASETS = ("start", "parked", "collided", "parking_seconds")


def read_start_grid(path: str | Path) -> StartGrid:
    """Read a start grid written by ``write_start_grid``; InputError naming the file and the
    datasets (or ``state_order``) it lacks."""
    with h5py.File(path, "r") as h5:
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
            attrs={k: h5.attrs[k] for k in h5.attrs if k != "state_order"},
        )
