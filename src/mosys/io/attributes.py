"""Helpers for HDF5 attributes."""

from __future__ import annotations

import numpy as np


def string_tuple(values) -> tuple[str, ...]:
    """A string-list attribute as read by h5py (str, bytes or an array of either) as a tuple."""
    return tuple(v.decode() if isinstance(v, bytes) else str(v) for v in np.atleast_1d(values))
