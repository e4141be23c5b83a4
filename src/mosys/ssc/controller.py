"""The controller at run time: torques for any state, and closed-loop simulation.

Policy outside the domain: a state beyond a non-wrap axis is clamped onto the domain's boundary
(the torque of the nearest state the table covers) and the sample is flagged; wrap axes are taken
modulo their period. Interpolated torques are clamped to the controls' limits.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from mosys.errors import InputError, NonFiniteStateError
from mosys.io.controller_table import ControllerTable, read_controller_table
from mosys.kernels.interpolate import clamp_to_domain, falls_short, interpolate_into
from mosys.kernels.simulate import simulate_controlled
from mosys.kernels.soundness import steps_before_blow_up, unsoundness
from mosys.ssc.grid import FigureGrid, control_scale, figure_grid, figure_state_names, state_unit
from mosys.ssc.regions import ARRIVAL_STEPS, REST_RATE, Bounds, Regions, state_periods

CLOSED_LOOP_DT = 0.001  # s: the simulator step of the closed-loop runs that judge and draw a
# table (quality, portraits); the DP's own steps are longer (kernels.dp_exits)

if TYPE_CHECKING:  # the lookahead policy (a vehicle's) is imported when a table uses it
    from mosys.ssc.lookahead import Lookahead


def non_finite_message(
    dynamics: ModuleType, t: float, figure_state: np.ndarray, driver: str
) -> str:
    """What ``NonFiniteStateError`` says: the model state ``figure_state`` (S,) SI, NaN, inf or
    beyond ±STATE_LIMIT, at ``t`` s under ``driver`` ('controller A', 'motor program swing'),
    each variable in its spec unit."""
    described = ", ".join(
        f"{name}={value / state_unit(dynamics, name)[1]:.6g} {state_unit(dynamics, name)[0]}"
        for name, value in zip(figure_state_names(dynamics), figure_state, strict=True)
    )
    return (
        f"the state {unsoundness(figure_state)} at t = {t:.6g} s under {driver} ({described}): "
        "the simulation cannot go on (a huge state, gain or figure parameter?); nothing written"
    )


def node_costs(value: np.ndarray, known: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Node costs (N, 1) s as ``Controller`` interpolates them: C-contiguous, 0 where not
    ``known`` (N,) bool (None: where finite), and ``known``."""
    if known is None:
        known = np.isfinite(value[:, 0])
    return np.ascontiguousarray(np.where(known[:, None], value, 0.0)), known


@dataclass(frozen=True)
class ClosedLoopRun:
    """One simulated stretch: ``states`` (steps+1, S) the model's state, SI, the first row the
    start; ``controls`` (steps, m) the controls held over each step, spec units; ``outside``
    (steps,) True where the state was outside the table's domain and was clamped."""

    states: np.ndarray
    controls: np.ndarray
    outside: np.ndarray


