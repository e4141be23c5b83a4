"""The animation-script runner (paper §3.1, §5.2, §7): a ``.anim`` script, the controllers and
motor programs it names → one motion.

``state`` values in positional form are read in the state order of the active controller (or,
before any ``swapcon``, of the script's first controller); figure state variables that order
leaves out start at 0. ``swapcon`` switches controller at once; ``sim`` runs the active
controller for that many seconds in whole steps of ``dt``, rounded (one shorter than half a step
simulates none, with a warning on stderr; with ``until=dest``, it stops at the
first step in an arrival box of the controller's, ``Controller.arrival_boxes``: one per
destination); during a ``sim``, the
first breakpoint (``when``) whose box holds the state drives instead, switching as the state
crosses box borders; a ``once`` breakpoint instead hands over for good the first time its box
holds the state. ``motor`` runs a motor program to its end from the current state. ``slew``
limits how fast each named control changes from then on (the 1990 paper's §5), across every
exchange, from the controls of the step before (0 at the script's start). Whenever a controller
takes over, the state is checked against its domain (Figure 7); each violation is recorded and
warned of on stderr.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from mosys.errors import NonFiniteStateError, SimulationError
from mosys.io.controller_table import read_controller_table
from mosys.limits import check_job
from mosys.parsing.script import (
    AnimationScript,
    Breakpoint,
    RunMotorProgram,
    SetState,
    Simulate,
    SlewLimit,
    SwapController,
)
from mosys.parsing.tokens import Token, format_number, location
from mosys.ssc.controller import Controller, non_finite_message
from mosys.ssc.grid import control_scale, figure_state_names, state_limit, state_unit
from mosys.ssc.regions import Bounds, regions

if TYPE_CHECKING:  # motor programs are imported when a script runs one
    from mosys.animation.motor_program import BoundMotorProgram


@dataclass(frozen=True)
class DomainViolation:
    """A controller took over at time ``t`` (s) outside its domain (``reason``), by the script's
    line ``line`` (a ``swapcon`` or ``when``)."""

    t: float
    controller: str
    line: int
    reason: str


@dataclass(frozen=True)
class ScriptBreakpoint:
    """A ``when`` line as run: its box (spec units), controller, ``once`` and line."""

    box: Bounds
    controller: str
    once: bool
    line: int


@dataclass(frozen=True)
class ScriptRun:
    """A script's motion. t: (N,) s; figure_states: (N, S) SI; state: (N, d) in ``state_order``,
    spec units; control: (N, m) in ``control_names``, spec units; source: (N,) int64 index
    into ``sources`` (the controller or motor program driving each step); outside: (N,) bool,
    the state lay outside the active controller's domain; switches: (t, source name) at each
    change of what drives the figure. ``source_kinds`` says 'controller' or 'motor' per source.
    domain_violations: each controller exchange outside the new controller's domain;
    breakpoints: the script's ``when`` lines; slew: the slew limits in force at the end, spec
    units per second, by control (only finite ones).

    The state order is the controllers' common one when the script runs no motor program and
    every controller shares it (the pendulum: omega, angle); otherwise every state variable of
    the figure. The controls likewise: the controllers' common ones, else every actuator."""

    t: np.ndarray
    figure_states: np.ndarray
    state: np.ndarray
    control: np.ndarray
    source: np.ndarray
    outside: np.ndarray
    sources: tuple[str, ...]
    source_kinds: tuple[str, ...]
    state_order: tuple[str, ...]
    control_names: tuple[str, ...]
    switches: tuple[tuple[float, str], ...]
    domain_violations: tuple[DomainViolation, ...] = ()
    breakpoints: tuple[ScriptBreakpoint, ...] = ()
    slew: dict[str, float] | None = None


@dataclass(frozen=True)
class ScriptSources:
    """What a script draws on: its figure's dynamics, its controllers by name (bound to that
    dynamics) and its motor programs by name."""

    dynamics: ModuleType
    controllers: dict[str, Controller]
    programs: dict[str, BoundMotorProgram]


def controller_table_path(
    script: AnimationScript, command: SwapController | Breakpoint, controller_dir: str | Path
) -> Path:
    """The table a ``swapcon`` or ``when`` names, ``controller_dir/NAME.h5``; SpecError at the
    line if it does not exist."""
    path = Path(controller_dir) / f"{command.controller}.h5"
    if not path.exists():
        raise script.error(command.table_token, f"a controller table ({path} does not exist)")
    return path


