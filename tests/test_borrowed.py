"""Borrowed views (``kernels.borrowed``): the same data, with no reference count."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from mosys.kernels.borrowed import borrowed


class Pair(NamedTuple):
    values: np.ndarray
    scale: float


@njit
def _double_through_borrowed_views(pair, nested):
    view = borrowed(pair)
    inner = borrowed(nested)
    for i in range(view.values.shape[0]):
        view.values[i] *= 2.0 * view.scale
    inner[0][1, 0] = -1.0
    return inner[1] + view.values.sum()


def test_borrowed_views_read_and_write_the_arrays_they_were_made_from():
    values = np.arange(4.0)
    matrix = np.zeros((2, 2))
    total = _double_through_borrowed_views(Pair(values, 1.5), (matrix, 7))
    np.testing.assert_array_equal(values, [0.0, 3.0, 6.0, 9.0])
    assert matrix[1, 0] == -1.0
    assert total == 7 + 18.0


def test_called_from_python_a_borrowed_value_is_the_value_itself():
    """(So kernels that borrow also run with ``NUMBA_DISABLE_JIT``.)"""
    pair = Pair(np.arange(3.0), 2.0)
    assert borrowed(pair) is pair
