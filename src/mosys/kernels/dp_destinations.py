"""Which destination each node's optimal path ends at, for a spec with several ``dest`` lines
(the paper's "conditional" goals, van de Panne et al. 1990 §5): Gauss–Seidel sweeps of each
node's shares of the destinations over the DP's exits (``kernels.dp_exits``) under the optimal
controls, in the value iteration's own sweep orders (``kernels.dp.sweep_order``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mosys.kernels.dp import shape_of, sweep_order

DESTINATION_TOLERANCE = 1e-9  # the largest change of a destination share that ends the sweeps
DESTINATION_MAX_SWEEPS = 10_000  # a cap on them (a converged table needs tens)


@njit(cache=True)
def destination_share_sweep(
    exit_index,
    exit_weight,
    to_destination,
    row_of,
    shape_row_of,
    best_control,
    reachable,
    terminal_node,
    active,
    share,
    order,
):
    """One Gauss–Seidel sweep, in ``order`` (``sweep_order``), of the destination shares
    (``destination_indices``): each ``active`` node's share of every destination becomes the
    weighted sum of its best exit's reachable corners' shares (weights renormalised over them,
    as ``known_value`` does; the share of ``terminal_node`` for an exit to the destination), at
    once, so that the nodes after it in the sweep use it. active: (N,) bool; share: (N, D)
    float64, in place. Returns the largest change of a share."""
    largest = 0.0
    for p in range(order.shape[0]):
        node = order[p]
        if not active[node]:
            continue
        row = row_of[node]
        shape = shape_of(shape_row_of, row_of, node)
        u = best_control[node]
        for k in range(share.shape[1]):
            if to_destination[row, u]:
                total = share[terminal_node, k]
            else:
                total = 0.0
                known = 0.0
                for i in range(exit_index.shape[2]):
                    w = exit_weight[shape, u, i]
                    corner = node + exit_index[shape, u, i]
                    if w != 0.0 and reachable[corner]:
                        total += w * share[corner, k]
                        known += w
                total /= known
            change = abs(total - share[node, k])
            if change > largest:
                largest = change
            share[node, k] = total
    return largest


@njit(cache=True)
def destination_indices(
    exit_index,
    exit_weight,
    to_destination,
    row_of,
    shape_row_of,
    best_control,
    reachable,
    terminal_node,
    value,
    destination_label,
    axis_count,
    tolerance,
    max_sweeps,
    order,
    share,
    out,
):
    """Which destination each node's optimal path ends at, for a spec with several ``dest``
    lines (the contract's ``/destination_index``), written into out (N,) int64; returns the
    sweeps run.

    The exit tables as ``gauss_seidel_sweep`` takes them (after ``discard_poorly_known_exits``);
    best_control (N,) int64 (``best_controls``); reachable (N,) bool, the nodes whose value the
    DP knew; terminal_node: the destination node an exit to the destination
    (``to_destination``) ends at; value (N,) float64, the table's cost-to-go, s (inf:
    unreachable or dead end); destination_label (N,) int64, the ``dest`` line (0 .. D-1) a
    destination node matches (the first, if several), -1 for the other nodes; axis_count (d,)
    int64; order (N,) int64 work space; share (N, D) float64 out: the destination shares below.

    The rule. The DP reads an exit as going on to the corners of the face it crosses in the
    proportions of their interpolation weights: the cost-to-go is the expected cost of that
    path. The share of destination k at a node is the probability that this path ends at k:
    1 for k's own nodes (0 for the other destinations), and elsewhere the weighted sum of the
    shares of the best control's exit corners, ``share(S) = Σ w_i share(corner_i)`` — a
    weight vote over the exit's corners, repeated until it is a fixed point. That is solved
    by Gauss–Seidel sweeps in the orders of ``sweep_order`` until no share changes by more
    than ``tolerance`` (or ``max_sweeps``); chains of exits that loop back are part of the
    linear system and need no special case. A node's index is the destination with the
    largest share (ties: the lowest index); -1 where the value is inf. A finite-valued node
    whose shares are all 0 (its path never reaches a destination: not seen in a converged
    table, since every exit costs time) takes 0, the first destination. One thread, fixed
    orders: deterministic.
    """
    n = value.shape[0]
    active = np.zeros(n, np.bool_)
    for node in range(n):
        for k in range(share.shape[1]):
            share[node, k] = 0.0
        if not value[node] < np.inf:
            continue
        if destination_label[node] >= 0:
            share[node, destination_label[node]] = 1.0
        elif row_of[node] >= 0:
            active[node] = True
    sweeps = 0
    while sweeps < max_sweeps:
        sweep_order(axis_count, sweeps, order)
        largest = destination_share_sweep(
            exit_index,
            exit_weight,
            to_destination,
            row_of,
            shape_row_of,
            best_control,
            reachable,
            terminal_node,
            active,
            share,
            order,
        )
        sweeps += 1
        if largest <= tolerance:
            break
    for node in range(n):
        if not value[node] < np.inf:
            out[node] = -1
            continue
        choice = 0
        for k in range(1, share.shape[1]):
            if share[node, k] > share[node, choice]:
                choice = k
        out[node] = choice
    return sweeps