class Controller:
    """A state-space controller table bound to its figure's dynamics module."""

    def __init__(self, name: str, table: ControllerTable, dynamics: ModuleType):
        """InputError if the table's state variables or controls are not the model's (a table
        of another figure)."""
        for kind, wanted, have in (
            ("state variables", table.state_order, figure_state_names(dynamics)),
            ("controls", table.control_names, tuple(dynamics.INPUT_NAMES)),
        ):
            lacking = [variable for variable in wanted if variable not in have]
            if lacking:
                raise InputError(
                    f"controller {name} (a table of figure '{table.figure}'): the dynamics "
                    f"have no {kind} {', '.join(lacking)} (theirs: {', '.join(have)})"
                )
        self.name = name
        self.table = table
        self.dynamics = dynamics
        axes = table.axes
        self.grid: FigureGrid = figure_grid(
            dynamics,
            table.state_order,
            np.array([axis[0] for axis in axes]),
            np.array([(axis[-1] - axis[0]) / (len(axis) - 1) for axis in axes]),
            np.array([len(axis) for axis in axes]),
            np.array(table.wrap),
        )
        m = len(table.control_names)
        self.torque_table = np.ascontiguousarray(table.torque.reshape(-1, m))
        self.known = np.ascontiguousarray(np.isfinite(table.value).reshape(-1))
        actuators = tuple(dynamics.INPUT_NAMES)
        self.control_slot = np.array(
            [actuators.index(name) for name in table.control_names], dtype=np.int64
        )
        self.control_scale = np.array([control_scale(dynamics, n) for n in table.control_names])
        # the simulator's SI copies of the table and the limits, made once per controller
        self.torque_table_si = np.ascontiguousarray(self.torque_table * self.control_scale)
        self.control_min_si = np.ascontiguousarray(table.control_min * self.control_scale)
        self.control_max_si = np.ascontiguousarray(table.control_max * self.control_scale)
        # 'policy lookahead' (a vehicle's spec): run by lookahead on the cost-to-go instead
        self.lookahead: Lookahead | None = None
        if table.attrs.get("policy") == "lookahead":
            from mosys.ssc.lookahead import lookahead_runtime

            self.lookahead = lookahead_runtime(table, dynamics, self.grid)
        self._per_thread = threading.local()  # each thread's copy of the lookahead's values

    @classmethod
    def load(cls, path: str | Path, dynamics: ModuleType) -> Controller:
        """Read a controller table; its name is the file stem (``B`` for ``B.h5``). InputError
        naming the file if it is not a controller table, or not one of the model's figure."""
        table = read_controller_table(path)
        try:
            return cls(Path(path).stem, table, dynamics)
        except InputError as error:
            raise InputError(f"{path}: {error}") from None

    @property
    def state_order(self) -> tuple[str, ...]:
        return self.table.state_order

    def _clamped(self, state: np.ndarray) -> tuple[np.ndarray, bool]:
        """A controller state (d,) in spec units as the table reads it: SI, each non-wrap
        coordinate moved onto its axis range (``clamp_to_domain``); and whether nothing had to
        move."""
        grid = self.grid
        si = np.asarray(state, dtype=np.float64) * grid.scale
        clamped = np.empty_like(si)
        inside = clamp_to_domain(
            grid.axis_min, grid.axis_step, grid.axis_count, grid.wrap, si, clamped
        )
        return clamped, bool(inside)

    def torque(self, state: np.ndarray) -> np.ndarray:
        """Controls (m,) at a controller state (d,) in spec units (deg, deg/s, m, m/s)."""
        grid = self.grid
        clamped, _ = self._clamped(state)
        out = np.empty(len(self.table.control_names))
        interpolate_into(
            grid.axis_min,
            grid.axis_step,
            grid.axis_count,
            grid.wrap,
            self.torque_table,
            self.known,
            clamped,
            out,
        )
        return np.clip(out, self.table.control_min, self.table.control_max)

    def cost_to_go(self, state: np.ndarray) -> float:
        """The table's cost-to-go (s) at a controller state (d,) in spec units, interpolated as
        the lookahead runtime does: over the corners whose value is known (a dead end's at the
        DP's bound ``dp.DEAD_END_BOUND``), inf where those carry less than the table's
        ``minimum_known_weight`` (0 when absent) of the weight (up to rounding,
        ``interpolate.falls_short``); beyond the axes, at the nearest covered state."""
        return self._interpolated_cost(*self._known_values, state)

    def arrival_cost_to_go(self, state: np.ndarray) -> float:
        """The table's cost-to-go (s) to its whole arrival box (``/arrival_value``) at a
        controller state (d,) in spec units, interpolated over the corners where it is finite,
        inf where those carry less than the table's ``minimum_known_weight``, and for a table
        without one (its policy line does not ask for ``arrival_value``)."""
        if self._arrival_values is None:
            return math.inf
        return self._interpolated_cost(*self._arrival_values, state)

    def _interpolated_cost(
        self, known_values: np.ndarray, known: np.ndarray, state: np.ndarray
    ) -> float:
        """Node costs (N, 1) s, 0 where not ``known`` (N,) bool, interpolated at a controller
        state (d,) in spec units (``cost_to_go``)."""
        grid = self.grid
        clamped, _ = self._clamped(state)
        out = np.empty(1)
        known_weight = interpolate_into(
            grid.axis_min,
            grid.axis_step,
            grid.axis_count,
            grid.wrap,
            known_values,
            known,
            clamped,
            out,
        )
        minimum = float(self.table.attrs.get("minimum_known_weight", 0.0))
        enough = known_weight > 0.0 and not falls_short(known_weight, minimum)
        return float(out[0]) if enough else math.inf

    def domain_violation(self, figure_state: np.ndarray) -> str | None:
        """Why the model state ``figure_state`` (S,) SI lies outside this controller's domain
        (the 1990 paper's Figure 7: beyond a non-wrap axis of the table, or where its
        interpolated cost-to-go is inf), or None inside it."""
        state = self.controller_states(np.asarray(figure_state, dtype=np.float64)[None, :])[0]
        if not self._clamped(state)[1]:
            return "beyond the table's axes"
        if not math.isfinite(self.cost_to_go(state)):
            return "where the table's cost-to-go is inf"
        return None

    @cached_property
    def _known_values(self) -> tuple[np.ndarray, np.ndarray]:
        """(N, 1) cost-to-go at the nodes, s, 0 where unknown, and (N,) bool known, as
        ``cost_to_go`` interpolates them (dead ends at the DP's bound, as the runtime sees
        them); built once, not per state."""
        if self.lookahead is not None:
            return node_costs(self.lookahead.value, self.lookahead.known)
        return node_costs(self.table.value.reshape(-1, 1))

    @cached_property
    def _arrival_values(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(N, 1) cost-to-go to the whole arrival box, s, 0 where not finite, and (N,) bool
        finite; None for a table without ``/arrival_value``."""
        if self.table.arrival_value is None:
            return None
        return node_costs(self.table.arrival_value.reshape(-1, 1))

    def figure_state(self, state: np.ndarray) -> np.ndarray:
        """A full model state (S,), SI, from a controller state (d,) in spec units; model
        state variables the controller does not name are 0."""
        full = np.zeros(len(self.dynamics.STATE_NAMES))
        full[self.grid.state_slot] = np.asarray(state, dtype=np.float64) * self.grid.scale
        return full

    def controller_states(self, figure_states: np.ndarray) -> np.ndarray:
        """Controller states (N, d) in spec units from model states (N, S) SI; wrap axes are
        reduced into [first node, first node + period)."""
        grid = self.grid
        states = figure_states[:, grid.state_slot] / grid.scale
        for k in np.flatnonzero(grid.wrap):
            first = grid.axis_min[k] / grid.scale[k]
            period = grid.axis_count[k] * grid.axis_step[k] / grid.scale[k]
            states[:, k] = first + np.mod(states[:, k] - first, period)
        return states

    @property
    def destinations(self) -> tuple[dict[str, float], ...]:
        """Every destination of the table, {name: value} in spec units, in ``dest`` line order
        (one for the usual table)."""
        return self.table.all_destinations

    @cached_property
    def _destination_votes(self) -> tuple[np.ndarray, np.ndarray]:
        """(N, D) float64, 1 in the column of each node's ``/destination_index``, and (N,)
        bool, the nodes whose index is known (>= 0); built once, not per state."""
        index = self.table.destination_index
        assert index is not None
        flat = index.reshape(-1)
        votes = np.zeros((flat.shape[0], len(self.destinations)))
        known = flat >= 0
        votes[np.flatnonzero(known), flat[known]] = 1.0
        return votes, np.ascontiguousarray(known)

    def heading_for(self, state: np.ndarray) -> int:
        """The index into ``destinations`` of the destination a controller state (d,), spec
        units, heads for: 0 for a table with one destination; with several, the index that
        the state's interpolation corners with a known ``/destination_index`` carry the most
        weight of (ties: the lowest), -1 where none of them is known. Beyond the axes, at the
        nearest covered state."""
        if self.table.destination_index is None:
            return 0
        grid = self.grid
        clamped, _ = self._clamped(state)
        votes, known = self._destination_votes
        out = np.empty(votes.shape[1])
        weight = interpolate_into(
            grid.axis_min, grid.axis_step, grid.axis_count, grid.wrap, votes, known, clamped, out
        )
        return int(np.argmax(out)) if weight > 0.0 else -1

    def arrival_boxes(self) -> list[Bounds]:
        """One ``arrival_box`` per destination, in ``destinations`` order: with several
        destinations, the figure has arrived when it is in any of them."""
        return [self._arrival_box(destination) for destination in self.destinations]

    def arrival_box(self, figure_state: np.ndarray | None = None) -> Bounds:
        """The box, spec units, in which the figure counts as back at the destination: each
        dimension ``dest`` names within ARRIVAL_STEPS grid steps of it, and every rate of the
        figure, whether the controller sees it or not, below REST_RATE (SI) in size as well:
        at rest, so that what follows starts from (nearly) the same state every time.

        With several destinations one box is the box of the destination that
        ``figure_state`` (S,) SI heads for (``heading_for``; the first destination where no
        node around it leads anywhere); without ``figure_state`` that is a ValueError, since
        no single box holds them all: ``arrival_boxes`` gives one per destination."""
        destinations = self.destinations
        if len(destinations) == 1:
            return self._arrival_box(destinations[0])
        if figure_state is None:
            raise ValueError(
                f"controller {self.name} has {len(destinations)} destinations: its arrival box "
                "depends on the state (pass figure_state, or use arrival_boxes)"
            )
        state = self.controller_states(np.asarray(figure_state, dtype=np.float64)[None])[0]
        return self._arrival_box(destinations[max(self.heading_for(state), 0)])

    def _arrival_box(self, destination: dict[str, float]) -> Bounds:
        """``arrival_box`` around one destination, {name: value} in spec units."""
        grid = self.grid
        box: dict[str, tuple[float, float]] = {}
        for k, name in enumerate(grid.names):
            if name in destination:
                reach = ARRIVAL_STEPS * grid.axis_step[k] / grid.scale[k]
                box[name] = (destination[name] - reach, destination[name] + reach)
        coordinates = len(getattr(self.dynamics, "Q_NAMES", ()))
        for name in figure_state_names(self.dynamics)[coordinates:]:
            rest = REST_RATE / state_unit(self.dynamics, name)[1]
            low, high = box.get(name, (-rest, rest))
            box[name] = (max(low, -rest), min(high, rest))
        return box

    def _learning_values(self) -> np.ndarray:
        """This thread's copy of the lookahead's cost-to-go (N, 1) s, made at its first run: a
        run raises it where it learns and puts it back before it returns
        (``kernels.lookahead.simulate_lookahead``), so runs at once need one each."""
        values = getattr(self._per_thread, "value", None)
        if values is None:
            values = self._per_thread.value = self.lookahead.value.copy()
        return values

    def run_work_bytes(self, steps: float) -> float:
        """What a run of ``steps`` steps allocates besides its records, bytes: for a lookahead
        table, this thread's copy of the cost-to-go (8 bytes a node, at its first run) and the
        run's put-back log (``kernels.lookahead.undo_log_bytes``); 0 for any other. inf where
        ``steps`` is not finite (``limits.check_job`` refuses those steps first)."""
        if self.lookahead is None:
            return 0.0
        if not math.isfinite(steps):
            return math.inf
        from mosys.kernels.lookahead import undo_log_bytes

        nodes = self.lookahead.value.shape[0]
        return 8.0 * nodes + undo_log_bytes(nodes, round(steps), len(self.grid.names))

    def simulate(
        self,
        figure_state: np.ndarray,
        seconds: float,
        dt: float,
        regions: Regions | None = None,
        slew_rate: np.ndarray | None = None,
        previous: np.ndarray | None = None,
    ) -> ClosedLoopRun:
        """Run the model from ``figure_state`` (S,) SI under this controller for ``seconds``
        (rounded to whole steps of ``dt``), or until the state enters or leaves one of
        ``regions`` (``kernels.simulate.simulate_controlled``, or
        ``kernels.lookahead.simulate_lookahead`` for a table made with ``policy lookahead``).
        The run's controls are in spec units.

        ``slew_rate`` (m,): the largest rate of change of each control, spec units per second
        (inf, or None for all: no limit), from ``previous`` (m,), the controls just before the
        run, spec units (None: 0). A ``policy lookahead`` table plans its own controls and
        takes no slew limit (ValueError).

        A state that becomes non-finite (NaN, inf, or beyond ±``kernels.soundness.STATE_LIMIT``
        SI) at the start of a step or at the end raises ``errors.NonFiniteStateError`` with the time
        from the run's start and that state."""
        steps = int(round(seconds / dt))
        m = len(self.table.control_names)
        slew_step = np.full(m, np.inf)
        if slew_rate is not None:
            slew_step = np.ascontiguousarray(slew_rate * self.control_scale * dt, dtype=float)
        held = np.zeros(m)
        if previous is not None:
            held = np.ascontiguousarray(previous * self.control_scale, dtype=float)
        n2 = len(figure_state)
        if regions is None:
            regions = Regions(np.empty((0, n2)), np.empty((0, n2)), state_periods(self.dynamics))
        state = np.ascontiguousarray(figure_state, dtype=np.float64).copy()
        states = np.empty((steps + 1, n2))
        controls = np.empty((steps, len(self.table.control_names)))
        outside = np.empty(steps, dtype=np.bool_)
        grid = self.grid
        if self.lookahead is not None:
            if np.isfinite(slew_step).any():
                raise ValueError(
                    f"controller {self.name} plans its controls by lookahead: no slew limit"
                )
            from mosys.kernels.lookahead import simulate_lookahead
            from mosys.ssc.lookahead import MAX_SEGMENT_SECONDS

            policy = self.lookahead
            taken = simulate_lookahead(
                self.dynamics.derivative_into,
                grid.axis_min,
                grid.axis_step,
                grid.axis_count,
                grid.wrap,
                self._learning_values(),
                policy.known,
                policy.minimum_known_weight,
                policy.control_samples,
                self.control_slot,
                len(self.dynamics.INPUT_NAMES),
                grid.state_slot,
                policy.pose_slot,
                policy.outline,
                policy.obstacle_vertices,
                policy.obstacle_start,
                policy.domain,
                policy.vehicle_slot,
                policy.wheelbase,
                policy.wheel_radius,
                policy.brake,
                policy.arrival_box,
                int(np.ceil(MAX_SEGMENT_SECONDS / policy.segment_dt)),
                policy.segment_dt,
                state,
                float(dt),
                states[:-1],
                controls,
                outside,
                regions.lower,
                regions.upper,
                regions.period,
            )
        else:
            taken = simulate_controlled(
                self.dynamics.derivative_into,
                grid.axis_min,
                grid.axis_step,
                grid.axis_count,
                grid.wrap,
                self.torque_table_si,
                self.known,
                self.control_min_si,
                self.control_max_si,
                slew_step,
                held,
                grid.state_slot,
                self.control_slot,
                len(self.dynamics.INPUT_NAMES),
                state,
                float(dt),
                states[:-1],
                controls,
                outside,
                regions.lower,
                regions.upper,
                regions.period,
            )
        if taken < 0:
            t = steps_before_blow_up(taken) * dt
            raise NonFiniteStateError(
                non_finite_message(self.dynamics, t, state, f"controller {self.name}"), t, state
            )
        states[taken] = state
        return ClosedLoopRun(
            states[: taken + 1], controls[:taken] / self.control_scale, outside[:taken]
        )