def load_controllers(
    script: AnimationScript, controller_dir: str | Path, dynamics: ModuleType
) -> dict[str, Controller]:
    """Every controller the script names, from ``controller_dir/NAME.h5``, bound to the
    object's ``dynamics`` by state-variable and actuator names. A missing table, or one whose
    variables the figure lacks, raises SpecError at the line that names it; a file that is not
    a controller table raises InputError naming the file."""
    controllers: dict[str, Controller] = {}
    for command in script.commands:
        if not isinstance(command, SwapController | Breakpoint):
            continue
        if command.controller in controllers:
            continue
        path = controller_table_path(script, command, controller_dir)
        table = read_controller_table(path)  # a damaged file: its own message, not the line's
        try:
            controllers[command.controller] = Controller(Path(path).stem, table, dynamics)
        except ValueError as error:  # a state variable or actuator the figure does not have
            raise script.error(
                command.table_token,
                "a controller over state variables and actuators of the object's figure "
                f"({path}: {error})",
            ) from None
    return controllers


def load_programs(
    script: AnimationScript, motor_dir: str | Path, figure: str, dynamics: ModuleType
) -> dict[str, BoundMotorProgram]:
    """Every motor program the script runs, ``motor_dir/FIGURE/NAME.mot``, bound to the
    figure; a missing file raises SpecError at the ``motor`` line."""
    files = script.motor_program_files(motor_dir, figure)
    if not files:
        return {}
    from mosys.animation.motor_program import load_motor_program

    return {name: load_motor_program(path, figure, dynamics) for name, path in files.items()}


class _Recorder:
    """Accumulates the stretches of a run, what drove each step, and the controls of the step
    before (``held``: (I,) SI on the model's input slots, 0 before the first step), from which
    a slew limit starts."""

    def __init__(self, sources: tuple[str, ...], input_size: int):
        self.sources = sources
        self.clock = 0.0
        self.t: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.inputs: list[np.ndarray] = []
        self.source: list[np.ndarray] = []
        self.outside: list[np.ndarray] = []
        self.switches: list[tuple[float, str]] = []
        self.violations: list[DomainViolation] = []
        self.driver: str | None = None
        self.held = np.zeros(input_size)

    def drive(self, name: str) -> bool:
        """``name`` drives from now on; True when that is a change."""
        if name == self.driver:
            return False
        self.switches.append((self.clock, name))
        self.driver = name
        return True

    def add(self, states: np.ndarray, inputs: np.ndarray, outside: np.ndarray, dt: float) -> None:
        """A stretch: states (steps+1, S), the first its start; inputs (steps, I) SI on the
        model's input slots; outside (steps,)."""
        steps = inputs.shape[0]
        self.t.append(self.clock + dt * np.arange(steps))
        self.states.append(states[:-1])
        self.inputs.append(inputs)
        self.source.append(np.full(steps, self.sources.index(self.driver), dtype=np.int64))
        self.outside.append(outside)
        self.clock += steps * dt
        if steps:
            self.held = inputs[-1].copy()


@dataclass
class _Exchange:
    """What decides which controller drives during a ``sim``: the last ``swapcon`` (``active``,
    and the line that made it, ``line``), the breakpoints so far (box, controller, the ``when``
    command; spent ``once`` breakpoints removed), and the slew limits, spec units per second,
    per actuator (inf: none)."""

    active: Controller | None
    line: int
    breakpoints: list[tuple[Bounds, Breakpoint]]
    slew_rate: np.ndarray


