"""Controller generation (paper §3.4–3.5): a ``.ssc`` spec and a figure's dynamics → a table.

Validation against the figure, array set-up and the HDF5 write live here; the numeric work is in
``mosys.kernels.dp_exits`` (the exit transitions), ``mosys.kernels.dp`` (value iteration) and
``mosys.kernels.dp_destinations`` (which destination a node's path ends at).
"""

from __future__ import annotations

import itertools
import json
import resource
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from types import ModuleType

import numpy as np
from numba import get_num_threads

from mosys import __version__
from mosys.errors import SimulationError
from mosys.io.controller_table import ControllerTable, write_controller_table
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
    free_nodes,
    node_coordinates,
    replay_classes,
    segment_boxes,
)
from mosys.kernels.specialise import specialise
from mosys.limits import check_job
from mosys.parsing.controller import ControllerSpec
from mosys.parsing.tokens import location
from mosys.ssc.grid import (
    FigureGrid,
    control_scale,
    control_units,
    figure_grid,
    figure_state_names,
)
from mosys.ssc.lookahead import vehicle_arrival
from mosys.ssc.obstacles import NO_OBSTACLES, Obstacles, blocked_reason, spec_obstacles

PROGRESS_CHUNKS = 20  # at most; fewer for small grids (each chunk wakes numba's threads)
SIMULATIONS_PER_CHUNK = 20_000  # at least, but for the last chunk
SWEEPS_PER_CALL = 8  # value-iteration (Bellman) sweeps between progress updates
POLICY_SWEEPS = 16  # at most, after each Bellman sweep (``dp.gauss_seidel_sweeps``)
BLOCKED_SWEEP_NODES = 200_000  # grids with at least this many nodes are swept in two blocks
# side by side (``sweep_blocks``); a smaller one's sweeps take milliseconds on one thread, and
# one block converges in fewer of them


@dataclass(frozen=True)
class Problem:
    """Everything the DP kernels need for one spec, SI units."""

    spec: ControllerSpec
    grid: FigureGrid
    base_state: np.ndarray  # (S,) values of the state slots the controller leaves out
    control_samples: np.ndarray  # (U, m) every combination of the sampled controls, spec units
    control_scale: np.ndarray  # (m,) spec unit -> SI factor of each control
    control_slot: np.ndarray  # (m,) entry of the model's inputs each control drives
    input_size: int  # how many inputs the model takes
    is_destination: np.ndarray  # (N,) bool: the nodes of any dest line
    destination_label: np.ndarray  # (N,) int64: the first dest line a node matches, else -1
    obstacles: Obstacles
    node_valid: np.ndarray  # (N,) bool: False for nodes removed (collision, outside the domain)


