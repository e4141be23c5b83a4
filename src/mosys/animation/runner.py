"""The animation-script runner (paper §3.1, §5.2, §7): a ``.anim`` script, the controllers and
motor programs it names → one motion.

``state`` values in positional form are read in the state order of the active controller (or,
before any ``swapcon``, of the script's first controller); figure state variables that order
leaves out start at 0. ``swapcon`` switches controller at once; ``sim`` runs the active
controller for that many seconds in whole steps of ``dt`` (with ``until=dest``, it stops at the
first step in the controller's arrival box, ``Controller.arrival_box``); during a ``sim``, the
first breakpoint (``when``) whose box holds the state drives instead, switching as the state
crosses box borders. ``motor`` runs a motor program to its end from the current state.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from mosys.parsing.script import (
    AnimationScript,
    Breakpoint,
    RunMotorProgram,
    SetState,
    Simulate,
    SwapController,
)
from mosys.ssc.controller import Controller
from mosys.ssc.grid import control_scale, figure_state_names, state_unit
from mosys.ssc.regions import Bounds, regions

if TYPE_CHECKING:  # motor programs are imported when a script runs one
    from mosys.animation.motor_program import BoundMotorProgram


@dataclass(frozen=True)
class ScriptRun:
    """A script's motion. t: (N,) s; figure_states: (N, S) SI; state: (N, d) in ``state_order``,
    spec units; control: (N, m) in ``control_names``, spec units; source: (N,) int64 index
    into ``sources`` (the controller or motor program driving each step); outside: (N,) bool,
    the state lay outside the active controller's domain; switches: (t, source name) at each
    change of what drives the figure. ``source_kinds`` says 'controller' or 'motor' per source.

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
    variables the figure lacks, raises SpecError at the line that names it."""
    controllers: dict[str, Controller] = {}
    for command in script.commands:
        if not isinstance(command, SwapController | Breakpoint):
            continue
        if command.controller in controllers:
            continue
        path = controller_table_path(script, command, controller_dir)
        try:
            controllers[command.controller] = Controller.load(path, dynamics)
        except ValueError as error:  # a state variable or actuator the figure does not have
            raise script.error(
                command.table_token,
                f"a controller over state variables and actuators of the object's figure ({error})",
            ) from None
    return controllers


def load_programs(
    script: AnimationScript, motor_dir: str | Path, figure: str, dynamics: ModuleType
) -> dict[str, BoundMotorProgram]:
    """Every motor program the script runs, ``motor_dir/FIGURE/NAME.mot``, bound to the
    figure; a missing file raises SpecError at the ``motor`` line."""
    programs: dict[str, BoundMotorProgram] = {}
    for command in script.commands:
        if not isinstance(command, RunMotorProgram) or command.program in programs:
            continue
        path = Path(motor_dir) / figure / f"{command.program}.mot"
        if not path.exists():
            raise script.error(command.program_token, f"a motor program ({path} does not exist)")
        from mosys.animation.motor_program import load_motor_program

        programs[command.program] = load_motor_program(path, figure, dynamics)
    return programs


class _Recorder:
    """Accumulates the stretches of a run, and what drove each step."""

    def __init__(self, sources: tuple[str, ...]):
        self.sources = sources
        self.clock = 0.0
        self.t: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.inputs: list[np.ndarray] = []
        self.source: list[np.ndarray] = []
        self.outside: list[np.ndarray] = []
        self.switches: list[tuple[float, str]] = []
        self.driver: str | None = None

    def drive(self, name: str) -> None:
        if name != self.driver:
            self.switches.append((self.clock, name))
            self.driver = name

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


def run_script(script: AnimationScript, sources: ScriptSources, dt: float) -> ScriptRun:
    """Run ``script`` with its loaded ``sources``; dt is the simulator step, s."""
    dynamics = sources.dynamics
    names = tuple(sources.controllers) + tuple(sources.programs)
    kinds = ("controller",) * len(sources.controllers) + ("motor",) * len(sources.programs)
    recorder = _Recorder(names)
    input_size = len(dynamics.INPUT_NAMES)
    pending: SetState | None = None
    figure_state: np.ndarray | None = None
    active: Controller | None = None
    breakpoints: list[tuple[Bounds, str]] = []
    for command in script.commands:
        if isinstance(command, SetState):
            pending = command
        elif isinstance(command, SwapController):
            active = sources.controllers[command.controller]
        elif isinstance(command, Breakpoint):
            try:
                breakpoints.append((_checked_box(dynamics, command), command.controller))
            except ValueError as error:
                raise script.error(command.conditions[0].token, str(error)) from None
        elif isinstance(command, RunMotorProgram | Simulate):
            if pending is not None:
                figure_state = _figure_state(script, pending, active, sources)
                pending = None
            assert figure_state is not None  # the parser puts a 'state' first
            if isinstance(command, RunMotorProgram):
                program = sources.programs[command.program]
                recorder.drive(command.program)
                run = program.run(figure_state, dt)
                inputs = np.zeros((run.controls.shape[0], input_size))
                inputs[:, program.coordinate] = run.controls
                recorder.add(run.states, inputs, np.zeros(len(inputs), dtype=bool), dt)
                figure_state = run.states[-1]
            else:
                assert active is not None  # the parser puts a 'swapcon' first
                figure_state = _simulate(
                    command, active, breakpoints, sources, figure_state, dt, recorder
                )
    assert figure_state is not None and recorder.driver is not None
    # the final state, with the input of the last step held
    last_inputs = (
        recorder.inputs[-1][-1:] if recorder.inputs[-1].size else np.zeros((1, input_size))
    )
    recorder.add(np.stack([figure_state, figure_state]), last_inputs, np.zeros(1, bool), 0.0)
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
    )


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
    command: Simulate,
    active: Controller,
    breakpoints: list[tuple[Bounds, str]],
    sources: ScriptSources,
    figure_state: np.ndarray,
    dt: float,
    recorder: _Recorder,
) -> np.ndarray:
    """One ``sim``: the active controller, or a breakpoint's where its box holds the state, in
    stretches that end where the state crosses a box border; stops early in the arrival box."""
    boxes = [box for box, _ in breakpoints]
    if command.until_dest:
        boxes.append(active.arrival_box())
    boxes_si = regions(sources.dynamics, boxes)
    remaining = int(round(command.seconds / dt))
    while remaining > 0:
        inside = boxes_si.membership(figure_state)
        if command.until_dest and inside[-1]:
            break
        driver = active
        for k, (_, name) in enumerate(breakpoints):
            if inside[k]:
                driver = sources.controllers[name]
                break
        recorder.drive(driver.name)
        run = driver.simulate(figure_state, remaining * dt, dt, boxes_si)
        inputs = np.zeros((run.controls.shape[0], len(sources.dynamics.INPUT_NAMES)))
        inputs[:, driver.control_slot] = run.controls * driver.control_scale
        recorder.add(run.states, inputs, run.outside, dt)
        figure_state = run.states[-1]
        remaining -= run.controls.shape[0]
    return figure_state


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
        return state
    controller = active or next(iter(sources.controllers.values()), None)
    if controller is None:
        raise script.error(
            command.value_tokens[0],
            "state values by name (NAME=VALUE): no controller gives an order",
        )
    if len(command.values) != len(controller.state_order):
        raise script.error(
            command.value_tokens[0],
            f"{len(controller.state_order)} values in the order {','.join(controller.state_order)}",
        )
    return controller.figure_state(np.array(command.values))


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
