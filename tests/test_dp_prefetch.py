"""The DP sweep's cache hints (``kernels.prefetch``) change no value: a Gauss–Seidel sweep gives,
bit for bit, what the same sweep computes written out plainly, with the hints and without, on
random exit tables with removed nodes, destinations, discarded (inf) segments and zero weights,
in every sweep order; and only tables larger than the caches get them."""

from __future__ import annotations

import numpy as np
import pytest
from exit_tables import random_tables, reference_sweep
from numba import njit

from mosys.kernels.dp import gauss_seidel_sweep, sweep_order
from mosys.kernels.prefetch import prefetch


@pytest.mark.parametrize("prefetching", [True, False])
@pytest.mark.parametrize("axis_count", [(7, 5), (4, 3, 5, 2, 3), (3, 2, 2, 3, 2, 2)])
def test_the_sweep_gives_the_plain_sweeps_values_bit_for_bit(axis_count, prefetching):
    rng = np.random.default_rng(len(axis_count))
    counts = np.array(axis_count, dtype=np.int64)
    tables, is_destination = random_tables(rng, counts, 5)
    row_of = tables[4]
    value = np.where(is_destination, 0.0, np.where(row_of >= 0, 1e4, np.inf))
    expected = value.copy()
    order = np.empty(value.size, dtype=np.int64)
    control = np.zeros(value.size, dtype=np.int64)
    for sweep in range(2**counts.size + 3):
        sweep_order(counts, sweep, order)
        largest = gauss_seidel_sweep(
            *tables, is_destination, value, order, np.inf, prefetching, control
        )
        expected_largest = reference_sweep(tables, is_destination, expected, order)
        assert np.array_equal(value, expected)
        assert largest == expected_largest
    assert np.isfinite(value).sum() > is_destination.sum()  # values really moved


@njit
def hint_then_sum(array, row):
    prefetch(array, (row,))
    prefetch(array, (row, 1))
    return array[row].sum()


def test_a_hint_reads_and_writes_nothing():
    array = np.arange(24.0).reshape(4, 3, 2)
    before = array.copy()
    assert hint_then_sum(array, 2) == before[2].sum()
    assert np.array_equal(array, before)


def test_only_tables_larger_than_the_caches_are_swept_with_hints():
    from mosys.kernels.dp import PREFETCH_ABOVE_BYTES, prefetch_pays

    small = np.empty((10, 4, 8), dtype=np.int32)
    assert not prefetch_pays(small, small.astype(np.float32))
    rows = PREFETCH_ABOVE_BYTES // (2 * 4 * 8 * 4) + 1
    # broadcast: the shapes' bytes, without the memory
    large_index = np.broadcast_to(np.int32(0), (rows, 4, 8))
    large_weight = np.broadcast_to(np.float32(0), (rows, 4, 8))
    assert prefetch_pays(large_index, large_weight)