def build_problem(spec: ControllerSpec, dynamics: ModuleType) -> Problem:
    """Check the spec against the figure (SpecError naming the line) and lay out the arrays."""
    names = figure_state_names(dynamics)
    ordered = spec.ordered_state(names)
    grid = figure_grid(
        dynamics,
        tuple(d.name for d in ordered),
        np.array([d.minimum for d in ordered]),
        np.array([d.step for d in ordered]),
        np.array([d.samples for d in ordered]),
        np.array([d.wrap for d in ordered]),
    )
    for k, dimension in enumerate(ordered):
        if dimension.wrap and grid.units[k] == "deg" and abs(dimension.period - 360.0) > 1e-9:
            raise spec.error(
                dimension.token,
                f"an angle whose wrap period samples*step is 360 deg (it is {dimension.period:g})",
            )
    actuators = tuple(dynamics.INPUT_NAMES)
    control_slot = []
    for control in spec.controls:
        if control.name not in actuators or not control.name:
            choices = ", ".join(f"'{a}'" for a in actuators if a)
            raise spec.error(
                control.token, f"an actuator of figure '{spec.figure}' (one of {choices})"
            )
        control_slot.append(actuators.index(control.name))
    check_policy(spec, dynamics)
    samples = np.array(
        list(itertools.product(*(control.values() for control in spec.controls))),
        dtype=np.float64,
    ).reshape(-1, len(spec.controls))
    destination_label = destination_labels(spec, grid)
    is_destination = np.ascontiguousarray(destination_label >= 0)
    base_state = np.zeros(len(names))
    obstacles = spec_obstacles(spec, dynamics, grid)
    node_valid = np.ones(grid.node_count, dtype=np.bool_)
    if obstacles.active:
        free_nodes(
            grid.axis_min,
            grid.axis_step,
            grid.axis_count,
            grid.state_slot,
            base_state,
            *obstacles.kernel_arguments(),
            node_valid,
        )
        blocked = np.flatnonzero(is_destination & ~node_valid)
        if blocked.size:
            line = spec.destinations[int(destination_label[blocked[0]])]
            state = np.empty(len(grid.names))
            node_coordinates(grid.axis_min, grid.axis_step, grid.axis_count, blocked[0], state)
            pose = np.array([state[grid.names.index(n)] for n in ("x", "y", "heading")])
            reason = blocked_reason(spec, obstacles, pose)
            raise spec.error(line[0].token, f"a destination the car can occupy ({reason})")
    return Problem(
        spec=spec,
        grid=grid,
        base_state=base_state,
        control_samples=np.ascontiguousarray(samples),
        control_scale=np.array([control_scale(dynamics, c.name) for c in spec.controls]),
        control_slot=np.array(control_slot, dtype=np.int64),
        input_size=len(actuators),
        is_destination=is_destination,
        destination_label=destination_label,
        obstacles=obstacles,
        node_valid=node_valid,
    )


def destination_labels(spec: ControllerSpec, grid: FigureGrid) -> np.ndarray:
    """(N,) int64: for each node, the index of the first ``dest`` line (file order) whose
    coordinates it matches (dimensions a line does not name are free), -1 for the other nodes.
    The DP's destination is the union of these node sets."""
    label = np.full(grid.shape, -1, dtype=np.int64)
    for number, line in enumerate(spec.destinations):
        destination = np.ones(grid.shape, dtype=bool)
        for entry in line:
            axis = grid.names.index(entry.name)
            on_node = np.zeros(grid.shape[axis], dtype=bool)
            on_node[entry.index] = True
            broadcast = [1] * len(grid.names)
            broadcast[axis] = grid.shape[axis]
            destination &= on_node.reshape(broadcast)
        label[destination & (label < 0)] = number
    return np.ascontiguousarray(label.reshape(-1))


def check_policy(spec: ControllerSpec, dynamics: ModuleType) -> None:
    """SpecError at the ``policy`` line when ``lookahead`` cannot run the figure: it steers and
    brakes a vehicle, and brakes no harder than the ``wheel_accel`` samples reach."""
    if spec.policy is None or spec.policy.kind != "lookahead":
        return
    if getattr(dynamics, "MODEL_KIND", "figure") != "vehicle":
        raise spec.error(
            spec.policy.token, f"'interpolate': figure '{spec.figure}' is not a vehicle"
        )
    accel = [control for control in spec.controls if control.name == "wheel_accel"]
    if not accel:
        raise spec.error(spec.policy.token, "a torq line for wheel_accel (lookahead brakes by it)")
    if not accel[0].minimum < 0.0 < accel[0].maximum:
        raise spec.error(
            spec.policy.token,
            f"a wheel_accel range from below 0 to above 0 (line {accel[0].token.line}): "
            "lookahead brakes by it",
        )


def policy_attributes(spec: ControllerSpec) -> dict:
    """Root attrs ``policy`` (how the table runs) and, for ``lookahead``,
    ``arrival_tolerance`` (JSON object: dest name -> tolerance, spec units) and
    ``arrival_aim`` (the DP's box: the arrival box scaled by it)."""
    if spec.policy is None or spec.policy.kind == "interpolate":
        return {"policy": "interpolate"}
    return {
        "policy": "lookahead",
        "arrival_tolerance": json.dumps(dict(spec.policy.arrival)),
        "arrival_aim": spec.policy.aim,
    }


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


