"""Value iteration in blocks (``kernels.dp``, ``ssc.solution.sweep_blocks``): a sweep in two
blocks (``blocked_gauss_seidel_sweep``) is, bit for bit, each block's part of the order swept
with its own values as it leaves them and the other block's as they stood at the sweep's start,
in every sweep order and on one thread or two; sweeps in blocks reach the fixed point that one
block reaches, from above; the blocks of a grid split its nodes about evenly and copy what a
block reads across the split; and the car's controller is the same table on one thread and on
two."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from exit_tables import random_tables, reference_sweep
from test_car import SMALL
from test_dp_policy import solve

from mosys.kernels.dp import (
    blocked_gauss_seidel_sweep,
    blocked_policy_sweep,
    gather_policy,
    gauss_seidel_sweep,
    policy_tables,
    sweep_order,
)
from mosys.parsing.controller import parse_controller_text
from mosys.ssc import solution
from mosys.ssc.exits import Transitions
from mosys.ssc.problem import build_problem


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("axis_count", [(6, 5), (5, 3, 4, 2)])
def test_a_sweep_in_two_blocks_reads_the_other_blocks_values_as_they_stood(axis_count, threads):
    rng = np.random.default_rng(11 + len(axis_count))
    counts = np.array(axis_count, dtype=np.int64)
    tables, is_destination = random_tables(rng, counts, 4)  # corners anywhere in the grid
    nodes = int(counts.prod())
    layer = nodes // counts[0]
    blocks = np.array([0, 2 * layer, nodes], dtype=np.int64)  # uneven, as a split may be
    value = np.where(is_destination, 0.0, np.where(tables[4] >= 0, 1e4, np.inf))
    expected = value.copy()
    order = np.empty(nodes, dtype=np.int64)
    control = np.zeros(nodes, dtype=np.int64)
    before = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        for sweep in range(2**counts.size + 3):  # each axis forwards and backwards
            sweep_order(counts, sweep, order)
            snapshot = value.copy()
            largest = blocked_gauss_seidel_sweep(
                *tables,
                is_destination,
                value,
                snapshot,
                order,
                blocks,
                np.empty(2),
                np.inf,
                False,
                control,
            )
            expected_largest = reference_sweep(tables, is_destination, expected, order, blocks)
            assert np.array_equal(value, expected)
            assert largest == expected_largest
    finally:
        numba.set_num_threads(before)
    assert np.isfinite(value).sum() > is_destination.sum()  # values really moved


@pytest.mark.parametrize("threads", [1, 2])
def test_a_policy_sweep_in_blocks_gives_the_same_values_asking_the_cache_ahead(threads):
    rng = np.random.default_rng(5)
    counts = np.array((6, 5, 4), dtype=np.int64)
    tables, is_destination = random_tables(rng, counts, 4)
    nodes = int(counts.prod())
    blocks = np.array([0, 2 * (nodes // counts[0]), nodes], dtype=np.int64)
    value = np.where(is_destination, 0.0, np.where(tables[4] >= 0, 1e4, np.inf))
    order = np.empty(nodes, dtype=np.int64)
    control = np.zeros(nodes, dtype=np.int64)
    for sweep in range(3):  # a policy to follow
        sweep_order(counts, sweep, order)
        gauss_seidel_sweep(*tables, is_destination, value, order, np.inf, False, control)
    policy = policy_tables(tables[2].shape[0], tables[0].shape[2])
    gather_policy(*tables, is_destination, value, control, *policy)
    start = value.copy()
    before = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        for sweep in range(2**counts.size):
            sweep_order(counts, sweep, order)
            snapshot = value.copy()
            hinted = value.copy()
            largest = np.empty(2)
            sweeps = [
                blocked_policy_sweep(
                    *policy[:5], tables[4], swept, snapshot, order, blocks, largest, np.inf, hint
                )
                for swept, hint in ((value, False), (hinted, True))
            ]
            assert sweeps[0] == sweeps[1]
            assert np.array_equal(value, hinted)
    finally:
        numba.set_num_threads(before)
    assert np.any(value < start)  # the policy sweeps moved values


@pytest.mark.parametrize("seed", range(3))
def test_sweeps_in_two_blocks_reach_the_fixed_point_of_one_from_above(seed):
    counts = np.array((8, 6, 5), dtype=np.int64)
    tables = random_tables(np.random.default_rng(seed), counts, 5)
    nodes = int(counts.prod())
    two = np.array([0, 3 * nodes // 8, nodes], dtype=np.int64)
    exact, _, _ = solve(tables, counts, 1e-14, 0)  # the fixed point, to rounding
    for policy_sweeps in (0, 16):
        value, _, _ = solve(tables, counts, 1e-7, policy_sweeps, blocks=two)
        finite = np.isfinite(exact)
        assert np.array_equal(np.isfinite(value), finite)
        assert np.all(value[finite] >= exact[finite] - 1e-9)  # upper bounds still
        assert np.max(value[finite] - exact[finite]) < 1e-4


def local_transitions(counts: np.ndarray, reach: int) -> Transitions:
    """Exit tables whose corners lie within ``reach`` node indices of their node (zero weight
    beyond), the first axis's first layer removed."""
    nodes = int(counts.prod())
    row_of = np.arange(nodes, dtype=np.int64)
    row_of[: nodes // counts[0]] = -1
    index = np.array([[[-reach, 1, 5 * reach]]], dtype=np.int32)
    weight = np.array([[[0.5, 0.5, 0.0]]], dtype=np.float32)
    return Transitions(
        index, weight, np.ones((nodes, 1)), np.zeros((nodes, 1), np.bool_), row_of, row_of * 0
    )


def test_the_blocks_split_the_nodes_evenly_and_copy_what_is_read_across(monkeypatch):
    counts = np.array((10, 4, 5), dtype=np.int64)  # layers of 20 nodes
    assert solution.sweep_blocks(counts, local_transitions(counts, 21))[0].tolist() == [0, 200]
    monkeypatch.setattr(solution, "BLOCKED_SWEEP_NODES", 100)
    blocks, edges = solution.sweep_blocks(counts, local_transitions(counts, 21))
    # 180 nodes kept in layers 1..9: the first block holds layers 0..5 (100 kept, 80 after)
    assert blocks.tolist() == [0, 120, 200]
    assert edges.tolist() == [[80, 160]]  # 21 nodes reach across two layers each side
    blocks, edges = solution.sweep_blocks(counts, local_transitions(counts, 20))
    assert edges.tolist() == [[100, 140]]
    # a corner that wraps round the first axis: one block, the plain sweep
    blocks, edges = solution.sweep_blocks(counts, local_transitions(counts, 180))
    assert blocks.tolist() == [0, 200] and edges is None


def test_the_car_controller_in_blocks_is_the_same_on_one_thread_and_two(car, monkeypatch):
    """The car test's SMALL grid swept in two blocks (as a grid of BLOCKED_SWEEP_NODES is):
    bit-identical values and controls on one thread and on two, each node's value within the
    tolerance of the one-block solution."""
    problem = build_problem(parse_controller_text(SMALL, "small.ssc"), car)
    one = solution.solve(problem, car, 1e-6, 3000, problem.spec.dt, quiet=True)
    monkeypatch.setattr(solution, "BLOCKED_SWEEP_NODES", 0)
    before = numba.get_num_threads()
    solutions = []
    try:
        for threads in (1, 2):
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            solutions.append(solution.solve(problem, car, 1e-6, 3000, problem.spec.dt, quiet=True))
    finally:
        numba.set_num_threads(before)
    first, second = solutions
    assert np.array_equal(first.value, second.value)
    assert np.array_equal(first.best_control, second.best_control)
    finite = np.isfinite(one.value)
    assert np.array_equal(np.isfinite(first.value), finite)
    assert np.max(np.abs(first.value[finite] - one.value[finite])) < 1e-4
