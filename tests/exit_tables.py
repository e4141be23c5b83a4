"""Random exit tables for the DP's sweep tests (``kernels.dp``), shaped as the exit
transitions leave them."""

from __future__ import annotations

import numpy as np

from mosys.kernels.dp import discard_poorly_known_exits


def random_tables(rng: np.random.Generator, axis_count: np.ndarray, controls: int):
    """Exit tables of a grid with axis_count nodes per axis, as ``dp.gauss_seidel_sweep`` takes
    them (exit_index, exit_weight, segment_cost, to_destination, row_of, shape_row_of None:
    each node its own shapes), and is_destination (N,) bool: about a fifth of the nodes removed,
    a third of the segments discarded, a quarter of the weights zero, some corners on removed
    nodes (left out of the exit's value), one exit in fifty to the destination."""
    nodes = int(np.prod(axis_count))
    corners = 2 ** (len(axis_count) - 1)
    kept = rng.random(nodes) > 0.2
    row_of = np.full(nodes, -1, dtype=np.int64)
    row_of[kept] = np.arange(kept.sum())
    rows = int(kept.sum())
    node_of_row = np.flatnonzero(kept)
    corner = rng.integers(0, nodes, (rows, controls, corners))
    exit_index = (corner - node_of_row[:, None, None]).astype(np.int32)
    weight = rng.random((rows, controls, corners)) * (rng.random((rows, controls, corners)) > 0.25)
    weight /= np.maximum(weight.sum(axis=2, keepdims=True), 1e-12)
    cost = rng.uniform(0.05, 1.0, (rows, controls))
    cost[rng.random((rows, controls)) < 0.33] = np.inf
    to_destination = rng.random((rows, controls)) < 0.02
    is_destination = np.zeros(nodes, dtype=np.bool_)
    is_destination[rng.choice(np.flatnonzero(kept), 3, replace=False)] = True
    tables = (exit_index, weight.astype(np.float32), cost, to_destination, row_of, None)
    discard_poorly_known_exits(*tables, kept, 0.0)  # renormalises each node's own shapes
    return tables, is_destination


def reference_sweep(tables, is_destination, value, order, blocks=None):
    """A Gauss–Seidel sweep as ``dp.gauss_seidel_sweep``'s and ``dp.blocked_gauss_seidel_sweep``'s
    docstrings state it, in Python, without hints: each block [blocks[k], blocks[k + 1]) (None:
    one, the whole grid) sweeps its part of ``order`` with its own values as it leaves them and
    the others' as they stood at the sweep's start. Returns the largest decrease."""
    exit_index, exit_weight, segment_cost, to_destination, row_of, shape_row_of = tables
    bounds = [0, value.size] if blocks is None else list(blocks)
    snapshot = value.copy()
    largest = 0.0
    for low, high in zip(bounds[:-1], bounds[1:], strict=True):
        for node in order[(order >= low) & (order < high)]:  # the block's part, in order
            row = row_of[node]
            if row < 0 or is_destination[node] or value[node] == np.inf:
                continue
            shape = row if shape_row_of is None else shape_row_of[node]
            best = np.inf
            for u in range(segment_cost.shape[1]):
                if segment_cost[row, u] == np.inf:
                    continue
                candidate = segment_cost[row, u]
                if not to_destination[row, u]:  # own shapes: renormalised already, Σ w·V
                    total = 0.0
                    for i in range(exit_index.shape[2]):
                        w = float(exit_weight[shape, u, i])
                        corner = node + exit_index[shape, u, i]
                        if w != 0.0:
                            total += w * (value if low <= corner < high else snapshot)[corner]
                    candidate += total
                best = min(best, candidate)
            if best < value[node]:
                largest = max(largest, value[node] - best)
                value[node] = best
    return largest
