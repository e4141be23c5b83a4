"""The controller table contract (DESIGN.md, ``results/controllers/F/C.h5``): write and read.

Beyond the contract (docs/formats/controller_table.md): every dataset has a ``unit``
(``/torque`` also ``units``, one per control); each ``/axes/<name>`` is an HDF5 dimension scale
named ``<name>``, attached to ``/value``, ``/torque``, ``/dead_end``, ``/destination_index``
and ``/arrival_value`` along its state dimension (labelled ``<name>``; ``/torque``'s last
dimension is labelled ``control``); the root carries the provenance attrs (``io.provenance``)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from mosys.io.atomic import write_hdf5_atomically
from mosys.io.attributes import (
    INDEX,
    column_units,
    create_with_unit,
    root_attributes,
    set_column_units,
    string_list,
    string_tuple,
)
from mosys.io.contracts import open_contract
from mosys.io.provenance import provenance_attributes
from mosys.parsing.vehicle import INPUT_NAMES as VEHICLE_CONTROLS
from mosys.parsing.vehicle import INPUT_UNITS as VEHICLE_CONTROL_UNITS

FORMAT_VERSION = 1


@dataclass(frozen=True)
class ControllerTable:
    """A state-space controller as stored on disk; spec units throughout.

    axes: one (n_k,) float64 grid per state dimension, in ``state_order``; axis_units: 'deg',
    'deg/s', 'm' or 'm/s'; wrap: periodic axes (period n_k * step). torque: (n_1, ..., n_d, m)
    float64, N·m or N; value: (n_1, ..., n_d) cost-to-go, s (inf: destination unreachable).
    attrs: every other root attribute (figure, dest, K, timings, ...), as read. dead_end:
    (n_1, ..., n_d) bool, dataset ``/dead_end``, for a spec with ``known_weight`` (None
    otherwise): the free nodes whose value is inf because no trusted exit leads on from them
    (``ssc.solution``), not because they cannot be reached.

    Several destinations (a spec with two or more ``dest`` lines; None for one, and a file
    without them reads as None): ``destinations``, root attr ``destinations``, one {name:
    value} per ``dest`` line in file order (``dest`` is the first), spec units; and
    ``destination_index`` (n_1, ..., n_d) int64, dataset ``/destination_index``: the index into
    ``destinations`` of the destination the node's optimal path ends at, -1 where the value is
    inf (``kernels.dp_destinations.destination_indices`` says how it is found).

    arrival_value: (n_1, ..., n_d) s, dataset ``/arrival_value``, for a ``policy lookahead``
    table whose policy line has ``arrival_value`` (None otherwise, and a file without it reads
    as None): the cost-to-go to the whole arrival box, the arrival the lookahead runtime brakes
    into, inf where unreachable or a dead end; ``value`` is the DP's to that box scaled by root
    attr ``arrival_aim`` (the same where the aim is 1), which the runtime descends (README, "The
    self-parking car").

    control_units: the spec unit of each control ('N*m' for a hinge actuator, 'deg/s' and
    'deg/s^2' for the car's), written as ``/torque``'s ``units``; None: the writer infers them
    (``torque_units``), and a file without them reads as None.
    """

    state_order: tuple[str, ...]
    control_names: tuple[str, ...]
    axes: tuple[np.ndarray, ...]
    axis_units: tuple[str, ...]
    wrap: tuple[bool, ...]
    torque: np.ndarray
    value: np.ndarray
    control_min: np.ndarray
    control_max: np.ndarray
    effort_weight: np.ndarray
    dest: dict[str, float]
    figure: str
    attrs: dict
    dead_end: np.ndarray | None = None
    destinations: tuple[dict[str, float], ...] | None = None
    destination_index: np.ndarray | None = None
    control_units: tuple[str, ...] | None = None
    arrival_value: np.ndarray | None = None

    @property
    def all_destinations(self) -> tuple[dict[str, float], ...]:
        """Every destination, {name: value} in spec units: ``destinations``, or ``(dest,)``
        for a table with one."""
        return self.destinations if self.destinations is not None else (self.dest,)


def write_controller_table(path: str | Path, table: ControllerTable) -> None:
    """Write ``table`` to ``path`` atomically (a hidden partial file, then a rename).
    ValueError when only one of ``destinations`` and ``destination_index`` is given."""
    if (table.destinations is None) != (table.destination_index is None):
        raise ValueError(
            "a table with several destinations needs both destinations and destination_index"
        )

    def fill(h5: h5py.File) -> None:
        axes = h5.create_group("axes")
        for name, axis, unit, wrap in zip(
            table.state_order, table.axes, table.axis_units, table.wrap, strict=True
        ):
            scale = create_with_unit(axes, name, np.asarray(axis, dtype=np.float64), unit)
            scale.attrs["wrap"] = bool(wrap)
            scale.make_scale(name)
        torque = h5.create_dataset("torque", data=table.torque.astype(np.float64))
        set_column_units(torque, torque_units(table))
        torque.dims[len(table.state_order)].label = "control"
        per_node = [torque, create_with_unit(h5, "value", table.value.astype(float), "s")]
        if table.dead_end is not None:
            dead_end = np.asarray(table.dead_end, dtype=np.bool_)
            per_node.append(create_with_unit(h5, "dead_end", dead_end, INDEX))
        if table.destination_index is not None:
            index = np.asarray(table.destination_index, dtype=np.int64)
            per_node.append(create_with_unit(h5, "destination_index", index, INDEX))
        if table.arrival_value is not None:
            arrival = np.asarray(table.arrival_value, dtype=np.float64)
            per_node.append(create_with_unit(h5, "arrival_value", arrival, "s"))
        for dataset in per_node:
            for k, name in enumerate(table.state_order):
                dataset.dims[k].attach_scale(axes[name])
                dataset.dims[k].label = name
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["state_order"] = string_list(table.state_order)
        h5.attrs["control_names"] = string_list(table.control_names)
        h5.attrs["control_min"] = np.asarray(table.control_min, dtype=np.float64)
        h5.attrs["control_max"] = np.asarray(table.control_max, dtype=np.float64)
        h5.attrs["K"] = np.asarray(table.effort_weight, dtype=np.float64)
        h5.attrs["dest"] = json.dumps(table.dest)
        if table.destinations is not None:
            h5.attrs["destinations"] = json.dumps(list(table.destinations))
        h5.attrs["figure"] = table.figure
        for key, value in table.attrs.items():
            h5.attrs[key] = value
        h5.attrs.update(provenance_attributes())  # this process wrote it, whatever was read

    write_hdf5_atomically(path, fill)


def torque_units(table: ControllerTable) -> tuple[str, ...]:
    """The spec unit of each control: ``table.control_units`` when given; else the car's
    (parsing.vehicle) for a vehicle's table (root attr ``wheelbase``), and N*m for an
    articulated figure's (its controls are hinge actuators: a figure spec actuates only
    hinges)."""
    if table.control_units is not None:
        return tuple(table.control_units)
    vehicle = dict(zip(VEHICLE_CONTROLS, VEHICLE_CONTROL_UNITS, strict=True))
    if "wheelbase" in table.attrs and all(name in vehicle for name in table.control_names):
        return tuple(vehicle[name] for name in table.control_names)
    return tuple("N*m" for _ in table.control_names)


def read_controller_table(path: str | Path) -> ControllerTable:
    """Read a controller table written by ``write_controller_table`` (or any file that meets the
    contract); InputError naming the file if it is not one (``contracts.open_contract``)."""
    with open_contract(path, "controller table") as h5:
        state_order = string_tuple(h5.attrs["state_order"])
        axes = tuple(np.asarray(h5["axes"][name][()], dtype=np.float64) for name in state_order)
        units = tuple(str(h5["axes"][name].attrs["unit"]) for name in state_order)
        wrap = tuple(bool(h5["axes"][name].attrs["wrap"]) for name in state_order)
        known = {
            "state_order",
            "control_names",
            "control_min",
            "control_max",
            "K",
            "dest",
            "destinations",
        }
        attrs = root_attributes(h5, known)
        return ControllerTable(
            state_order=state_order,
            control_names=string_tuple(h5.attrs["control_names"]),
            axes=axes,
            axis_units=units,
            wrap=wrap,
            torque=np.asarray(h5["torque"][()], dtype=np.float64),
            value=np.asarray(h5["value"][()], dtype=np.float64),
            control_min=np.atleast_1d(np.asarray(h5.attrs["control_min"], dtype=np.float64)),
            control_max=np.atleast_1d(np.asarray(h5.attrs["control_max"], dtype=np.float64)),
            effort_weight=np.atleast_1d(np.asarray(h5.attrs["K"], dtype=np.float64)),
            dest=json.loads(h5.attrs["dest"]),
            figure=str(h5.attrs["figure"]),
            attrs=attrs,
            dead_end=np.asarray(h5["dead_end"][()], dtype=np.bool_) if "dead_end" in h5 else None,
            destinations=tuple(json.loads(h5.attrs["destinations"]))
            if "destinations" in h5.attrs
            else None,
            destination_index=np.asarray(h5["destination_index"][()], dtype=np.int64)
            if "destination_index" in h5
            else None,
            control_units=column_units(h5["torque"]),
            arrival_value=np.asarray(h5["arrival_value"][()], dtype=np.float64)
            if "arrival_value" in h5
            else None,
        )
