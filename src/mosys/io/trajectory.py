"""The trajectory contract (DESIGN.md, ``results/trajectories/S.h5``) and the ``figure_motion``
group every moving articulated figure writes.

Beyond the contract (docs/formats/trajectory.md, figure_motion.md): every dataset has a
``unit``; ``/state`` and ``/control`` also ``units`` (one per column) when the writer is told
them or can tell (a car's fixed variables), else ``unit`` ``spec``; the root carries the
provenance attrs (``io.provenance``)."""

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
from mosys.parsing import vehicle

FORMAT_VERSION = 1


@dataclass(frozen=True)
class FigureMotion:
    """An articulated figure moving. t: (N,) s, non-decreasing; endpoints: (N, n_rods, 2, D) m,
    per rod its proximal then distal end (x, y) or, for a 3-D figure (D = ``dimensions`` = 3),
    (x, y, z), y up; com: (N, D) m. The rod and world properties are the group attributes of the
    contract; a 3-D figure also has ``heading_rod``, ``heading_offset`` (deg) and ``feet`` (pairs
    of rod index and end, 0 proximal, 1 distal)."""

    t: np.ndarray
    endpoints: np.ndarray
    com: np.ndarray
    rod_names: tuple[str, ...]
    rod_mass: np.ndarray
    rod_length: np.ndarray
    rod_com: np.ndarray
    rod_inertia: np.ndarray
    gravity: float
    terrain: list
    contact: str
    dimensions: int = 2
    heading_rod: str = ""
    heading_offset: float = 0.0
    feet: tuple[tuple[int, int], ...] = ()


def write_figure_motion(group: h5py.Group, motion: FigureMotion) -> None:
    """Fill an open HDF5 group with the ``figure_motion`` contract."""
    create_with_unit(group, "t", np.asarray(motion.t, dtype=np.float64), "s")
    create_with_unit(group, "endpoints", np.asarray(motion.endpoints, dtype=np.float64), "m")
    create_with_unit(group, "com", np.asarray(motion.com, dtype=np.float64), "m")
    group.attrs["rod_names"] = string_list(motion.rod_names)
    group.attrs["rod_mass"] = np.asarray(motion.rod_mass, dtype=np.float64)
    group.attrs["rod_length"] = np.asarray(motion.rod_length, dtype=np.float64)
    group.attrs["rod_com"] = np.asarray(motion.rod_com, dtype=np.float64)
    group.attrs["rod_inertia"] = np.asarray(motion.rod_inertia, dtype=np.float64)
    group.attrs["gravity"] = float(motion.gravity)
    group.attrs["terrain"] = json.dumps(motion.terrain)
    group.attrs["contact"] = motion.contact
    if motion.dimensions == 3:
        group.attrs["dimensions"] = 3
        group.attrs["heading_rod"] = motion.heading_rod
        group.attrs["heading_offset"] = float(motion.heading_offset)
        group.attrs["feet"] = json.dumps([list(foot) for foot in motion.feet])


def read_figure_motion(group: h5py.Group) -> FigureMotion:
    """Read a ``figure_motion`` group."""
    names = string_tuple(group.attrs["rod_names"])
    return FigureMotion(
        t=group["t"][()],
        endpoints=group["endpoints"][()],
        com=group["com"][()],
        rod_names=names,
        rod_mass=np.atleast_1d(group.attrs["rod_mass"]),
        rod_length=np.atleast_1d(group.attrs["rod_length"]),
        rod_com=np.atleast_1d(group.attrs["rod_com"]),
        rod_inertia=np.atleast_1d(group.attrs["rod_inertia"]),
        gravity=float(group.attrs["gravity"]),
        terrain=json.loads(group.attrs["terrain"]),
        contact=str(group.attrs["contact"]),
        dimensions=int(group.attrs.get("dimensions", 2)),
        heading_rod=str(group.attrs.get("heading_rod", "")),
        heading_offset=float(group.attrs.get("heading_offset", 0.0)),
        feet=tuple(tuple(foot) for foot in json.loads(group.attrs.get("feet", "[]"))),
    )


@dataclass(frozen=True)
class Contacts:
    """A figure's contact points over a trajectory (group ``contacts``): position (N, C, 2) m
    and the ground's force on each, force (N, C, 2) N, sampled at ``/t``; ``rods`` the rod of
    each point and ``fraction`` where along it (0 proximal, 1 distal)."""

    position: np.ndarray
    force: np.ndarray
    rods: tuple[str, ...]
    fraction: np.ndarray


