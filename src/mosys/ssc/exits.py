"""The DP's exit transitions for a ``Problem`` (paper §3.5): from every node under every sampled
control, the segment to where the state leaves its cell, its cost and its exit's corners and
weights (``Transitions``), computed by ``kernels.dp_exits`` in chunks with progress, once per
motion class where the model ignores some coordinates (``record_classes``), and checked to be
finite.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from types import ModuleType

import numpy as np
from numba import get_num_threads

from mosys.errors import SimulationError
from mosys.io.progress import Progress
from mosys.kernels.dp_exits import SEGMENT_BOX_COLUMNS, replay_classes, segment_boxes
from mosys.parsing.tokens import location
from mosys.ssc.lookahead import vehicle_arrival
from mosys.ssc.obstacles import NO_OBSTACLES
from mosys.ssc.problem import Problem

PROGRESS_CHUNKS = 20  # at most; fewer for small grids (each chunk wakes numba's threads)
SIMULATIONS_PER_CHUNK = 20_000  # at least, but for the last chunk


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
