"""Helpers for HDF5 attributes: reading strings back, and the ``unit``/``units`` every dataset
mosys writes carries (docs/formats/README.md, "Units").

Unit vocabulary: SI or spec unit strings (``s``, ``m``, ``m/s``, ``m/s^2``, ``deg``, ``deg/s``,
``deg/s^2``, ``N``, ``N*m``, ``kg``, ``kg*m^2``: ``*`` a product, ``^`` a power), and
``1`` a dimensionless number or count; ``index`` an integer index (into a list a root or group
attr names, -1 for none) or a boolean flag; ``text`` strings; ``SI`` a simulator's own state
vector, each entry in its SI unit (m, rad, m/s, rad/s, ...); ``spec`` spec units (deg, deg/s, m,
m/s by variable) where the writer was not told which; ``mixed`` columns of different units,
listed in ``units``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import h5py
import numpy as np
from numpy.typing import ArrayLike

from mosys.errors import InputError

DIMENSIONLESS = "1"
INDEX = "index"
TEXT = "text"
SI_STATE = "SI"
SPEC = "spec"
MIXED = "mixed"


class FileAttributes(dict):
    """A file's root attributes as read, name -> value; looking up one the file lacks raises
    InputError naming the file and the attribute (a table made from a file written before an
    attribute was added stopped with a KeyError traceback). ``get`` and ``in`` are a dict's."""

    def __init__(self, path: str, items: Iterable[tuple[str, object]]):
        super().__init__(items)
        self.path = path

    def __missing__(self, key: str) -> object:
        raise InputError(f"{self.path}: no root attribute {key!r}, which mosys reads here")


def root_attributes(h5: h5py.File, skip: Iterable[str] = ()) -> FileAttributes:
    """The root attributes of an open file but those in ``skip`` (read into their own fields)."""
    skipped = set(skip)
    return FileAttributes(h5.filename, ((k, h5.attrs[k]) for k in h5.attrs if k not in skipped))


def string_attr(value: object) -> str:
    """A string attribute as read by h5py (str or bytes)."""
    return value.decode() if isinstance(value, bytes) else str(value)


def string_tuple(values: object) -> tuple[str, ...]:
    """A string-list attribute as read by h5py (str, bytes or an array of either) as a tuple."""
    return tuple(string_attr(v) for v in np.atleast_1d(values))


def string_list(values: Iterable[object]) -> np.ndarray:
    """A list of strings as an attribute value: variable-length UTF-8 strings, also when the list
    is empty (h5py stores a plain empty list as float64, and a reader checking the type saw
    numbers: ``sense_names`` of every time-based search, ``domain_violation_controllers`` of
    most trajectories)."""
    return np.array([str(value) for value in values], dtype=h5py.string_dtype())


def set_unit(dataset: h5py.Dataset, unit: str) -> None:
    """Give ``dataset`` its ``unit`` attr (one of the vocabulary above)."""
    dataset.attrs["unit"] = unit


def set_column_units(dataset: h5py.Dataset, units: Sequence[str] | None) -> None:
    """The units of a dataset whose last axis holds named quantities (a table's controls, a
    trajectory's state columns): ``units``, one per entry of the last axis, and ``unit``, their
    common unit or ``mixed``. ``units`` None (the writer was not told): ``unit`` ``spec`` and no
    ``units``."""
    if units is None:
        set_unit(dataset, SPEC)
        return
    units = [str(unit) for unit in units]
    if len(units) != dataset.shape[-1]:
        raise ValueError(
            f"{dataset.name}: {len(units)} units {units} for {dataset.shape[-1]} columns"
        )
    dataset.attrs["units"] = string_list(units)
    if not units:  # no columns: nothing to measure
        set_unit(dataset, DIMENSIONLESS)
    else:
        set_unit(dataset, units[0] if len(set(units)) == 1 else MIXED)


def column_units(dataset: h5py.Dataset) -> tuple[str, ...] | None:
    """The ``units`` attr written by ``set_column_units`` as a tuple; None when absent."""
    return string_tuple(dataset.attrs["units"]) if "units" in dataset.attrs else None


def create_with_unit(
    group: h5py.Group, name: str, data: ArrayLike, unit: str, **options: object
) -> h5py.Dataset:
    """``group.create_dataset(name, data=data, **options)`` with its ``unit``."""
    dataset = group.create_dataset(name, data=data, **options)
    set_unit(dataset, unit)
    return dataset