@dataclass(frozen=True)
class Trajectory:
    """A script's trajectory. t: (N,) s; state: (N, d) spec units in ``state_order``; control:
    (N, m); controller: (N,) int64 index into ``controllers`` (table file stems); attrs: extra
    root attributes; motion: the figure's ``figure_motion`` (None for non-articulated figures);
    contacts: its contact points (None for a figure without them). state_units, control_units:
    the spec unit of each column ('deg', 'deg/s', 'm', 'm/s'; 'N*m', ...), written as the
    datasets' ``units``; None: the writer infers them where it can (``column_units_of``), and a
    file without them reads as None."""

    t: np.ndarray
    state: np.ndarray
    control: np.ndarray
    controller: np.ndarray
    state_order: tuple[str, ...]
    control_names: tuple[str, ...]
    controllers: tuple[str, ...]
    attrs: dict
    motion: FigureMotion | None
    contacts: Contacts | None = None
    state_units: tuple[str, ...] | None = None
    control_units: tuple[str, ...] | None = None


def write_trajectory(path: str | Path, trajectory: Trajectory) -> None:
    """Write a trajectory file atomically."""

    def fill(h5: h5py.File) -> None:
        state_units, control_units = column_units_of(trajectory)
        create_with_unit(h5, "t", np.asarray(trajectory.t, dtype=np.float64), "s")
        state = h5.create_dataset("state", data=np.asarray(trajectory.state, np.float64))
        set_column_units(state, state_units)
        control = h5.create_dataset("control", data=np.asarray(trajectory.control, float))
        set_column_units(control, control_units)
        controller = np.asarray(trajectory.controller, np.int64)
        create_with_unit(h5, "controller", controller, INDEX)
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["state_order"] = string_list(trajectory.state_order)
        h5.attrs["control_names"] = string_list(trajectory.control_names)
        h5.attrs["controllers"] = string_list(trajectory.controllers)
        for key, value in trajectory.attrs.items():
            h5.attrs[key] = value
        if trajectory.motion is not None:
            write_figure_motion(h5.create_group("figure_motion"), trajectory.motion)
        if trajectory.contacts is not None:
            group = h5.create_group("contacts")
            contacts = trajectory.contacts
            position = np.asarray(contacts.position, np.float64)
            create_with_unit(group, "position", position, "m")
            create_with_unit(group, "force", np.asarray(contacts.force, np.float64), "N")
            group.attrs["rods"] = string_list(contacts.rods)
            group.attrs["fraction"] = np.asarray(contacts.fraction, np.float64)
        h5.attrs.update(provenance_attributes())  # this process wrote it, whatever was read

    write_hdf5_atomically(path, fill)


def column_units_of(
    trajectory: Trajectory,
) -> tuple[tuple[str, ...] | None, tuple[str, ...] | None]:
    """The spec units of the state and control columns: those the trajectory gives; else, for a
    car (no ``figure_motion``, the car's fixed variable names: parsing.vehicle), the car's;
    else None for the state (an articulated figure's variables are named by its spec, which
    the file does not hold) and N*m for the controls (a figure spec actuates only hinges)."""
    state_units, control_units = trajectory.state_units, trajectory.control_units
    is_car = (
        trajectory.motion is None
        and set(trajectory.state_order) <= set(vehicle.STATE_NAMES)
        and set(trajectory.control_names) <= set(vehicle.INPUT_NAMES)
    )
    if state_units is None and is_car:
        units = dict(zip(vehicle.STATE_NAMES, vehicle.STATE_UNITS, strict=True))
        state_units = tuple(units[name] for name in trajectory.state_order)
    if control_units is None:
        units = dict(zip(vehicle.INPUT_NAMES, vehicle.INPUT_UNITS, strict=True))
        control_units = tuple(units[name] if is_car else "N*m" for name in trajectory.control_names)
    return state_units, control_units


def read_trajectory(path: str | Path) -> Trajectory:
    """Read a trajectory file; InputError naming the file if it is not one
    (``contracts.open_contract``)."""
    with open_contract(path, "trajectory") as h5:
        known = {"state_order", "control_names", "controllers"}
        return Trajectory(
            t=h5["t"][()],
            state=h5["state"][()],
            control=h5["control"][()],
            controller=h5["controller"][()],
            state_order=string_tuple(h5.attrs["state_order"]),
            control_names=string_tuple(h5.attrs["control_names"]),
            controllers=string_tuple(h5.attrs["controllers"]),
            attrs=root_attributes(h5, known),
            motion=read_figure_motion(h5["figure_motion"]) if "figure_motion" in h5 else None,
            contacts=_read_contacts(h5["contacts"]) if "contacts" in h5 else None,
            state_units=column_units(h5["state"]),
            control_units=column_units(h5["control"]),
        )


def _read_contacts(group: h5py.Group) -> Contacts:
    return Contacts(
        position=group["position"][()],
        force=group["force"][()],
        rods=string_tuple(group.attrs["rods"]),
        fraction=np.atleast_1d(group.attrs["fraction"]),
    )
