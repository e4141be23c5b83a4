"""Helpers for HDF5 attributes."""

from __future__ import annotations

import numpy as np


def string_attr(value) -> str:
    """A string attribute as read by h5py (str or bytes)."""
    return value.decode() if isinstance(value, bytes) else str(value)


def string_tuple(values) -> tuple[str, ...]:
    """A string-list attribute as read by h5py (str, bytes or an array of either) as a tuple."""
    return tuple(string_attr(v) for v in np.atleast_1d(values))