@dataclass(frozen=True)
class Transitions:
    """What the exit transitions give (``dp.gauss_seidel_sweep`` reads them): segment_cost (R,
    U) s and to_destination (R, U) bool, one row per node that is not removed (row_of (N,)
    int64, each node's row, -1 for a removed node, which takes no memory); the exits' shapes
    exit_index (E, U, 2**(d-1)) int32 (corner offsets from the node) and exit_weight float32:
    each node's own (shape_row_of None: E = R) or its class's, row shape_row_of[node]
    (``MotionClasses``; ``dp.shape_of``)."""

    exit_index: np.ndarray
    exit_weight: np.ndarray
    segment_cost: np.ndarray
    to_destination: np.ndarray
    row_of: np.ndarray
    shape_row_of: np.ndarray | None

    @classmethod
    def empty(cls, valid: np.ndarray, controls: int, dimensions: int) -> Transitions:
        """Tables for the nodes where ``valid`` (N,) bool is True, a shape for each."""
        corners = 1 << (dimensions - 1)
        rows = int(valid.sum())
        row_of = np.full(valid.shape[0], -1, dtype=np.int64)
        row_of[valid] = np.arange(rows)
        return cls(
            np.zeros((rows, controls, corners), dtype=np.int32),
            np.zeros((rows, controls, corners), dtype=np.float32),
            np.empty((rows, controls)),
            np.zeros((rows, controls), dtype=np.bool_),
            row_of,
            None,
        )

    def arrays(self) -> tuple[np.ndarray | None, ...]:
        """The tables as the kernels take them: exit_index, exit_weight, segment_cost,
        to_destination, row_of, shape_row_of."""
        return (
            self.exit_index,
            self.exit_weight,
            self.segment_cost,
            self.to_destination,
            self.row_of,
            self.shape_row_of,
        )

    def outputs(self) -> tuple[np.ndarray | None, ...]:
        """What ``dp_exits.exit_transitions_template`` writes: exit_index, exit_weight,
        segment_cost, to_destination."""
        return self.arrays()[:4]


def exit_transition_arguments(
    problem: Problem, dynamics: ModuleType, dt: float, aim: float | None = None
) -> tuple[tuple, tuple, tuple]:
    """The exit-transition kernel's arguments (``dp_exits.exit_transitions_template``) before
    ``nodes``, its obstacles and its arrival box (``arrival_arguments``, scaled by ``aim``), SI."""
    grid = problem.grid
    # the kernels take SI controls; K stays per spec unit: K |u_spec| = (K / scale) |u_SI|
    samples_si = np.ascontiguousarray(problem.control_samples * problem.control_scale)
    effort = np.array([c.effort_weight for c in problem.spec.controls]) / problem.control_scale
    before = (
        grid.axis_min,
        grid.axis_step,
        grid.axis_count,
        grid.wrap,
        grid.state_slot,
        problem.base_state,
        samples_si,
        problem.control_slot,
        problem.input_size,
        effort,
        float(dt),
    )
    arrival = arrival_arguments(problem, dynamics, aim)
    return before, problem.obstacles.kernel_arguments(), arrival


def arrival_arguments(problem: Problem, dynamics: ModuleType, aim: float | None = None) -> tuple:
    """The exit kernel's arrival arguments (``dp_exits.exit_transitions_template``): a lookahead
    table's arrival box scaled by ``aim`` (None: the spec's ``aim``; README, "The self-parking
    car") and braking, else a disabled placeholder."""
    spec, grid = problem.spec, problem.grid
    if spec.policy is None or spec.policy.kind != "lookahead":
        return no_arrival(len(grid.names))
    scale = spec.policy.aim if aim is None else aim
    control = next(c for c in spec.controls if c.name == "wheel_accel")
    arrival = vehicle_arrival(
        dynamics,
        grid,
        spec.destination_values(),
        {name: scale * tolerance for name, tolerance in spec.policy.arrival},
        min(abs(control.minimum), abs(control.maximum)),
    )
    return (
        True,
        arrival.box,
        arrival.vehicle_slot,
        arrival.wheelbase,
        arrival.wheel_radius,
        arrival.brake,
    )


def no_arrival(dimensions: int) -> tuple:
    """The exit kernel's arrival arguments for a table without an arrival box."""
    return False, np.zeros((3, dimensions)), np.zeros(7, dtype=np.int64), 1.0, 1.0, 1.0


