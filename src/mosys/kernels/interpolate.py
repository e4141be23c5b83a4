"""n-linear interpolation on a uniform grid with periodic (wrap) axes.

Grids are described by four (d,) arrays in one consistent unit system: ``axis_min`` (the first
node), ``axis_step`` (node spacing), ``axis_count`` (nodes per axis, int64) and ``wrap`` (bool: the
axis is periodic with period ``axis_count * axis_step``). Node values are stored flat in C order
(the last axis varies fastest).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# A wrap coordinate beyond this many grid steps from the first node (2**52: where a float64 holds
# no fraction of a step) cannot be placed within its period: ``corner_weights`` gives NaN there.
WRAP_LIMIT = 2.0**52
# A sum of interpolation weights this far below a known-weight threshold still meets it: weights
# are products of fractions (and float32 in the DP's exit tables), so a state at 0.8 of a cell
# sums to 0.7999999999999998, and was refused by a threshold of 0.8 that it meets.
KNOWN_WEIGHT_ROUNDING = 1e-6
# A coordinate this far (in grid steps) beyond an axis's end lies on it: the end is computed as
# the first node plus (n - 1) steps, which rounds away from the number in the spec.
AXIS_END_ROUNDING = 1e-9


@njit(cache=True, inline="always")  # inside the DP's loop over every exit
def falls_short(known_weight, minimum_known_weight):
    """True when corners carrying ``known_weight`` of the interpolation weight (in [0, 1]) carry
    less than ``minimum_known_weight`` of it, beyond rounding (``KNOWN_WEIGHT_ROUNDING``): the
    one test of the spec's ``known_weight`` in the DP, the lookahead runtime and the
    controller's cost-to-go."""
    return known_weight < minimum_known_weight - KNOWN_WEIGHT_ROUNDING


@njit(cache=True)
def grid_strides(axis_count, out):
    """C-order strides of a grid, in nodes. axis_count: (d,) int64; out: (d,) int64."""
    stride = 1
    for k in range(axis_count.shape[0] - 1, -1, -1):
        out[k] = stride
        stride *= axis_count[k]


@njit(cache=True)
def clamp_to_domain(axis_min, axis_step, axis_count, wrap, state, out):
    """Copy ``state`` (d,) into ``out`` (d,), moving each non-wrap coordinate onto the nearest
    point of its axis range (±inf onto its ends). Returns True when nothing had to move more
    than ``AXIS_END_ROUNDING`` of a grid step (the last node is ``axis_min`` + (n − 1) ·
    ``axis_step``, which rounds: the car's speed axis, ``ssd speed -0.9 0.9 7``, ends at
    0.8999999999999999 m/s, and a start at 0.9 read as beyond it); False too when a coordinate
    is NaN (copied as is: ``corner_weights`` makes a NaN of it)."""
    unchanged = True
    for k in range(state.shape[0]):
        value = state[k]
        if value != value:  # NaN lies nowhere: left NaN, and flagged
            unchanged = False
        elif not wrap[k]:
            top = axis_min[k] + axis_step[k] * (axis_count[k] - 1)
            slack = AXIS_END_ROUNDING * axis_step[k]
            if value < axis_min[k]:
                unchanged = unchanged and value >= axis_min[k] - slack
                value = axis_min[k]
            elif value > top:
                unchanged = unchanged and value <= top + slack
                value = top
        out[k] = value
    return unchanged


@njit(cache=True)
def interpolation_scratch(d):
    """Work arrays for ``corner_weights`` on a d-dimensional grid: (low, high, free_axes) as one
    (3, d) int64 array, fraction (d,) float64, corner_index (2**d,) int64, corner_weight (2**d,)."""
    return (
        np.empty((3, d), np.int64),
        np.empty(d),
        np.empty(1 << d, np.int64),
        np.empty(1 << d),
    )