def run_script(script: AnimationScript, sources: ScriptSources, dt: float) -> ScriptRun:
    """Run ``script`` with its loaded ``sources``; dt is the simulator step, s."""
    dynamics = sources.dynamics
    names = tuple(sources.controllers) + tuple(sources.programs)
    kinds = ("controller",) * len(sources.controllers) + ("motor",) * len(sources.programs)
    input_size = len(dynamics.INPUT_NAMES)
    _check_size(script, sources, dt)
    recorder = _Recorder(names, input_size)
    pending: SetState | None = None
    figure_state: np.ndarray | None = None
    exchange = _Exchange(None, 0, [], np.full(input_size, np.inf))
    slew: dict[str, float] = {}
    for command in script.commands:
        if isinstance(command, SetState):
            pending = command
        elif isinstance(command, SwapController):
            exchange.active = sources.controllers[command.controller]
            exchange.line = command.token.line
        elif isinstance(command, Breakpoint):
            try:
                box = _checked_box(dynamics, command)
            except ValueError as error:
                raise script.error(command.conditions[0].token, str(error)) from None
            exchange.breakpoints.append((box, command))
        elif isinstance(command, SlewLimit):
            _set_slew(script, command, dynamics, exchange.slew_rate, slew)
        elif isinstance(command, RunMotorProgram | Simulate):
            if pending is not None:
                figure_state = _figure_state(script, pending, exchange.active, sources)
                pending = None
            assert figure_state is not None  # the parser puts a 'state' first
            if isinstance(command, RunMotorProgram):
                figure_state = _run_motor_program(
                    script, command, sources, exchange, figure_state, dt, recorder
                )
            else:
                assert exchange.active is not None  # the parser puts a 'swapcon' first
                figure_state = _simulate(
                    script, command, exchange, sources, figure_state, dt, recorder
                )
    assert figure_state is not None
    if recorder.driver is None:  # every 'sim' ended at once: the figure was at the destination
        assert exchange.active is not None
        recorder.drive(exchange.active.name)
    # the final state, with the input of the last step held
    recorder.add(
        np.stack([figure_state, figure_state]), recorder.held[None, :], np.zeros(1, bool), 0.0
    )
    figure_states = np.concatenate(recorder.states)
    inputs = np.concatenate(recorder.inputs)
    state_order, state = _state_columns(sources, figure_states)
    control_names, control = _control_columns(sources, inputs)
    return ScriptRun(
        t=np.concatenate(recorder.t),
        figure_states=figure_states,
        state=state,
        control=control,
        source=np.concatenate(recorder.source),
        outside=np.concatenate(recorder.outside),
        sources=names,
        source_kinds=kinds,
        state_order=state_order,
        control_names=control_names,
        switches=tuple(recorder.switches),
        domain_violations=tuple(recorder.violations),
        breakpoints=tuple(
            ScriptBreakpoint(command.box(), command.controller, command.once, command.token.line)
            for command in script.commands
            if isinstance(command, Breakpoint)
        ),
        slew={name: rate for name, rate in slew.items() if math.isfinite(rate)},
    )


def run_row_bytes(dynamics: ModuleType) -> int:
    """About what one simulator step of a run takes in memory, bytes: the kernel's record, the
    recorder's copies and the trajectory's columns (the figure's state and inputs, time, source,
    the drawn points of ``figure_motion``). Measured: a 1,000,000-step pendulum run peaks 133 MB
    above a 1-step one, against 184 MB from this estimate."""
    states = len(dynamics.STATE_NAMES)
    inputs = len(dynamics.INPUT_NAMES)
    points = len(getattr(dynamics, "ROD_NAMES", ())) or 8
    return 8 * (4 * states + 3 * inputs + 4 + 8 * points)


def _check_size(script: AnimationScript, sources: ScriptSources, dt: float) -> None:
    """LimitError at the first ``sim`` or ``motor`` line where the run, counted from its start,
    needs more integration steps or memory than the limits allow (``mosys.limits``): its
    records, and what the most demanding of its controllers allocates besides them
    (``Controller.run_work_bytes``, a lookahead table's)."""
    steps = 0.0
    row_bytes = run_row_bytes(sources.dynamics)
    controllers = sources.controllers.values()
    for command in script.commands:
        if isinstance(command, Simulate):
            steps += command.seconds / dt
        elif isinstance(command, RunMotorProgram):
            steps += sources.programs[command.program].duration() / dt
        else:
            continue
        where = location(script.path, command.token)
        job = f"the run to the end of this line at dt {dt:g} s"
        work = max((c.run_work_bytes(steps) for c in controllers), default=0.0)
        check_job(where, job, steps, steps * row_bytes + work)


def _set_slew(
    script: AnimationScript,
    command: SlewLimit,
    dynamics: ModuleType,
    slew_rate: np.ndarray,
    slew: dict[str, float],
) -> None:
    """Apply a ``slew`` line: ``slew_rate`` (I,) per input slot and ``slew`` (name -> rate),
    spec units per second, in place; SpecError at a name that is not an actuator."""
    actuators = tuple(dynamics.INPUT_NAMES)
    for (name, rate), token in zip(command.rates, command.name_tokens, strict=True):
        if not name or name not in actuators:
            known = ", ".join(a for a in actuators if a)
            raise script.error(token, f"a control of the object's figure (one of {known})")
        slew_rate[actuators.index(name)] = rate
        slew[name] = rate


def _blown_up(
    script: AnimationScript,
    token: Token,
    dynamics: ModuleType,
    clock: float,
    driver: str,
    error: NonFiniteStateError,
) -> SimulationError:
    """The error for a run, started at ``clock`` s by the line of ``token``, whose state became
    non-finite: led by the script's file, line and column, with the script's time."""
    message = non_finite_message(dynamics, clock + error.t, error.state, driver)
    return SimulationError(f"{location(script.path, token)}: {message}")