def no_record(size: int) -> tuple:
    """The exit kernel's record arguments when it records nothing (model state size S)."""
    empty = np.zeros((0, 0), dtype=np.int64)
    return False, empty, empty, np.zeros((0, size + 1)), np.zeros(size, dtype=np.bool_)


@dataclass(frozen=True)
class MotionClasses:
    """The nodes that move alike: for a model whose equations read none of the controller axes
    its ``IGNORABLE_STATES`` names (axes that do not wrap and have at least 3 nodes), every
    node of a class (the nodes differing only on those axes) moves the same way under a
    control, shifted (``dp_exits.replay_classes``). class_of (N,) int64; representative (C,)
    int64: a node of each class, in the middle of the ignorable axes, so that its exits stay on
    the grid; relative_slot (S,) bool: the model-state slots of the ignorable axes."""

    class_of: np.ndarray
    representative: np.ndarray
    relative_slot: np.ndarray

    @classmethod
    def of(cls, problem: Problem, dynamics: ModuleType) -> MotionClasses | None:
        """The classes of ``problem``'s grid, or None when no controller axis is ignorable."""
        grid = problem.grid
        names = getattr(dynamics, "IGNORABLE_STATES", ())
        ignorable = np.array(
            [
                name in names and not wraps and count >= 3
                for name, wraps, count in zip(grid.names, grid.wrap, grid.axis_count, strict=True)
            ]
        )
        if not ignorable.any():
            return None
        index = np.indices(grid.shape).reshape(len(grid.shape), -1)
        class_shape = tuple(1 if ignorable[k] else n for k, n in enumerate(grid.shape))
        index[ignorable] = 0
        class_of = np.ravel_multi_index(tuple(index), class_shape).astype(np.int64)
        members = np.unravel_index(np.arange(int(np.prod(class_shape))), class_shape)
        middle = tuple(
            np.full_like(m, grid.shape[k] // 2) if ignorable[k] else m
            for k, m in enumerate(members)
        )
        representative = np.ravel_multi_index(middle, grid.shape).astype(np.int64)
        relative_slot = np.zeros(problem.base_state.shape[0], dtype=np.bool_)
        relative_slot[grid.state_slot[ignorable]] = True
        return cls(class_of, representative, relative_slot)


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


def compute_transitions(
    exit_transitions: Callable,
    arguments: tuple,
    problem: Problem,
    valid: np.ndarray,
    classes: MotionClasses | None,
    quiet: bool,
) -> Transitions:
    """The exit transitions of the nodes where ``valid`` (N,) bool is True, in chunks of nodes,
    showing progress unless ``quiet``; with ``classes``, each class's segments are integrated
    once (``record_classes``) and replayed at its nodes (``dp_exits.replay_classes``), which share
    its exit shapes. arguments: ``exit_transition_arguments``."""
    before, obstacles, arrival = arguments
    controls = problem.control_samples.shape[0]
    size = problem.base_state.shape[0]
    transitions = Transitions.empty(valid, controls, len(problem.grid.names))
    if classes is not None:
        shapes, record = record_classes(exit_transitions, arguments, problem, classes)
        transitions = replace(
            transitions,
            exit_index=shapes.exit_index,
            exit_weight=shapes.exit_weight,
            shape_row_of=np.where(transitions.row_of >= 0, classes.class_of, -1),
        )
    nodes = np.flatnonzero(transitions.row_of >= 0)
    progress = Progress("exit transitions", nodes.size * controls, "simulations")
    count = max(1, min(PROGRESS_CHUNKS, nodes.size * controls // SIMULATIONS_PER_CHUNK))
    done = 0
    for chunk in (dealt(nodes[k::count]) for k in range(count)):
        if classes is None:
            exit_transitions(
                *before,
                chunk,
                transitions.row_of,
                *obstacles,
                *arrival,
                *transitions.outputs(),
                *no_record(size),
            )
        else:
            replay_classes(
                *before[:7],
                before[9],
                chunk,
                transitions.row_of,
                classes.class_of,
                *obstacles,
                *arrival,
                shapes.segment_cost,
                *record,
                transitions.segment_cost,
                transitions.to_destination,
            )
        done += chunk.size * controls
        if not quiet:
            progress.update(done)
    if not quiet:
        progress.finish()
    return transitions


def dealt(nodes: np.ndarray) -> np.ndarray:
    """``nodes`` (M,) int64 dealt to numba's threads like cards, for a ``prange`` over them: its
    static schedule gives each of T threads one contiguous share, which now holds every T-th node
    and so a sample of the whole grid rather than one region of it (a node's segments cost more
    in some regions than others: Luxo's exit transitions took a median of 1.77 s on two threads
    in grid order, 1.44 s dealt, 12 runs each). The order of the nodes changes nothing else: each
    node's transitions are computed on their own and written to its own row."""
    threads = get_num_threads()
    return np.concatenate([nodes[t::threads] for t in range(threads)])


def record_classes(
    exit_transitions: Callable, arguments: tuple, problem: Problem, classes: MotionClasses
) -> tuple[Transitions, tuple]:
    """Integrate each class's segments once from its representative, without obstacles or
    arrival box (``recording``: the steps counted, then written) and return the class's exits
    (one row per class: its shapes and costs) and ``dp_exits.replay_classes``'s record arguments
    (record_start, record_count, record, relative_slot, the segment boxes)."""
    before, obstacles, arrival = arguments
    grid = problem.grid
    size = problem.base_state.shape[0]
    row_of = np.full(grid.node_count, -1, dtype=np.int64)
    row_of[classes.representative] = np.arange(classes.representative.size)
    shapes = Transitions.empty(row_of >= 0, problem.control_samples.shape[0], len(grid.names))
    record_start = np.zeros(shapes.segment_cost.shape, dtype=np.int64)
    record_count = np.zeros_like(record_start)
    record = np.zeros((0, size + 1))
    free = (*NO_OBSTACLES.kernel_arguments(), *no_arrival(len(grid.names)))
    for _ in range(2):  # count the rows, then write them
        exit_transitions(
            *before,
            dealt(classes.representative),
            row_of,
            *free,
            *shapes.outputs(),
            True,
            record_start,
            record_count,
            record,
            classes.relative_slot,
        )
        if record.shape[0] == 0:
            ends = np.cumsum(record_count.ravel())
            record_start = (ends - record_count.ravel()).reshape(record_count.shape)
            record = np.empty((int(ends[-1]), size + 1))
    boxes = np.empty(record_count.shape + (SEGMENT_BOX_COLUMNS,))
    segment_boxes(
        record,
        record_start,
        record_count,
        *obstacles[:2],
        arrival[0],
        *arrival[2:],
        grid.state_slot,
        boxes,
    )
    return shapes, (record_start, record_count, record, classes.relative_slot, boxes)


def check_transitions_finite(problem: Problem, transitions: Transitions) -> None:
    """SimulationError at the spec's ``dyn`` line if some segment's state became non-finite
    (its cost nan, ``dp_exits.exit_transitions_template``), naming the first such node and
    control."""
    diverged = np.argwhere(np.isnan(transitions.segment_cost))
    if not diverged.size:
        return
    row, u = diverged[0]
    node = int(np.flatnonzero(transitions.row_of >= 0)[row])
    grid, spec = problem.grid, problem.spec
    where = np.unravel_index(node, grid.shape)
    values = grid.axis_values()
    start = ", ".join(f"{name}={values[k][where[k]]:g}" for k, name in enumerate(grid.names))
    control = ", ".join(
        f"{c.name}={value:g}"
        for c, value in zip(spec.controls, problem.control_samples[u], strict=True)
    )
    token = spec.figure_token
    raise SimulationError(
        f"{location(spec.path, token)}: the state became non-finite in the segment "
        f"from node {start} under {control} ({len(diverged):,} of "
        f"{transitions.segment_cost.size:,} segments): the figure's dynamics diverge there (a "
        "huge figure parameter?); nothing written"
    )


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


def holding_torques(problem: Problem, dynamics: ModuleType) -> np.ndarray:
    """(D, m) controls, spec units, that hold the figure at rest at each of the D destination
    nodes (``hold``; the nodes of every ``dest`` line): with every rate 0, the actuators
    cancel the generalised forces of gravity, joint stops and contacts, ``-forcing(q, 0, 0)``.
    SpecError at the ``hold`` line when the figure has no equations of motion (a vehicle), a
    destination is not at rest, a coordinate without an actuator would need a force, or a
    torque lies outside its ``torq`` range."""
    spec, grid = problem.spec, problem.grid
    assert spec.hold is not None
    if not hasattr(dynamics, "forcing"):
        raise spec.error(spec.hold, "no 'hold' line: a vehicle is held by braking, not torques")
    n = dynamics.COORDINATE_COUNT
    coordinates = grid.state_slot < n
    several = len(spec.destinations) > 1
    for line in spec.destinations:
        rates_named = {entry.name for entry in line}
        for k, name in enumerate(grid.names):
            if not coordinates[k] and name not in rates_named:
                where = f" (line {line[0].token.line} does not)" if several else ""
                raise spec.error(
                    spec.hold, f"a 'dest' that names the rate '{name}' (= 0) for 'hold'{where}"
                )
    lower = np.array([c.minimum for c in spec.controls])
    upper = np.array([c.maximum for c in spec.controls])
    nodes = np.flatnonzero(problem.is_destination)
    held = np.empty((len(nodes), len(spec.controls)))
    state = np.empty(len(problem.base_state))
    center = np.empty(len(grid.names))
    for row, node in enumerate(nodes):
        node_coordinates(grid.axis_min, grid.axis_step, grid.axis_count, node, center)
        state[:] = problem.base_state
        state[grid.state_slot] = center
        if np.any(state[n:] != 0.0):
            raise spec.error(spec.hold, "a destination at rest (every rate 0) for 'hold'")
        force = -np.asarray(dynamics.forcing(state[:n], state[n:], np.zeros(n)))
        unheld = np.ones(n, dtype=bool)
        unheld[problem.control_slot] = False
        if np.any(np.abs(force[unheld]) > 1e-9):
            name = dynamics.Q_NAMES[int(np.flatnonzero(unheld & (np.abs(force) > 1e-9))[0])]
            raise spec.error(
                spec.hold, f"a destination where '{name}', which has no actuator, is at rest"
            )
        held[row] = force[problem.control_slot] / problem.control_scale
        outside = np.flatnonzero((held[row] < lower) | (held[row] > upper))
        if outside.size:
            control = spec.controls[int(outside[0])]
            raise spec.error(
                spec.hold,
                f"holding torques within the torq range of '{control.name}' "
                f"(it needs {held[row, outside[0]]:.4g})",
            )
    return held


def peak_rss_bytes() -> int:
    """This process's peak resident set size so far, bytes (Linux reports KiB)."""
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024


def figure_attributes(problem: Problem, dynamics: ModuleType) -> dict:
    """Root attrs the contract adds for a vehicle (wheelbase, wheel_radius) and for a spec
    with obstacles (body_outline, obstacles, and this mosys's domain polygon)."""
    attrs: dict = {}
    if getattr(dynamics, "MODEL_KIND", "figure") == "vehicle":
        attrs["wheelbase"] = float(dynamics.WHEELBASE)
        attrs["wheel_radius"] = float(dynamics.WHEEL_RADIUS)
    obstacles = problem.obstacles
    if obstacles.active:
        attrs["body_outline"] = json.dumps(obstacles.outline.tolist())
        attrs["obstacles"] = json.dumps(obstacles.polygons())
        attrs["obstacle_names"] = list(obstacles.names)
        attrs["domain"] = json.dumps(obstacles.domain.tolist())
    return attrs


def dp_memory_bytes(spec: ControllerSpec) -> float:
    """About the memory the DP of ``spec`` takes, bytes: per node and control sample, and once
    more for the policy's compact copy (``dp.gather_policy``), the exit (2^(d-1) corners of an
    int32 node and a float32 weight) and the segment's cost (float64); per node, about a dozen
    float64/int64 arrays (values, policy, grid bookkeeping)."""
    nodes = float(np.prod([float(d.samples) for d in spec.state]))
    controls = float(np.prod([float(c.samples) for c in spec.controls]))
    corners = 2.0 ** (len(spec.state) - 1)
    return nodes * ((controls + 1.0) * (8.0 * corners + 8.0) + 8.0 * (12 + len(spec.state)))


def generate_controller(
    spec: ControllerSpec,
    dynamics: ModuleType,
    out_path: str | Path,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    quiet: bool = False,
) -> ControllerTable:
    """Run the DP of a parsed spec on ``dynamics`` and write the table to ``out_path``.
    ``tolerance``/``max_iterations`` override the spec's. Raises SpecError where the spec does
    not fit the figure."""
    started = time.perf_counter()
    last_torq = spec.controls[-1].token
    check_job(
        location(spec.path, last_torq),
        "the DP of this grid and these control samples",
        memory_bytes=dp_memory_bytes(spec),
    )
    problem = build_problem(spec, dynamics)
    tolerance = spec.tolerance if tolerance is None else tolerance
    max_iterations = spec.max_iterations if max_iterations is None else max_iterations
    solution = solve(problem, dynamics, tolerance, max_iterations, spec.dt, quiet=quiet)
    arrival = arrival_solution(problem, dynamics, solution, tolerance, max_iterations, quiet)
    kernel_load_seconds = solution.kernel_load_seconds
    if arrival is not None and arrival is not solution:
        kernel_load_seconds += arrival.kernel_load_seconds
    generation_seconds = time.perf_counter() - started - kernel_load_seconds
    grid = problem.grid
    lower = np.array([c.minimum for c in spec.controls])
    upper = np.array([c.maximum for c in spec.controls])
    torque = problem.control_samples[solution.best_control]
    unreachable = ~np.isfinite(solution.value)
    torque[unreachable] = np.clip(0.0, lower, upper)
    if spec.hold is not None:
        torque[problem.is_destination] = holding_torques(problem, dynamics)
    table = ControllerTable(
        state_order=grid.names,
        control_names=tuple(c.name for c in spec.controls),
        control_units=control_units(dynamics, tuple(c.name for c in spec.controls)),
        axes=grid.axis_values(),
        axis_units=grid.units,
        wrap=tuple(bool(w) for w in grid.wrap),
        torque=torque.reshape(grid.shape + (len(spec.controls),)),
        value=solution.value.reshape(grid.shape),
        control_min=lower,
        control_max=upper,
        effort_weight=np.array([c.effort_weight for c in spec.controls]),
        dest=spec.destination_values(),
        figure=spec.figure,
        dead_end=solution.dead_end.reshape(grid.shape) if spec.known_weight else None,
        destinations=None
        if solution.destination_index is None
        else tuple(spec.all_destination_values()),
        destination_index=None
        if solution.destination_index is None
        else solution.destination_index.reshape(grid.shape),
        arrival_value=None if arrival is None else arrival.value.reshape(grid.shape),
        attrs={
            "spec_sha256": spec.spec_sha256,
            "generation_seconds": generation_seconds,
            "transition_seconds": solution.transition_seconds,
            "iteration_seconds": solution.iteration_seconds,
            "kernel_load_seconds": solution.kernel_load_seconds,
            "iterations": solution.iterations,
            "policy_sweeps": solution.policy_sweeps,
            "residual": solution.residual,
            "converged": bool(solution.residual < tolerance),
            "tolerance": tolerance,
            "dt": spec.dt,
            "control_samples": np.array([c.samples for c in spec.controls], dtype=np.int64),
            "unreachable_nodes": int((unreachable & ~solution.dead_end).sum()),
            "dead_end_nodes": int(solution.dead_end.sum()),
            "removed_nodes": int((~problem.node_valid).sum()),
            "minimum_known_weight": spec.known_weight,
            "table_states": int(problem.node_valid.sum()),
            "peak_rss_bytes": peak_rss_bytes(),
            "hold": spec.hold is not None,
            "mosys_version": __version__,
            **figure_attributes(problem, dynamics),
            **policy_attributes(spec),
        },
    )
    write_controller_table(out_path, table)
    return table