@njit(cache=True)
def corner_weights(
    axis_min,
    axis_step,
    axis_count,
    wrap,
    strides,
    state,
    on_node_axis,
    corner_index,
    corner_weight,
    integer_scratch,
    fraction,
):
    """The grid nodes around ``state`` and their n-linear weights.

    state: (d,) inside the domain (non-wrap axes within [min, max]); on_node_axis: an axis on which
    ``state`` lies exactly on a node layer (its weights would be 0 on one side), or -1.
    corner_index: (2**d,) int64 flat node indices out; corner_weight: (2**d,) float64 out.
    integer_scratch (3, d) int64 and fraction (d,) float64: work arrays
    (``interpolation_scratch``). Returns the number of corners written: 2**d, or 2**(d-1) when
    ``on_node_axis`` >= 0. Weights are non-negative and sum to 1. Whatever ``state`` holds, the
    indices stay on the grid: a NaN coordinate, or an inf or beyond-WRAP_LIMIT one on a wrap
    axis, gives NaN weights (at node 0 of that axis).
    """
    d = state.shape[0]
    low = integer_scratch[0]
    high = integer_scratch[1]
    free_axes = integer_scratch[2]
    lost = False  # a coordinate with no place on the grid
    for k in range(d):
        n = axis_count[k]
        u = (state[k] - axis_min[k]) / axis_step[k]
        if u != u or (wrap[k] and abs(u) > WRAP_LIMIT):
            # NaN, or inf or so large a wrap coordinate that its place in the period is lost:
            # node 0, every weight NaN (so is the result), never an index off the grid
            low[k] = 0
            high[k] = 0
            fraction[k] = 0.0
            lost = True
            continue
        if wrap[k]:
            u = u - n * np.floor(u / n)
            if not u >= 0.0:  # rounded to just below 0: node 0, never index -1
                u = 0.0
            if k == on_node_axis:
                i = np.int64(np.floor(u + 0.5)) % n
                low[k] = i
                high[k] = i
                fraction[k] = 0.0
                continue
            i = np.int64(np.floor(u))
            if i >= n:  # u rounded up to exactly n
                i = n - 1
            low[k] = i
            high[k] = (i + 1) % n
            fraction[k] = min(max(u - i, 0.0), 1.0)
        else:
            u = min(max(u, 0.0), n - 1.0)
            if k == on_node_axis or n == 1:
                i = np.int64(np.floor(u + 0.5))
                low[k] = i
                high[k] = i
                fraction[k] = 0.0
                continue
            i = min(np.int64(np.floor(u)), n - 2)
            low[k] = i
            high[k] = i + 1
            fraction[k] = u - i
    free = 0
    for k in range(d):
        if k != on_node_axis:
            free_axes[free] = k
            free += 1
    count = 1 << free
    for corner in range(count):
        index = 0
        weight = 1.0
        for k in range(d):
            if k == on_node_axis:
                index += low[k] * strides[k]
        for bit in range(free):
            k = free_axes[bit]
            if (corner >> bit) & 1:
                index += high[k] * strides[k]
                weight *= fraction[k]
            else:
                index += low[k] * strides[k]
                weight *= 1.0 - fraction[k]
        corner_index[corner] = index
        corner_weight[corner] = np.nan if lost else weight
    return count


@njit(cache=True)
def interpolate_with(
    axis_min, axis_step, axis_count, wrap, strides, table, known, state, scratch, out
):
    """n-linear interpolation of a node table at one state, written into out, with work arrays
    from ``interpolation_scratch`` (no allocation: for loops over time steps).

    table: (prod(axis_count), m) float64, nodes in C order; known: (prod(axis_count),) bool, the
    nodes whose entries count: the weights of the others are dropped and the rest renormalised
    (the paper's Figure 10: interpolate between the neighbours whose values are known); where no
    corner with weight is known, every corner counts. strides: from ``grid_strides``; state:
    (d,), inside the domain (clamp first with ``clamp_to_domain``); out: (m,) float64. Returns
    the weight of the known corners (in [0, 1]); scratch's corner_index and corner_weight hold
    the 2**d corners and their weights (``corner_weights``).
    """
    integer_scratch, fraction, corner_index, corner_weight = scratch
    count = corner_weights(
        axis_min,
        axis_step,
        axis_count,
        wrap,
        strides,
        state,
        np.int64(-1),  # not the literal -1: the signature the DP's exits compile too
        corner_index,
        corner_weight,
        integer_scratch,
        fraction,
    )
    known_weight = 0.0
    for c in range(count):
        if known[corner_index[c]]:
            known_weight += corner_weight[c]
    for j in range(out.shape[0]):
        out[j] = 0.0
    for c in range(count):
        w = corner_weight[c]
        row = corner_index[c]
        if w == 0.0 or (known_weight > 0.0 and not known[row]):
            continue
        if known_weight > 0.0:
            w /= known_weight
        for j in range(out.shape[0]):
            out[j] += w * table[row, j]
    return known_weight


@njit(cache=True)
def interpolate_into(axis_min, axis_step, axis_count, wrap, table, known, state, out):
    """n-linear interpolation of a node table at one state, written into out.

    table: (prod(axis_count), m) float64, nodes in C order; known: (prod(axis_count),) bool, as
    in ``interpolate_with``; state: (d,), inside the domain (clamp first with
    ``clamp_to_domain``); out: (m,) float64. Returns the weight of the known corners.
    """
    d = state.shape[0]
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    scratch = interpolation_scratch(d)
    return interpolate_with(
        axis_min, axis_step, axis_count, wrap, strides, table, known, state, scratch, out
    )