def _run_motor_program(
    script: AnimationScript,
    command: RunMotorProgram,
    sources: ScriptSources,
    exchange: _Exchange,
    figure_state: np.ndarray,
    dt: float,
    recorder: _Recorder,
) -> np.ndarray:
    """One ``motor`` line: the program to its end, slew-limited from the controls before it;
    SimulationError at the line if the state becomes non-finite."""
    program = sources.programs[command.program]
    recorder.drive(command.program)
    scale = np.array(
        [
            control_scale(sources.dynamics, sources.dynamics.INPUT_NAMES[c])
            for c in program.coordinate
        ]
    )
    try:
        run = program.run(
            figure_state,
            dt,
            slew_rate=exchange.slew_rate[program.coordinate] * scale,
            previous=recorder.held[program.coordinate],
        )
    except NonFiniteStateError as error:
        driver = f"motor program {program.name}"
        raise _blown_up(
            script, command.token, sources.dynamics, recorder.clock, driver, error
        ) from None
    inputs = np.zeros((run.controls.shape[0], len(recorder.held)))
    inputs[:, program.coordinate] = run.controls
    recorder.add(run.states, inputs, np.zeros(len(inputs), dtype=bool), dt)
    return run.states[-1]


def _checked_box(dynamics: ModuleType, command: Breakpoint) -> Bounds:
    box = command.box()
    known = figure_state_names(dynamics)
    for condition in command.conditions:
        if condition.name not in known:
            raise ValueError(
                f"a state variable of the object's figure (one of {', '.join(known)}), "
                f"not '{condition.name}'"
            )
    return box


def _simulate(
    script: AnimationScript,
    command: Simulate,
    exchange: _Exchange,
    sources: ScriptSources,
    figure_state: np.ndarray,
    dt: float,
    recorder: _Recorder,
) -> np.ndarray:
    """One ``sim``: the active controller, or a breakpoint's where its box holds the state, in
    stretches that end where the state crosses a box border; stops early in the arrival box.
    A ``once`` breakpoint whose box holds the state makes its controller the active one and is
    spent. Each change of controller is checked against the new one's domain. A state that
    becomes non-finite raises SimulationError at the ``sim`` line."""
    remaining = int(round(command.seconds / dt))
    if remaining == 0:  # a coarse --dt, for a quick look: say what it skips
        print(
            f"warning: {script.path}:{command.token.line}: sim {command.seconds:g} is less "
            f"than half a step (dt = {dt:g} s): no step simulated",
            file=sys.stderr,
        )
    # the breakpoints' boxes, SI, made once and kept in step with exchange.breakpoints (made
    # again at every stretch and every hand-over, 10,000 once breakpoints took 32 s)
    breakpoint_boxes = regions(sources.dynamics, [box for box, _ in exchange.breakpoints])
    once = np.array([when.once for _, when in exchange.breakpoints], dtype=np.bool_)
    while remaining > 0:
        breakpoints = len(breakpoint_boxes)
        boxes_si = breakpoint_boxes
        if command.until_dest:  # back at any of the active controller's destinations
            arrival = regions(sources.dynamics, exchange.active.arrival_boxes())
            boxes_si = breakpoint_boxes.joined(arrival)
        inside = boxes_si.membership(figure_state)
        if inside[breakpoints:].any():
            break
        holding = inside[:breakpoints]
        fired = np.flatnonzero(once & holding)
        if fired.size:  # the state hands over: a swapcon made by the state
            k = int(fired[0])
            when = exchange.breakpoints.pop(k)[1]
            breakpoint_boxes = breakpoint_boxes.without(k)
            once = np.delete(once, k)
            exchange.active = sources.controllers[when.controller]
            exchange.line = when.token.line
            continue
        driver, line = exchange.active, exchange.line
        if holding.any():
            when = exchange.breakpoints[int(holding.argmax())][1]
            driver, line = sources.controllers[when.controller], when.token.line
        if recorder.drive(driver.name):
            _check_domain(script, driver, line, figure_state, recorder)
        slots = driver.control_slot
        try:
            run = driver.simulate(
                figure_state,
                remaining * dt,
                dt,
                boxes_si,
                slew_rate=exchange.slew_rate[slots],
                previous=recorder.held[slots] / driver.control_scale,
            )
        except NonFiniteStateError as error:
            driver_name = f"controller {driver.name}"
            raise _blown_up(
                script, command.token, sources.dynamics, recorder.clock, driver_name, error
            ) from None
        except ValueError as error:  # a slew limit on a lookahead controller
            raise script.error(command.token, f"a run the controller can make ({error})") from None
        inputs = np.zeros((run.controls.shape[0], len(recorder.held)))
        inputs[:, slots] = run.controls * driver.control_scale
        recorder.add(run.states, inputs, run.outside, dt)
        figure_state = run.states[-1]
        remaining -= run.controls.shape[0]
    return figure_state


