"""Value iteration's policy sweeps (``kernels.dp.gather_policy``, ``policy_sweep``): a policy
sweep is, bit for bit, a Bellman sweep over the tables cut down to each node's control; sweeps
with them reach the fixed point that Bellman sweeps alone reach, from above, never below it;
and on a chain that keeps returning before it escapes (the slow mode of Luxo's and the car's
tables) they take over all but a few of the many Bellman sweeps it would need."""

from __future__ import annotations

import numpy as np
import pytest
from exit_tables import random_tables

from mosys.kernels.dp import (
    gather_policy,
    gauss_seidel_sweep,
    gauss_seidel_sweeps,
    policy_sweep,
    policy_tables,
    sweep_order,
)


def solve(
    tables,
    axis_count,
    tolerance,
    policy_sweeps,
    bound=1e4,
    count=100_000,
    blocks=None,
):
    """Value iteration from ``bound`` as ``ssc.solution.value_iteration`` runs it: (values,
    Bellman sweeps, policy sweeps). blocks: ``dp.blocked_gauss_seidel_sweep``'s, each sweep's
    snapshot a full copy (default: one block, the plain sweeps)."""
    arrays, is_destination = tables
    row_of = arrays[4]
    value = np.where(is_destination, 0.0, np.where(row_of >= 0, bound, np.inf))
    edges = None if blocks is None else np.array([[0, value.size]], dtype=np.int64)
    bellman, policy, _ = gauss_seidel_sweeps(
        *arrays,
        is_destination,
        value,
        value.copy(),
        np.array([0, value.size], dtype=np.int64) if blocks is None else blocks,
        edges,
        np.asarray(axis_count, dtype=np.int64),
        0,
        count,
        tolerance,
        np.empty(value.size, dtype=np.int64),
        np.inf,
        False,
        np.zeros(value.size, dtype=np.int64),
        *policy_tables(arrays[2].shape[0], arrays[0].shape[2]),
        policy_sweeps,
    )
    return value, bellman, policy


@pytest.mark.parametrize("shared", [False, True])
@pytest.mark.parametrize("axis_count", [(7, 5), (4, 3, 5, 2, 3)])
def test_a_policy_sweep_is_a_bellman_sweep_over_each_nodes_own_control(axis_count, shared):
    """Bit for bit, with each node's own (renormalised) shapes or with shapes read as a motion
    class's are (shared: renormalised over the corners whose value is known as they are read;
    here each row its own class, so that removed nodes leave corners unknown)."""
    rng = np.random.default_rng(7 + len(axis_count))
    counts = np.array(axis_count, dtype=np.int64)
    arrays, is_destination = random_tables(rng, counts, 5)
    exit_index, exit_weight, cost, to_destination, row_of, _ = arrays
    if shared:
        arrays = (*arrays[:5], row_of)
    nodes = row_of.size
    value = np.where(is_destination, 0.0, np.where(row_of >= 0, 1e4, np.inf))
    order = np.empty(nodes, dtype=np.int64)
    control = np.zeros(nodes, dtype=np.int64)
    policy = policy_tables(arrays[2].shape[0], arrays[0].shape[2])
    for sweep in range(2**counts.size + 3):
        sweep_order(counts, sweep, order)
        gauss_seidel_sweep(*arrays, is_destination, value, order, np.inf, False, control)
        # the control recorded gives each node no more than its value (it gave it, onto
        # values that have only decreased since)
        kept = np.flatnonzero(row_of >= 0)
        held = row_of[kept]
        chosen = control[kept]
        moved = (value[kept] < 1e4) & ~is_destination[kept]  # decreased at least once
        weights = exit_weight[held, chosen].astype(np.float64)  # renormalised: Σ w·V
        corner_values = value[kept[:, None] + exit_index[held, chosen]]
        exit_value = np.einsum("ij,ij->i", weights, np.where(weights != 0, corner_values, 0.0))
        exit_value = np.where(to_destination[held, chosen], 0.0, exit_value)
        promised = cost[held, chosen] + exit_value
        if not shared:  # own shapes are renormalised already: Σ w·V is the exit's value
            assert np.all(promised[moved] <= value[kept][moved] * (1 + 1e-12))
        gather_policy(*arrays, is_destination, value, control, *policy)
        corner, weight, count, segment, known, gathered = policy
        assert np.array_equal(gathered, chosen)  # every row gathered under its control
        for node, row, u in zip(kept, held, chosen, strict=True):
            used = exit_weight[row, u] != 0
            if shared:  # only the corners whose value is known
                used &= np.isfinite(value[node + exit_index[row, u]])
            never = is_destination[node] or (shared and not used.any())
            if never or to_destination[row, u] or cost[row, u] == np.inf:
                assert count[row] == 0
            else:  # the weighted corners, in order, as node indices
                assert np.array_equal(corner[row, : count[row]], node + exit_index[row, u][used])
                assert np.array_equal(weight[row, : count[row]], exit_weight[row, u][used])
            assert segment[row] == (np.inf if never else cost[row, u])
            if shared and count[row] > 0:  # the known weight, summed in the same order
                assert known[row] == np.cumsum(exit_weight[row, u][used].astype(np.float64))[-1]
            else:
                assert known[row] == 1.0
        cut = (
            exit_index[held, chosen][:, None, :].copy(),
            exit_weight[held, chosen][:, None, :].copy(),
            cost[held, chosen][:, None].copy(),
            to_destination[held, chosen][:, None].copy(),
        )
        swept = value.copy()
        hinted = value.copy()  # the same sweep asking the cache ahead: the same values
        largest = policy_sweep(*policy[:5], row_of, value, order, np.inf, False)
        assert policy_sweep(*policy[:5], row_of, hinted, order, np.inf, True) == largest
        assert np.array_equal(hinted, value)
        control_after = np.zeros(nodes, dtype=np.int64)
        expected_largest = gauss_seidel_sweep(
            *cut,
            row_of,
            row_of if shared else None,
            is_destination,
            swept,
            order,
            np.inf,
            False,
            control_after,
        )
        assert np.array_equal(value, swept)
        assert largest == expected_largest


