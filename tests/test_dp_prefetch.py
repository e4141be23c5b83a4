"""The DP sweep's cache hints (``kernels.prefetch``) change no value: a Gauss–Seidel sweep gives,
bit for bit, what the same sweep computes written out plainly, with the hints and without, on
random exit tables with removed nodes, destinations, discarded (inf) segments and zero weights,
in every sweep order; only tables larger than the caches get them; and the one-block sweeps'
compiled code takes no reference to a table at a node, with each node's shapes or its class's
(numba's reference counts: when the hints were an inlined function taking the tables, every node
took and dropped one, and a policy sweep of the car's tables took 85 ms instead of 12)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from exit_tables import random_tables, reference_sweep
from numba import njit

from mosys.kernels import dp
from mosys.kernels.dp import gather_policy, gauss_seidel_sweep, policy_tables, sweep_order
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


def blocks_taking_references(kernel) -> list[str]:
    """The labels of the basic blocks of ``kernel``'s compiled code (LLVM) that take a
    reference (``NRT_incref``): a function's entry takes one to each array once a call, the
    loop's blocks would take them at every node."""
    labels = []
    for code in kernel.inspect_llvm().values():
        for function in re.split(r"\ndefine ", code)[1:]:
            for block in re.split(r"\n(?=[\w.$]+:)", function):
                label = block.split(":", 1)[0]
                if "call void @NRT_incref" in block and "{" not in label:
                    labels.append(label)
    return labels


@njit
def keeps_through_a_tuple(arrays, picks):
    """How many arrays[p] a list kept: the list holds each, so the loop takes a reference at
    every pass whatever numba prunes (the check's positive control; a bare binding of arrays[p]
    in the loop took one under Python 3.11 and none under 3.13, with the same numba)."""
    kept = []
    for p in picks:
        kept.append(arrays[p])
    return len(kept)


def test_the_check_sees_a_reference_taken_in_a_loop():
    assert keeps_through_a_tuple((np.ones(2), np.zeros(2)), np.array([0, 1, 0])) == 3
    assert set(blocks_taking_references(keeps_through_a_tuple)) - {"entry", "B0"}


@pytest.mark.parametrize("shared_shapes", [False, True])
def test_the_one_block_sweeps_take_no_reference_at_a_node(shared_shapes):
    """Compiled afresh from their Python source (a kernel loaded from numba's cache has no code to
    inspect), with hints, for exit shapes of each node's own and shared by classes (there, until
    the sweep borrowed its arrays, the inlined ``_bellman`` took references at every node)."""
    rng = np.random.default_rng(3)
    counts = np.array((4, 3, 5), dtype=np.int64)
    arrays, is_destination = random_tables(rng, counts, 5)
    row_of = arrays[4]
    if shared_shapes:  # each node's class its row: the shared-shape variant of the kernels
        arrays = (*arrays[:5], np.where(row_of >= 0, row_of, 0))
    value = np.where(is_destination, 0.0, np.where(row_of >= 0, 1e4, np.inf))
    order = np.empty(value.size, dtype=np.int64)
    sweep_order(counts, 1, order)
    control = np.zeros(value.size, dtype=np.int64)
    bellman = njit(dp.gauss_seidel_sweep.py_func)
    bellman(*arrays, is_destination, value, order, np.inf, True, control)
    policy = policy_tables(arrays[2].shape[0], arrays[0].shape[2])
    gather_policy(*arrays, is_destination, value, control, *policy)
    follow = njit(dp.policy_sweep.py_func)
    follow(*policy[:5], row_of, value, order, np.inf, True)
    for kernel in (bellman, follow):
        assert set(blocks_taking_references(kernel)) <= {"entry"}