def _check_domain(
    script: AnimationScript,
    controller: Controller,
    line: int,
    figure_state: np.ndarray,
    recorder: _Recorder,
) -> None:
    """Record, and warn on stderr, when ``controller`` takes over outside its domain."""
    reason = controller.domain_violation(figure_state)
    if reason is None:
        return
    state = controller.controller_states(figure_state[None, :])[0]
    described = ", ".join(
        f"{name}={value:.6g}" for name, value in zip(controller.state_order, state, strict=True)
    )
    violation = DomainViolation(recorder.clock, controller.name, line, reason)
    recorder.violations.append(violation)
    print(
        f"warning: {script.path}:{line}: at t={recorder.clock:.6g} s controller "
        f"{controller.name} takes over at ({described}), {reason}: outside its domain",
        file=sys.stderr,
    )


def _figure_state(
    script: AnimationScript,
    command: SetState,
    active: Controller | None,
    sources: ScriptSources,
) -> np.ndarray:
    """The full model state (S,) SI that a ``state`` line sets."""
    dynamics = sources.dynamics
    names = figure_state_names(dynamics)
    if command.names:
        state = np.zeros(len(names))
        for name, value, token in zip(
            command.names, command.values, command.name_tokens, strict=True
        ):
            if name not in names:
                raise script.error(
                    token, f"a state variable of the object's figure (one of {', '.join(names)})"
                )
            state[names.index(name)] = value * state_unit(dynamics, name)[1]
        _check_limits(script, command, dynamics, command.names)
        return state
    controller = active or next(iter(sources.controllers.values()), None)
    if controller is None:
        raise script.error(
            command.value_tokens[0],
            "state values by name (NAME=VALUE): no controller gives an order",
        )
    if len(command.values) != len(controller.state_order):
        given = len(command.values)
        raise script.error(
            command.value_tokens[0],
            f"{len(controller.state_order)} values in the order {','.join(controller.state_order)}",
            "the only value" if given == 1 else f"the first of {given} values",
        )
    _check_limits(script, command, dynamics, controller.state_order)
    return controller.figure_state(np.array(command.values))


def _check_limits(
    script: AnimationScript, command: SetState, dynamics: ModuleType, names: tuple[str, ...]
) -> None:
    """SpecError at a ``state`` value the model cannot take (a car's steer beyond its
    ``steer_limit``: the wheels would stay there, turned further than they can turn)."""
    for name, value, token in zip(names, command.values, command.value_tokens, strict=True):
        limit = state_limit(dynamics, name)
        unit, scale = state_unit(dynamics, name)
        if limit is not None and abs(value) * scale > limit * (1.0 + 1e-12):
            largest = format_number(round(limit / scale, 9))
            raise script.error(token, f"a {name} within ±{largest} {unit} (the figure's limit)")


def _state_columns(
    sources: ScriptSources, figure_states: np.ndarray
) -> tuple[tuple[str, ...], np.ndarray]:
    controllers = list(sources.controllers.values())
    orders = {controller.state_order for controller in controllers}
    if controllers and not sources.programs and len(orders) == 1:
        return controllers[0].state_order, controllers[0].controller_states(figure_states)
    names = figure_state_names(sources.dynamics)
    scale = np.array([state_unit(sources.dynamics, name)[1] for name in names])
    return names, figure_states / scale


def _control_columns(
    sources: ScriptSources, inputs: np.ndarray
) -> tuple[tuple[str, ...], np.ndarray]:
    dynamics = sources.dynamics
    actuators = tuple(dynamics.INPUT_NAMES)
    controllers = list(sources.controllers.values())
    orders = {controller.table.control_names for controller in controllers}
    if controllers and not sources.programs and len(orders) == 1:
        names = controllers[0].table.control_names
    else:
        names = tuple(name for name in actuators if name)
    slots = [actuators.index(name) for name in names]
    scale = np.array([control_scale(dynamics, name) for name in names])
    return names, inputs[:, slots] / scale
