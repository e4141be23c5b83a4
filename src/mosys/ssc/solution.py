"""A ``Problem`` solved (paper §3.5): its kernels loaded (compiled once per machine), its exit
transitions computed (``ssc.exits``), value iteration run to the tolerance with progress
(``kernels.dp``), in two blocks side by side on a large grid (``sweep_blocks``), and the
optimal controls, reachable nodes and destinations found (``Solution``); for a lookahead table
that asks for it, the cost-to-go to the whole arrival box too (``arrival_solution``).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from types import ModuleType

import numpy as np

from mosys.io.progress import Progress
from mosys.kernels.compile_lock import CompilationBusyError, deferring
from mosys.kernels.dp import (
    DEAD_END_BOUND,
    DEAD_END_SECONDS,
    UNKNOWN,
    best_controls,
    discard_poorly_known_exits,
    gauss_seidel_sweeps,
    policy_tables,
    prefetch_pays,
    reach_sweep,
    sweep_order,
)
from mosys.kernels.dp_destinations import (
    DESTINATION_MAX_SWEEPS,
    DESTINATION_TOLERANCE,
    destination_indices,
)
from mosys.kernels.dp_exits import (
    SEGMENT_BOX_COLUMNS,
    exit_transitions_template,
    replay_classes,
    segment_boxes,
)
from mosys.kernels.specialise import specialise
from mosys.ssc.exits import (
    MotionClasses,
    Transitions,
    check_transitions_finite,
    compute_transitions,
    exit_transition_arguments,
    no_record,
)
from mosys.ssc.problem import Problem

SWEEPS_PER_CALL = 8  # value-iteration (Bellman) sweeps between progress updates
POLICY_SWEEPS = 16  # at most, after each Bellman sweep (``dp.gauss_seidel_sweeps``)
BLOCKED_SWEEP_NODES = 200_000  # grids with at least this many nodes are swept in two blocks
# side by side (``sweep_blocks``); a smaller one's sweeps take milliseconds on one thread, and
# one block converges in fewer of them


def reachable_nodes(
    transitions: Transitions, destination: np.ndarray, axis_count: np.ndarray
) -> np.ndarray:
    """(N,) bool: the nodes from which some sequence of controls leads to the destination (every
    step onto a face with a weight on a node already known to lead there), by sweeps in the
    orders of ``sweep_order`` until one adds nothing."""
    reached = destination & (transitions.row_of >= 0)
    order = np.empty(reached.shape[0], dtype=np.int64)
    sweep = 0
    while True:
        sweep_order(axis_count, sweep, order)
        if not reach_sweep(*transitions.arrays(), reached, order):
            return reached
        sweep += 1


@dataclass(frozen=True)
class Solution:
    """The DP's result: cost-to-go (N,) s, inf where unreachable or a dead end; best control
    index (N,); dead_end (N,) bool: reachable nodes from which no exit that ``known_weight``
    trusts leads to the destination (none when the spec has no ``known_weight``).
    destination_index (N,) int64, for a spec with several ``dest`` lines (None otherwise): the
    line each node's optimal path ends at, -1 where the value is inf
    (``dp_destinations.destination_indices``)."""

    value: np.ndarray
    best_control: np.ndarray
    dead_end: np.ndarray
    iterations: int
    policy_sweeps: int
    residual: float
    transition_seconds: float
    iteration_seconds: float
    kernel_load_seconds: float
    destination_index: np.ndarray | None = None


def load_kernels(
    exit_transitions: Callable,
    arguments: tuple,
    problem: Problem,
    classes: MotionClasses | None,
) -> float:
    """Load (or compile, on a cold cache) every kernel of ``solve`` and start numba's threads,
    by calling each on no nodes, so that the DP's timings are the DP's; returns the seconds.
    A kernel that another process is compiling is left for last (``compile_lock.deferring``):
    two jobs started together on a cold cache compile different kernels side by side, then each
    loads what the other compiled. arguments: ``exit_transition_arguments``."""
    started = time.perf_counter()
    none = np.empty(0, dtype=np.int64)
    before, obstacles, arrival = arguments
    flags = np.empty(0, dtype=np.bool_)
    empty = Transitions.empty(flags, problem.control_samples.shape[0], len(problem.grid.names))
    if classes is not None:  # the sweeps' variant for shared shapes (``dp.shape_of``)
        empty = replace(empty, shape_row_of=empty.row_of)
    size = problem.base_state.shape[0]
    loads = [
        lambda: exit_transitions(
            *before, none, none, *obstacles, *arrival, *empty.outputs(), *no_record(size)
        ),
        lambda: reach_sweep(*empty.arrays(), flags, none),
        lambda: discard_poorly_known_exits(*empty.arrays(), flags, 1.0),
        lambda: gauss_seidel_sweeps(
            *empty.arrays(),
            flags,
            np.empty(0),
            np.empty(0),
            np.zeros(2, dtype=np.int64),
            # edges: the variant that ``sweep_blocks`` is likely to choose (one block: None)
            None if problem.grid.node_count < BLOCKED_SWEEP_NODES else np.empty((0, 2), np.int64),
            problem.grid.axis_count,
            0,
            0,
            1.0,
            none,
            1.0,
            False,  # prefetching: a flag, whose type is all that compiling needs
            none,
            *policy_tables(empty.segment_cost.shape[0], empty.exit_index.shape[2]),
            0,
        ),
        lambda: best_controls(*empty.arrays(), np.empty(0), 1.0, none),
        lambda: sweep_order(problem.grid.axis_count, 0, none),
    ]
    if classes is not None:
        _, record_start, record_count, record, relative_slot = no_record(size)
        boxes = np.empty((0, 0, SEGMENT_BOX_COLUMNS))
        loads.append(
            lambda: segment_boxes(
                record,
                record_start,
                record_count,
                *obstacles[:2],
                arrival[0],
                *arrival[2:],
                before[4],
                boxes,
            )
        )
        loads.append(
            lambda: replay_classes(
                *before[:7],
                before[9],
                none,
                none,
                none,
                *obstacles,
                *arrival,
                empty.segment_cost,
                record_start,
                record_count,
                record,
                relative_slot,
                boxes,
                empty.segment_cost,
                empty.to_destination,
            )
        )
    if len(problem.spec.destinations) > 1:
        loads.append(
            lambda: destination_indices(
                empty.exit_index,
                empty.exit_weight,
                empty.to_destination,
                none,
                empty.shape_row_of,
                none,
                flags,
                0,
                np.empty(0),
                none,
                problem.grid.axis_count,
                DESTINATION_TOLERANCE,
                1,
                none,
                np.empty((0, 2)),
                none,
            )
        )
    busy = []
    with deferring():
        for load in loads:
            try:
                load()
            except CompilationBusyError:
                busy.append(load)
    for load in busy:
        load()  # waits for the other process's compilation, then loads it
    return time.perf_counter() - started


def sweep_blocks(
    axis_count: np.ndarray, transitions: Transitions
) -> tuple[np.ndarray, np.ndarray | None]:
    """(blocks, edges) for the value iteration's sweeps (``dp.gauss_seidel_sweeps``): on a grid
    of at least BLOCKED_SWEEP_NODES nodes, two blocks of the first axis's layers, split where
    each holds about half the nodes that are not removed (each block is one thread's work),
    and the node ranges a block reads across the split: as many layers on each side of it as
    the farthest exit corner (with a weight) lies from its node, in node indices. Else, or
    where those ranges would cover the grid (an exit corner wrapping around the first axis),
    one block [0, N] and edges None: the plain sweeps. Depends on the problem alone, so the
    tables are the same whatever the thread count."""
    nodes = int(np.prod(axis_count))
    layers = int(axis_count[0])
    layer = nodes // layers
    one_block = np.array([0, nodes], dtype=np.int64), None
    if nodes < BLOCKED_SWEEP_NODES:
        return one_block
    weighted = transitions.exit_weight != 0
    reach = int(np.abs(transitions.exit_index[weighted]).max()) if weighted.any() else 0
    span = -(-reach // layer)  # layers a read may cross
    rows = np.cumsum((transitions.row_of >= 0).reshape(layers, layer).sum(axis=1))
    split = int(np.searchsorted(rows, rows[-1] / 2)) + 1
    if split - span < 0 or split + span > layers or split >= layers:
        return one_block
    blocks = np.array([0, split * layer, nodes], dtype=np.int64)
    edges = np.array([[(split - span) * layer, (split + span) * layer]], dtype=np.int64)
    return blocks, edges


def value_iteration(
    problem: Problem,
    transitions: Transitions,
    reachable: np.ndarray,
    tolerance: float,
    max_iterations: int,
    quiet: bool,
    warm: np.ndarray | None = None,
) -> tuple[np.ndarray, int, int, float]:
    """Bellman sweeps, each followed by up to POLICY_SWEEPS sweeps of its policy
    (``dp.gauss_seidel_sweeps``), in the orders of ``dp.sweep_order`` until a Bellman sweep's
    largest decrease < tolerance (s) or ``max_iterations`` Bellman sweeps, from the paper's upper
    bound, or where ``warm`` (N,) s is finite at a reachable node, from it (an upper bound of
    this problem's cost-to-go: ``solve`` checks it); returns the cost-to-go (N,) s, the Bellman
    sweeps, the policy sweeps and the last Bellman sweep's largest decrease."""
    grid = problem.grid
    bound = DEAD_END_BOUND if problem.spec.known_weight else UNKNOWN
    if warm is not None:
        bound = np.where(np.isfinite(warm), warm, bound)
    value = np.where(problem.is_destination, 0.0, np.where(reachable, bound, np.inf))
    blocks, edges = sweep_blocks(grid.axis_count, transitions)
    snapshot = value.copy() if edges is not None else value  # one block reads value alone
    order = np.empty(grid.node_count, dtype=np.int64)
    control = np.zeros(grid.node_count, dtype=np.int64)
    policy = policy_tables(transitions.segment_cost.shape[0], transitions.exit_index.shape[2])
    prefetching = prefetch_pays(transitions.exit_index, transitions.exit_weight)
    progress = Progress("value iteration", max_iterations, "sweeps", at_most=True)
    residual = np.inf
    iterations = 0
    policy_sweeps = 0
    while iterations < max_iterations and not residual < tolerance:
        swept, followed, residual = gauss_seidel_sweeps(
            *transitions.arrays(),
            problem.is_destination,
            value,
            snapshot,
            blocks,
            edges,
            grid.axis_count,
            iterations + policy_sweeps,
            min(SWEEPS_PER_CALL, max_iterations - iterations),
            tolerance,
            order,
            DEAD_END_SECONDS if problem.spec.known_weight else np.inf,
            prefetching,
            control,
            *policy,
            POLICY_SWEEPS,
        )
        iterations += swept
        policy_sweeps += followed
        if not quiet:
            progress.update(iterations, f"largest change {residual:.3g} s")
    if not quiet:
        progress.finish(f"largest change {residual:.3g} s")
    return value, iterations, policy_sweeps, float(residual)


def solve(
    problem: Problem,
    dynamics: ModuleType,
    tolerance: float,
    max_iterations: int,
    dt: float,
    node_valid: np.ndarray | None = None,
    quiet: bool = False,
    aim: float | None = None,
    warm: np.ndarray | None = None,
) -> Solution:
    """Exit transitions once (integrator steps of at most ``dt`` s), then Bellman sweeps until the
    largest decrease < tolerance (s) or ``max_iterations`` sweeps. ``node_valid``: (N,) bool,
    False for further nodes to remove (on top of ``problem.node_valid``); ``aim``: the scale of
    a lookahead table's arrival box the segments end in (None: the spec's). The kernels are
    loaded first, outside the DP's timings (``kernel_load_seconds``). With the spec's
    ``known_weight``, exits resting on less of it than that cost inf, values start from
    DEAD_END_BOUND, and the nodes left at DEAD_END_SECONDS or more are dead ends (inf).
    ``warm`` (N,) s: values believed to bound this problem's cost-to-go from above (a cost-to-go
    of the same grid to a smaller target), from which the sweeps start where they are finite;
    where the result leaves some node below what its best control gives by more than the
    tolerance (``dp.best_controls``), the belief was wrong there, and the sweeps run again
    from the bound.
    """
    grid = problem.grid
    valid = problem.node_valid if node_valid is None else problem.node_valid & node_valid
    exit_transitions = specialise(exit_transitions_template, dynamics, parallel=True)
    arguments = exit_transition_arguments(problem, dynamics, dt, aim)
    classes = MotionClasses.of(problem, dynamics)
    kernel_load_seconds = load_kernels(exit_transitions, arguments, problem, classes)
    started = time.perf_counter()
    transitions = compute_transitions(exit_transitions, arguments, problem, valid, classes, quiet)
    check_transitions_finite(problem, transitions)
    transition_seconds = time.perf_counter() - started
    reachable = reachable_nodes(transitions, problem.is_destination, grid.axis_count)
    discard_poorly_known_exits(*transitions.arrays(), reachable, problem.spec.known_weight)
    settled_above = DEAD_END_SECONDS if problem.spec.known_weight else np.inf
    best_control = np.empty(grid.node_count, dtype=np.int64)
    for start in (warm, None) if warm is not None else (None,):
        value, iterations, policy_sweeps, residual = value_iteration(
            problem, transitions, reachable, tolerance, max_iterations, quiet, start
        )
        excess = best_controls(*transitions.arrays(), value, settled_above, best_control)
        if start is None or excess <= tolerance:
            break
        if not quiet:
            print(
                f"the warm start lay below the cost-to-go (by up to {excess:.3g} s): "
                "the sweeps again from the bound",
                file=sys.stderr,
                flush=True,
            )
    iteration_seconds = time.perf_counter() - started - transition_seconds
    dead_end = reachable & (value >= DEAD_END_SECONDS) & bool(problem.spec.known_weight)
    value = np.where(reachable & ~dead_end, value, np.inf)
    destination_index = None
    if len(problem.spec.destinations) > 1:
        destination_index = np.empty(grid.node_count, dtype=np.int64)
        destination_indices(
            transitions.exit_index,
            transitions.exit_weight,
            transitions.to_destination,
            transitions.row_of,
            transitions.shape_row_of,
            best_control,
            reachable,
            int(np.flatnonzero(problem.is_destination)[0]),
            value,
            problem.destination_label,
            grid.axis_count,
            DESTINATION_TOLERANCE,
            DESTINATION_MAX_SWEEPS,
            np.empty(grid.node_count, dtype=np.int64),
            np.empty((grid.node_count, len(problem.spec.destinations))),
            destination_index,
        )
    return Solution(
        value,
        best_control,
        dead_end,
        iterations,
        policy_sweeps,
        residual,
        transition_seconds,
        iteration_seconds,
        kernel_load_seconds,
        destination_index,
    )


def arrival_solution(
    problem: Problem,
    dynamics: ModuleType,
    solution: Solution,
    tolerance: float,
    max_iterations: int,
    quiet: bool,
) -> Solution | None:
    """For a lookahead table whose policy line asks for ``arrival_value``, the DP whose segments
    end in the whole arrival box (aim 1): the cost-to-go to the arrival the runtime brakes
    into, where the table's own (``solution``) is to the box scaled by its ``aim`` (README,
    "The self-parking car"); ``solution`` itself where the aim is 1 already. None for any other
    table. Its sweeps start from ``solution``'s cost-to-go: a segment that reaches the aimed
    box has passed through the whole box, so the whole box is usually nearer (``solve`` checks
    it, and starts again from the bound where it is not)."""
    policy = problem.spec.policy
    if policy is None or policy.kind != "lookahead" or not policy.arrival_value:
        return None
    if policy.aim == 1.0:
        return solution
    if not quiet:
        print("the DP again, aiming at the whole arrival box:", file=sys.stderr, flush=True)
    return solve(
        problem,
        dynamics,
        tolerance,
        max_iterations,
        problem.spec.dt,
        quiet=quiet,
        aim=1.0,
        warm=solution.value,
    )
