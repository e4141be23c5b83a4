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
