"""Value iteration for state-space controllers (van de Panne et al. 1990, §3.5), over the exit
transitions of ``kernels.dp_exits``: each node's segment under each sampled control, its cost,
and its exit's corners and weights as a shape shared by the nodes of a class.

Value iteration repeats Bellman sweeps ``V(S) = min_u [cost(S,u) + Σ w V(corner)]`` until the
largest change is below a tolerance (``gauss_seidel_sweep``). The paper: "It
is difficult to sequence local optimizations such that each local optimization always uses accurate
information. It is simpler to approximate this order and repeat this for several iterations" —
the sweeps run through the grid in the 2**d orders of the fast sweeping method in turn
(``sweep_order``), each node using the values the sweep has just updated; between them, sweeps
of the policy the last one left, each node under its own control only (modified policy
iteration: ``policy_sweep``), run down the slow tail at a fraction of the cost. On large grids
both run in two blocks of the first axis side by side (``blocked_gauss_seidel_sweep``), each
reading the other's values as they stood when the sweep began. For a spec with
several destinations (the paper's "conditional" goals), ``kernels.dp_destinations`` then finds
which destination each node's optimal path ends at, by the same sweeps over the exits.

All quantities here are SI (rad, rad/s, m, m/s, s, N·m); grids follow ``kernels.interpolate``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from mosys.kernels.borrowed import borrowed
from mosys.kernels.interpolate import falls_short, grid_strides
from mosys.kernels.prefetch import prefetch

UNKNOWN = 1.0e9  # s: cost-to-go of a reachable node whose value is not known yet (the paper's
# upper bound, from which value iteration decreases)
DEAD_END_BOUND = 1.0e4  # s: that bound for a spec with known_weight, whose dead ends keep it (far
# above any path's seconds, and low enough that values resting partly on it settle in fewer sweeps)
DEAD_END_SECONDS = 1.0e3  # s: a cost-to-go this long rests on a dead end
PREFETCH_AHEAD = 2  # nodes: a sweep asks the cache for the exits of the node this far ahead in
# its order and for the segment costs of the one twice as far (``kernels.prefetch``)
CACHE_LINE = 64  # bytes
POLICY_PREFETCH_AHEAD = 16  # nodes: a policy sweep asks the cache for the compact row of the
# node this far ahead in its order (``_policy_block``)
PREFETCH_ABOVE_BYTES = 64 * 2**20  # tables of corners larger than this are swept with cache
# hints: on smaller ones (in or near the processor's caches) the hints cost more than they save


@njit(cache=True)
def prefetch_pays(index: np.ndarray, weight: np.ndarray) -> bool:
    """Whether sweeps over these tables of corners and weights (the exits', or the policy's
    compact copy) should ask the cache ahead (PREFETCH_ABOVE_BYTES)."""
    return index.nbytes + weight.nbytes > PREFETCH_ABOVE_BYTES


@njit(cache=True)
def sweep_order(axis_count, sweep, out):
    """The grid's nodes in the order of sweep number ``sweep`` (out: (N,) int64): C order with
    the axes whose bit is set in ``sweep mod 2**d`` run backwards. Successive sweeps take the
    2**d orders in turn (the fast sweeping method), so that what is known spreads along every
    direction of the grid within a few sweeps, each running through memory in order. The first
    layer of the first axis is walked with the node index carried from one node to the next (a
    step along the last axis that moves, back to the start of the axes after it); every other
    layer is that one shifted by its steps along the first axis, a plain add that the compiler
    vectorises (the car's 1.6 million nodes in 0.4 ms against 1.2–1.6 ms walked node by node)."""
    d = axis_count.shape[0]
    backwards = sweep % (1 << d)
    strides = np.empty(d, np.int64)
    grid_strides(axis_count, strides)
    step = np.empty(d, np.int64)  # the index change of one step along each axis
    node = 0
    for k in range(d):
        if (backwards >> k) & 1:
            step[k] = -strides[k]
            node += (axis_count[k] - 1) * strides[k]
        else:
            step[k] = strides[k]
    n = out.shape[0]  # N; fewer: the order's first n nodes (0: none, to compile the kernel)
    layer = min(strides[0], n)
    first = np.empty(layer, np.int64)  # apart from ``out``, so that the adds below vectorise
    position = np.zeros(d, np.int64)
    for p in range(layer):
        first[p] = node
        k = d - 1
        while k >= 1:
            position[k] += 1
            if position[k] < axis_count[k]:
                node += step[k]
                break
            position[k] = 0
            node -= (axis_count[k] - 1) * step[k]
            k -= 1
    for i in range(axis_count[0]):
        start = i * strides[0]
        shift = i * step[0]
        count = min(layer, n - start)
        destination = out[start : start + count]  # a view from 0: the loop below vectorises
        for j in range(count):
            destination[j] = first[j] + shift


@njit(cache=True, inline="always")
def shape_of(shape_row_of, row_of, node):
    """The row of a node's exit shapes: its own row (shape_row_of None: each node has shapes of
    its own, renormalised once by ``discard_poorly_known_exits``) or its class's
    (shape_row_of (N,) int64: the nodes of a class share them, ``replay_classes``). Which it is,
    is a type, so that the kernels are compiled for each and hold no test of it."""
    if shape_row_of is None:
        return row_of[node]
    return shape_row_of[node]


@njit(cache=True)
def reach_sweep(
    exit_index, exit_weight, segment_cost, to_destination, row_of, shape_row_of, reached, order
):
    """One sweep of reachability in ``order`` (``sweep_order``), in place: a node with a row
    joins ``reached`` when some control leaves its cell (finite cost) for the destination or
    onto a face with at least one reached corner (weight > 0). Start from the destination nodes;
    repeat until nothing joins. The nodes never reached cannot reach the destination: their
    cost-to-go is inf. The exit tables as ``gauss_seidel_sweep`` takes them; reached: (N,)
    bool. Returns how many nodes joined."""
    joined = 0
    for p in range(order.shape[0]):
        node = order[p]
        row = row_of[node]
        if reached[node] or row < 0:
            continue
        shape = shape_of(shape_row_of, row_of, node)
        for u in range(segment_cost.shape[1]):
            if segment_cost[row, u] == np.inf:
                continue
            if to_destination[row, u]:
                reached[node] = True
            for i in range(exit_index.shape[2]):
                if exit_weight[shape, u, i] > 0.0 and reached[node + exit_index[shape, u, i]]:
                    reached[node] = True
                    break
            if reached[node]:
                joined += 1
                break
    return joined


@njit(cache=True)
def discard_poorly_known_exits(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    reachable,
    minimum_known_weight,
):
    """The paper's Figure 10: the cost-to-go at an exit is interpolated between the neighbours
    whose values are known, the reachable corners of its face, their weights renormalised (here,
    once, for nodes with shapes of their own, ``shape_of``; as they are read for shared shapes,
    ``known_value``); an exit whose reachable corners carry less than ``minimum_known_weight``
    of its weight (in (0, 1]; up to rounding, ``interpolate.falls_short``), or none, gets cost
    inf here. Afterwards every finite transition rests on reachable nodes. The exit tables as
    ``gauss_seidel_sweep`` takes them; reachable: (N,) bool."""
    for node in range(row_of.shape[0]):
        row = row_of[node]
        if row < 0:
            continue
        shape = shape_of(shape_row_of, row_of, node)
        for u in range(segment_cost.shape[1]):
            if segment_cost[row, u] == np.inf or to_destination[row, u]:
                continue
            known = 0.0
            for i in range(exit_index.shape[2]):
                w = exit_weight[shape, u, i]
                if w > 0.0 and reachable[node + exit_index[shape, u, i]]:
                    known += w
                elif shape_row_of is None:
                    exit_weight[shape, u, i] = 0.0
            if known == 0.0 or falls_short(known, minimum_known_weight):
                segment_cost[row, u] = np.inf
            elif shape_row_of is None:
                for i in range(exit_index.shape[2]):
                    exit_weight[shape, u, i] /= known


@njit(cache=True, inline="always")
def block_read(value, snapshot, low, high, corner):
    """The cost-to-go at ``corner`` as a sweep block [low, high) of node indices sees it
    (``blocked_gauss_seidel_sweep``): its own nodes' values as the sweep leaves them
    (``value``), the other blocks' as they stood when the sweep began (``snapshot``).
    snapshot None: one block, ``value`` alone (a type: compiled without the test, which in
    the plain sweep's loop cost four times its time)."""
    if snapshot is None:
        return value[corner]
    return value[corner] if low <= corner < high else snapshot[corner]


@njit(cache=True, inline="always")
def known_value(exit_index, exit_weight, shape, u, node, value, shape_row_of, snapshot, low, high):
    """The cost-to-go at the exit of (node, u): Σ w·V over the corners of its shape (row
    ``shape`` of the tables, corners as offsets from ``node``) whose value is known (finite:
    reachable), over the sum of their weights; zero-weight corners are skipped. Shapes of a
    node's own (shape_row_of None, ``shape_of``) have been renormalised already: Σ w·V. Values
    are read as the sweep block [low, high) sees them (``block_read``; snapshot None: all from
    ``value``)."""
    total = 0.0
    if shape_row_of is None:
        for i in range(exit_index.shape[2]):
            w = exit_weight[shape, u, i]
            if w != 0.0:
                total += w * block_read(value, snapshot, low, high, node + exit_index[shape, u, i])
        return total
    known = 0.0
    for i in range(exit_index.shape[2]):
        w = exit_weight[shape, u, i]
        if w != 0.0:
            v = block_read(value, snapshot, low, high, node + exit_index[shape, u, i])
            if v < np.inf:
                total += w * v
                known += w
    return total / known


@njit(cache=True, inline="always")
def _bellman(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    value,
    row,
    shape,
    node,
    shape_row_of,
    snapshot,
    low,
    high,
):
    """(min over u of cost(row, u) + the exit's cost-to-go (``known_value``, read as the block
    [low, high) sees it; 0 for an exit to the destination), the first minimising u); (inf, 0)
    where every control costs inf. Inlined where it is called (numba's ``inline="always"``): a
    call per node would cost more than the node's arithmetic."""
    best = np.inf
    choice = 0
    for u in range(segment_cost.shape[1]):
        cost = segment_cost[row, u]
        if cost == np.inf:
            continue
        candidate = cost
        if not to_destination[row, u]:
            candidate += known_value(
                exit_index, exit_weight, shape, u, node, value, shape_row_of, snapshot, low, high
            )
        if candidate < best:
            best = candidate
            choice = u
    return best, choice


@njit(cache=True, inline="always")
def block_positions(blocks, k, order):
    """(first, end): the positions in ``order`` (``sweep_order``) of sweep block k, the nodes
    [blocks[k], blocks[k + 1]) (blocks: (K + 1,) int64, node indices at boundaries between
    the first axis's layers, 0 and N at the ends). Each order runs through the first axis's
    layers forwards or backwards, so each block is a run of positions: forwards where the
    order starts in the first block."""
    n = order.shape[0]
    if blocks.shape[0] == 2 or order[0] < blocks[1]:
        return blocks[k], blocks[k + 1]
    return n - blocks[k + 1], n - blocks[k]


@njit(cache=True, inline="always")
def _bellman_block(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    order,
    first,
    end,
    low,
    high,
    settled_above,
    prefetching,
    control,
):
    """``gauss_seidel_sweep`` over the positions [first, end) of ``order``, reading values as
    the block of nodes [low, high) sees them (``block_read``); returns the largest decrease.
    ``prefetching``: ask the cache, a step before the sweep needs them, for the segment costs
    of the node 2·PREFETCH_AHEAD places ahead and the exit shapes (corners and weights) of the
    finite-cost controls of the node PREFETCH_AHEAD ahead. Written out in the loop: as an
    inlined function taking the tables, the hints took and dropped a reference to each table at
    every node (numba's reference counts). Measured on a car grid with exits of its own at every
    node (840,840 nodes, 1.2 GB of exit shapes; ``benchmarks/dp_sweeps.py``, mean over the
    2**5 orders): a blocked sweep 113 ms without hints, 115 ms with the inlined function, 105
    ms written out; the hints for the cost-to-go at the next node's corners (400 a node) cost
    more than they saved (117 ms) and are gone."""
    largest = 0.0
    for p in range(first, end):
        if prefetching:
            if p + 2 * PREFETCH_AHEAD < end:  # the segment costs, two steps ahead
                far = row_of[order[p + 2 * PREFETCH_AHEAD]]
                if far >= 0:
                    for u in range(0, segment_cost.shape[1], CACHE_LINE // segment_cost.itemsize):
                        prefetch(segment_cost, (far, u))
            if p + PREFETCH_AHEAD < end:  # the exit shapes of the finite-cost controls
                ahead_node = order[p + PREFETCH_AHEAD]
                ahead = row_of[ahead_node]
                if ahead >= 0:
                    ahead_shape = shape_of(shape_row_of, row_of, ahead_node)
                    per_line = CACHE_LINE // exit_index.itemsize
                    for u in range(segment_cost.shape[1]):
                        if segment_cost[ahead, u] != np.inf:
                            for i in range(0, exit_index.shape[2], per_line):
                                prefetch(exit_index, (ahead_shape, u, i))
                                prefetch(exit_weight, (ahead_shape, u, i))
        node = order[p]
        row = row_of[node]
        if row < 0 or is_destination[node]:
            continue
        old = value[node]
        if old == np.inf:  # unreachable: every exit reads only unknown corners (NaN or inf)
            continue
        best, choice = _bellman(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            value,
            row,
            shape_of(shape_row_of, row_of, node),
            node,
            shape_row_of,
            snapshot,
            low,
            high,
        )
        if best < old:
            value[node] = best
            control[node] = choice
            if old - best > largest and best < settled_above:
                largest = old - best
    return largest


@njit(cache=True)
def gauss_seidel_sweep(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    order,
    settled_above,
    prefetching,
    control,
):
    """One Gauss–Seidel sweep of value iteration over the nodes in ``order`` (``sweep_order``):
    each node's cost-to-go becomes ``min(old, update)`` at once, so the nodes after it in the
    sweep use it. Returns the largest decrease, s. control: (N,) int64, in place: where a
    node's value decreases, the control sample that gave the new value (the policy that
    ``policy_sweep`` follows).

    The exit tables: segment_cost and to_destination (R, U), one row per node that is not
    removed (row_of: (N,) int64, each node's row, -1: removed, skipped); the exits' shapes
    exit_index (int32 corner offsets from the node) and exit_weight (float32), (E, U,
    2**(d-1)), the row of a node's exits its own or, where shape_row_of is an array, its
    class's (``shape_of``). value: (N,) float64 cost-to-go, s, in place.
    Value iteration starts from an upper bound (0 at the destination nodes, a large finite
    ``UNKNOWN`` at the other reachable nodes: the paper's "values not yet known"; inf at
    unreachable nodes, which ``known_value`` leaves out), so values only decrease, as the paper
    describes; a node at inf is not swept (the car's unreachable 8 %). is_destination: (N,)
    bool, held at 0. A decrease to a value still at or above
    ``settled_above`` (s; inf: none) does not count in the largest decrease: such a node is a
    dead end (``known_weight``), whatever its exact bound. One thread, in a fixed order: the
    same result on any machine whatever the thread count (``blocked_gauss_seidel_sweep``: two
    threads, the same). ``prefetching``: ask the cache for the rows a few nodes ahead
    (``_bellman_block``; ``prefetch_pays``): half the orders run backwards through memory,
    where the processor's own prefetch falls behind on tables larger than its caches. The hint
    changes no value.
    """
    n = order.shape[0]
    # borrowed views (``kernels.borrowed``): with each class's shapes shared, the inlined
    # ``_bellman`` took and dropped references to the tables at every node (a one-block sweep of
    # park.ssc's 1.6 M nodes 286 ms, borrowed 254 ms); the arguments keep the arrays alive.
    # shape_row_of is borrowed in a call of its own: None unpacked from a tuple is no longer an
    # argument, whose ``is None`` numba decides when it compiles
    tables = (exit_index, exit_weight, segment_cost, to_destination, row_of)
    index, weight, cost, ends, rows = borrowed(tables)
    destination, values, nodes, controls = borrowed((is_destination, value, order, control))
    if shape_row_of is None:
        return _bellman_block(
            index, weight, cost, ends, rows, None, destination, values, None, nodes,
            0, n, 0, value.shape[0], settled_above, prefetching, controls,
        )  # fmt: skip
    return _bellman_block(
        index, weight, cost, ends, rows, borrowed(shape_row_of), destination, values, None, nodes,
        0, n, 0, value.shape[0], settled_above, prefetching, controls,
    )  # fmt: skip


@njit(cache=True, parallel=True)
def blocked_gauss_seidel_sweep(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    order,
    blocks,
    largest,
    settled_above,
    prefetching,
    control,
):
    """``gauss_seidel_sweep`` in blocks (``block_positions``; blocks (K + 1,) int64): the K
    blocks are swept side by side on numba's threads, each in its own part of the order,
    reading its own nodes' values as it updates them and the other blocks' from ``snapshot``
    (N,), ``value`` as it stood when the sweep began (``copy_block_edges``: at least every
    node read across a block's edge). Nothing a block reads depends on how the blocks are
    scheduled: the same result whatever the thread count. largest: (K,) work space. Returns
    the largest decrease, s."""
    for k in prange(blocks.shape[0] - 1):
        first, end = block_positions(blocks, k, order)
        largest[k] = _bellman_block(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            row_of,
            shape_row_of,
            is_destination,
            value,
            snapshot,
            order,
            first,
            end,
            blocks[k],
            blocks[k + 1],
            settled_above,
            prefetching,
            control,
        )
    return largest.max()


def policy_tables(rows: int, corners: int) -> tuple[np.ndarray, ...]:
    """The tables ``gather_policy`` fills for the policy sweeps, for ``rows`` nodes that are not
    removed and exits of ``corners`` (2**(d-1)) corners: policy_corner, policy_weight,
    policy_count, policy_cost, policy_known, and gathered (-1: nothing gathered yet)."""
    return (
        np.zeros((rows, corners), dtype=np.int32),
        np.zeros((rows, corners), dtype=np.float32),
        np.zeros(rows, dtype=np.int32),
        np.empty(rows),
        np.empty(rows),
        np.full(rows, -1, dtype=np.int64),
    )


@njit(cache=True)
def gather_policy(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    control,
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    gathered,
):
    """The exit of each node under its control (control: (N,) int64), compacted for
    ``policy_sweep`` to read in order instead of picking one control's exit out of every row
    of the full tables: for row R, its weighted corners that ``known_value`` reads, in its
    order, as node indices and weights (policy_corner (R, 2**(d-1)) int32, policy_weight
    float32, the first policy_count[R] (int32) of them), the segment's cost (policy_cost (R,),
    inf where the node is never updated: a destination, a discarded segment, an exit none of
    whose corners is known) and the sum that ``known_value`` divides by (policy_known (R,):
    the known corners' weight for shared shapes, 1 for a node's own, which are renormalised
    already; an exit to the destination has no corners). The corners with a known value
    (finite) are those of the start: value iteration only lowers finite values. Only the rows
    whose control differs from the one gathered before (gathered (R,) int64, -1: none yet)
    are rewritten: after the first Bellman sweeps few controls change. A sweep over these
    tables gives the values ``known_value`` would, bit for bit (the same sums in the same
    order), and reads about one cache line of them a node instead of the shape tables, the
    segment costs and the flags. One thread, like the sweeps of a grid swept in one block (a
    parallel loop here would be compiled for every grid)."""
    for node in range(row_of.shape[0]):
        row = row_of[node]
        if row < 0:
            continue
        u = control[node]
        if gathered[row] == u:
            continue
        gathered[row] = u
        cost = segment_cost[row, u]
        count = 0
        known = 0.0
        if is_destination[node]:
            cost = np.inf
        elif cost < np.inf and not to_destination[row, u]:
            shape = shape_of(shape_row_of, row_of, node)
            for i in range(exit_index.shape[2]):
                w = exit_weight[shape, u, i]
                if w != 0.0:
                    corner = node + exit_index[shape, u, i]
                    if shape_row_of is None or value[corner] < np.inf:
                        policy_corner[row, count] = corner
                        policy_weight[row, count] = w
                        known += w
                        count += 1
            if shape_row_of is not None and count == 0:
                cost = np.inf  # 0/0: known_value's NaN, which never lowers a value
        policy_cost[row] = cost
        policy_count[row] = count
        policy_known[row] = known if shape_row_of is not None and count > 0 else 1.0


@njit(cache=True, inline="always")
def _policy_block(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    snapshot,
    order,
    first,
    end,
    low,
    high,
    settled_above,
    prefetching,
):
    """``policy_sweep`` over the positions [first, end) of ``order``, reading values as the
    block of nodes [low, high) sees them (``block_read``), asking the cache ahead where
    ``prefetching``: the compact row of the node POLICY_PREFETCH_AHEAD places ahead, which in
    the orders that run some inner axes backwards and others forwards the processor's own
    prefetcher does not fetch in time (the car's policy sweep 12.5 ms on two threads without
    the hint, 10 ms with it, over the 2**5 orders). Written out in the loop: as an inlined
    function taking the tables, the hint took and dropped a reference to each table at every
    node (numba's reference counts), which made a one-block sweep of the car's tables 85 ms
    instead of 12. Returns the largest decrease."""
    largest = 0.0
    for p in range(first, end):
        if prefetching and p + POLICY_PREFETCH_AHEAD < end:
            ahead = row_of[order[p + POLICY_PREFETCH_AHEAD]]
            if ahead >= 0:
                prefetch(policy_corner, (ahead,))
                prefetch(policy_weight, (ahead,))
                prefetch(policy_count, (ahead,))
                prefetch(policy_cost, (ahead,))
                prefetch(policy_known, (ahead,))
        node = order[p]
        row = row_of[node]
        if row < 0:
            continue
        candidate = policy_cost[row]
        if candidate == np.inf:
            continue
        total = 0.0
        for i in range(policy_count[row]):
            total += policy_weight[row, i] * block_read(
                value, snapshot, low, high, policy_corner[row, i]
            )
        candidate += total / policy_known[row]
        old = value[node]
        if candidate < old:
            value[node] = candidate
            if old - candidate > largest and candidate < settled_above:
                largest = old - candidate
    return largest


@njit(cache=True)
def policy_sweep(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    order,
    settled_above,
    prefetching,
):
    """One Gauss–Seidel sweep in ``order`` of the Bellman update restricted to each node's
    control in the compact tables of ``gather_policy``: ``min(old, cost + the exit's
    cost-to-go)`` under that one control. Each update is the cost of a real control from the
    node, onto values that are themselves upper bounds, so values stay upper bounds of the
    cost-to-go and still only decrease; a sweep reads one control's exit per node instead of
    all of them. Returns the largest decrease, s (decreases to values at or above
    ``settled_above`` not counted, as in ``gauss_seidel_sweep``). ``prefetching``: ask the
    cache for the rows a few nodes ahead (``_policy_block``; ``prefetch_pays`` of the
    compact tables). The hint changes no value."""
    return _policy_block(
        policy_corner,
        policy_weight,
        policy_count,
        policy_cost,
        policy_known,
        row_of,
        value,
        None,
        order,
        0,
        order.shape[0],
        0,
        value.shape[0],
        settled_above,
        prefetching,
    )


@njit(cache=True, parallel=True)
def blocked_policy_sweep(
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    row_of,
    value,
    snapshot,
    order,
    blocks,
    largest,
    settled_above,
    prefetching,
):
    """``policy_sweep`` in blocks, as ``blocked_gauss_seidel_sweep`` runs them."""
    for k in prange(blocks.shape[0] - 1):
        first, end = block_positions(blocks, k, order)
        largest[k] = _policy_block(
            policy_corner,
            policy_weight,
            policy_count,
            policy_cost,
            policy_known,
            row_of,
            value,
            snapshot,
            order,
            first,
            end,
            blocks[k],
            blocks[k + 1],
            settled_above,
            prefetching,
        )
    return largest.max()


@njit(cache=True)
def copy_block_edges(value, snapshot, edges):
    """snapshot[a:b] = value[a:b] for each row (a, b) of ``edges`` ((M, 2) int64): the nodes
    that some sweep block reads across its edge (``gauss_seidel_sweep``)."""
    for m in range(edges.shape[0]):
        for node in range(edges[m, 0], edges[m, 1]):
            snapshot[node] = value[node]


@njit(cache=True)
def gauss_seidel_sweeps(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    is_destination,
    value,
    snapshot,
    blocks,
    edges,
    axis_count,
    first,
    count,
    tolerance,
    order,
    settled_above,
    prefetching,
    control,
    policy_corner,
    policy_weight,
    policy_count,
    policy_cost,
    policy_known,
    gathered,
    policy_sweeps,
):
    """Value iteration by modified policy iteration: Bellman sweeps (``gauss_seidel_sweep``),
    at most ``count`` of them, stopping after the first whose largest decrease is below
    ``tolerance`` (s); after each other one, up to ``policy_sweeps`` sweeps of the policy it
    left (``gather_policy``, ``policy_sweep``), stopping early once one of them changes less
    than ``tolerance``. Where Bellman sweeps shrink the largest change by only a few per cent a
    sweep (the policy's chain keeps returning to a few cells before it escapes: 130 of Luxo's
    191 sweeps, most of the car's 222), the policy has nearly settled; the policy sweeps
    run that slow mode down reading one control's exit per node from a compact table instead
    of all of them (about a tenth of a Bellman sweep's time). Every sweep takes the next of
    the orders of ``sweep_order``, counting from sweep number ``first``. The exit tables as
    ``gauss_seidel_sweep`` takes them; order: (N,) int64 and control (N,) int64 work space
    (control: zeros before the first call, kept between calls); policy_* and gathered:
    ``gather_policy``'s tables (gathered: -1 before the first call, kept between calls as the
    tables are); settled_above, prefetching: as ``gauss_seidel_sweep``. edges None: one block, each
    sweep ``gauss_seidel_sweep`` or ``policy_sweep`` (snapshot and blocks unread); else the
    blocked sweeps (``blocked_gauss_seidel_sweep``; snapshot, blocks as they take them), each
    from ``copy_block_edges`` (edges). Which it is, is a type: a grid swept in one block
    compiles no parallel sweep. Returns (Bellman sweeps run, policy sweeps run, the last
    Bellman sweep's largest decrease)."""
    block_largest = np.empty(blocks.shape[0] - 1)
    policy_prefetching = prefetch_pays(policy_corner, policy_weight)
    largest = np.inf
    sweep = first
    policy = 0
    for k in range(count):
        sweep_order(axis_count, sweep, order)
        sweep += 1
        if edges is None:
            largest = gauss_seidel_sweep(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                order,
                settled_above,
                prefetching,
                control,
            )
        else:
            copy_block_edges(value, snapshot, edges)
            largest = blocked_gauss_seidel_sweep(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                snapshot,
                order,
                blocks,
                block_largest,
                settled_above,
                prefetching,
                control,
            )
        if largest < tolerance:
            return k + 1, policy, largest
        if policy_sweeps > 0:
            gather_policy(
                exit_index,
                exit_weight,
                segment_cost,
                to_destination,
                row_of,
                shape_row_of,
                is_destination,
                value,
                control,
                policy_corner,
                policy_weight,
                policy_count,
                policy_cost,
                policy_known,
                gathered,
            )
        for _ in range(policy_sweeps):
            sweep_order(axis_count, sweep, order)
            sweep += 1
            policy += 1
            if edges is None:
                change = policy_sweep(
                    policy_corner,
                    policy_weight,
                    policy_count,
                    policy_cost,
                    policy_known,
                    row_of,
                    value,
                    order,
                    settled_above,
                    policy_prefetching,
                )
            else:
                copy_block_edges(value, snapshot, edges)
                change = blocked_policy_sweep(
                    policy_corner,
                    policy_weight,
                    policy_count,
                    policy_cost,
                    policy_known,
                    row_of,
                    value,
                    snapshot,
                    order,
                    blocks,
                    block_largest,
                    settled_above,
                    policy_prefetching,
                )
            if change < tolerance:
                break
    return count, policy, largest


@njit(cache=True)
def best_controls(
    exit_index,
    exit_weight,
    segment_cost,
    to_destination,
    row_of,
    shape_row_of,
    value,
    settled_above,
    best_control,
):
    """The minimising control sample index of every node (the first on ties; 0 where every
    sample costs inf, the node is removed or its value is inf: unreachable, where every sample's
    exit reads only unknown corners). best_control: (N,) int64 out. Returns the largest excess,
    s, of a node's Bellman update over its value, over the nodes whose value is above 0 (not a
    destination) and below ``settled_above`` (0 where there are none): at most 0 for values
    reached from an upper bound (each update only lowers a value that its own update does not
    exceed), above 0 where a value lies below what its best control gives, which no value
    iteration from above leaves (``ssc.solution.solve`` checks a warm start by it)."""
    excess = 0.0
    for node in range(value.shape[0]):
        row = row_of[node]
        if row < 0 or value[node] == np.inf:
            best_control[node] = 0
            continue
        best, choice = _bellman(
            exit_index,
            exit_weight,
            segment_cost,
            to_destination,
            value,
            row,
            shape_of(shape_row_of, row_of, node),
            node,
            shape_row_of,
            None,
            0,
            value.shape[0],
        )
        best_control[node] = choice
        if 0.0 < value[node] < settled_above and best - value[node] > excess:
            excess = best - value[node]
    return excess
