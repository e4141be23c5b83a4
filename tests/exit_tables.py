"""Random exit tables for the DP's sweep tests (``kernels.dp``), shaped as the exit
transitions leave them."""

from __future__ import annotations

import numpy as np


def random_tables(rng: np.random.Generator, axis_count: np.ndarray, controls: int):
    """Exit tables (R, U, 2**(d-1)) of a grid with axis_count nodes per axis: about a fifth of
    the nodes removed, a third of the segments discarded, a quarter of the weights zero."""
    nodes = int(np.prod(axis_count))
    corners = 2 ** (len(axis_count) - 1)
    kept = rng.random(nodes) > 0.2
    row_of = np.full(nodes, -1, dtype=np.int64)
    row_of[kept] = np.arange(kept.sum())
    rows = int(kept.sum())
    exit_index = rng.integers(0, nodes, (rows, controls, corners)).astype(np.int32)
    weight = rng.random((rows, controls, corners)) * (rng.random((rows, controls, corners)) > 0.25)
    weight /= np.maximum(weight.sum(axis=2, keepdims=True), 1e-12)
    cost = rng.uniform(0.05, 1.0, (rows, controls))
    cost[rng.random((rows, controls)) < 0.33] = np.inf
    is_destination = np.zeros(nodes, dtype=np.bool_)
    is_destination[rng.choice(np.flatnonzero(kept), 3, replace=False)] = True
    return exit_index, weight.astype(np.float32), cost, row_of, is_destination