@pytest.mark.parametrize("seed", range(4))
def test_policy_sweeps_reach_the_bellman_fixed_point_from_above(seed):
    rng = np.random.default_rng(seed)
    counts = np.array((9, 7, 5), dtype=np.int64)
    tables = random_tables(rng, counts, 6)
    exact, _, _ = solve(tables, counts, 1e-14, 0)  # the fixed point, to rounding
    for policy_sweeps in (0, 4, 16):
        value, bellman, policy = solve(tables, counts, 1e-6, policy_sweeps)
        finite = np.isfinite(exact)
        assert np.array_equal(np.isfinite(value), finite)
        assert np.all(value[finite] >= exact[finite] - 1e-9)  # never below: upper bounds
        assert np.max(value[finite] - exact[finite]) < 1e-4
        assert (policy > 0) == (policy_sweeps > 0)


def returning_chain(n: int, forward: float, controls: int):
    """A strip of n x 2 nodes with the destination at i = 0: from (i, j) the exit lies a
    fraction ``forward`` of the way to (i + 1, 1 - j) from (i - 1, j) (at the far end, to
    (i, 1 - j)), each segment 1 s under control 0 and 2 s under the others: a walk that drifts
    away from the destination and keeps returning before it escapes to it."""
    nodes = 2 * n
    row_of = np.arange(nodes, dtype=np.int64)
    exit_index = np.zeros((nodes, controls, 2), dtype=np.int32)
    exit_weight = np.zeros((nodes, controls, 2), dtype=np.float32)
    for i in range(n):
        for j in range(2):
            node = 2 * i + j
            exit_index[node, :, 0] = 2 * max(i - 1, 0) + j - node
            exit_index[node, :, 1] = 2 * min(i + 1, n - 1) + 1 - j - node
            exit_weight[node, :] = (1.0 - forward, forward)
    cost = np.full((nodes, controls), 2.0)
    cost[:, 0] = 1.0
    is_destination = np.zeros(nodes, dtype=np.bool_)
    is_destination[:2] = True
    to_destination = np.zeros((nodes, controls), dtype=np.bool_)
    return (exit_index, exit_weight, cost, to_destination, row_of, None), is_destination


def test_policy_sweeps_take_over_the_slow_mode_of_a_returning_chain():
    tables = returning_chain(12, 0.55, 8)
    (exit_index, exit_weight, _, _, row_of, _), is_destination = tables
    # the exact values: V = 1 + P V off the destination, solved directly
    nodes = row_of.size
    transition = np.zeros((nodes, nodes))
    for node in range(nodes):
        for i in range(2):
            transition[node, node + exit_index[node, 0, i]] += exit_weight[node, 0, i]
    free = ~is_destination
    exact = np.zeros(nodes)
    exact[free] = np.linalg.solve(
        np.eye(free.sum()) - transition[np.ix_(free, free)], np.ones(free.sum())
    )
    plain, plain_sweeps, _ = solve(tables, (12, 2), 1e-6, 0, bound=1e9)
    value, bellman, policy = solve(tables, (12, 2), 1e-6, 16, bound=1e9)
    assert plain_sweeps > 1000  # the slow mode: a fraction of a per cent a sweep
    assert bellman * 10 < plain_sweeps
    assert bellman + policy < 1.1 * plain_sweeps  # the policy sweeps do the rest, no more
    for found in (plain, value):
        assert np.all(found >= exact - 1e-9)
        assert np.max((found - exact) / np.maximum(exact, 1.0)) < 1e-3


def test_shared_exit_shapes_reach_the_fixed_point_of_each_nodes_own_copy():
    """Where the nodes of a class share their exit shapes (``replay_classes``: shape_row_of an
    array), the exits' values are renormalised over the known corners as they are read (and
    gathered so for the policy sweeps): the same fixed point, to rounding, as each node with a
    copy of its own."""
    counts = np.array((6, 5, 4), dtype=np.int64)
    (exit_index, exit_weight, cost, to_destination, row_of, _), is_destination = random_tables(
        np.random.default_rng(3), counts, 4
    )
    shared = (exit_index, exit_weight, cost, to_destination, row_of, row_of)
    own, _, policy_sweeps = solve(((*shared[:5], None), is_destination), counts, 1e-9, 16)
    value, _, shared_policy_sweeps = solve((shared, is_destination), counts, 1e-9, 16)
    assert policy_sweeps > 0 and shared_policy_sweeps > 0
    finite = np.isfinite(own)
    assert np.array_equal(np.isfinite(value), finite)
    np.testing.assert_allclose(value[finite], own[finite], rtol=1e-6)
