"""The animation-script runner (paper §5.2, Figure 15): a ``.anim`` script and the controllers it
names → one trajectory.

``state`` values are read in the state order of the controller active at the next ``sim`` (every
controller a script uses must share one state order); figure state variables that order leaves out
start at 0. ``swapcon`` switches controller at once; ``sim`` runs the active controller for that
many seconds, in whole steps of ``dt``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from mosys.parsing.script import AnimationScript, SetState, Simulate, SwapController
from mosys.ssc.controller import Controller


@dataclass(frozen=True)
class ScriptRun:
    """A script's motion. t: (N,) s; figure_states: (N, S) SI; state: (N, d) in the controllers'
    state order and spec units (wrap axes reduced into the first controller's range); control:
    (N, m); controller: (N,) int64 index into ``controllers``; outside: (N,) bool, the state lay
    outside the active controller's domain; switches: (t, controller name) at each ``swapcon``."""

    t: np.ndarray
    figure_states: np.ndarray
    state: np.ndarray
    control: np.ndarray
    controller: np.ndarray
    outside: np.ndarray
    controllers: tuple[str, ...]
    state_order: tuple[str, ...]
    control_names: tuple[str, ...]
    switches: tuple[tuple[float, str], ...]


def controller_table_path(
    script: AnimationScript, command: SwapController, controller_dir: str | Path
) -> Path:
    """The table a ``swapcon`` names, ``controller_dir/NAME.h5``; SpecError at the line if it
    does not exist."""
    path = Path(controller_dir) / f"{command.controller}.h5"
    if not path.exists():
        raise script.error(command.table_token, f"a controller table ({path} does not exist)")
    return path


def load_controllers(
    script: AnimationScript, controller_dir: str | Path, dynamics: ModuleType
) -> dict[str, Controller]:
    """Every controller the script names, from ``controller_dir/NAME.h5``; a missing table or one
    whose state order differs from the first raises SpecError at the ``swapcon`` line."""
    controllers: dict[str, Controller] = {}
    for command in script.commands:
        if not isinstance(command, SwapController) or command.controller in controllers:
            continue
        path = controller_table_path(script, command, controller_dir)
        controller = Controller.load(path, dynamics)
        if controllers:
            first = next(iter(controllers.values()))
            if controller.state_order != first.state_order:
                raise script.error(
                    command.table_token,
                    f"a controller with state order {first.state_order}",
                )
        controllers[command.controller] = controller
    return controllers


def run_script(script: AnimationScript, controllers: dict[str, Controller], dt: float) -> ScriptRun:
    """Run ``script`` with its loaded ``controllers``; dt is the simulator step, s."""
    names = tuple(controllers)
    first = controllers[names[0]]
    pending_state: SetState | None = None
    figure_state: np.ndarray | None = None
    active: Controller | None = None
    times, states, controls, indices, outside = [], [], [], [], []
    switches: list[tuple[float, str]] = []
    clock = 0.0
    for command in script.commands:
        if isinstance(command, SetState):
            pending_state = command
        elif isinstance(command, SwapController):
            active = controllers[command.controller]
            switches.append((clock, command.controller))
        elif isinstance(command, Simulate):
            if pending_state is not None:
                if len(pending_state.values) != len(active.state_order):
                    raise script.error(
                        pending_state.value_tokens[0],
                        f"{len(active.state_order)} values in the order "
                        f"{','.join(active.state_order)}",
                    )
                figure_state = active.figure_state(np.array(pending_state.values))
                pending_state = None
            run = active.simulate(figure_state, command.seconds, dt)
            steps = run.controls.shape[0]
            times.append(clock + dt * np.arange(steps))
            states.append(run.states[:-1])
            controls.append(run.controls)
            indices.append(np.full(steps, names.index(active.name), dtype=np.int64))
            outside.append(run.outside)
            figure_state = run.states[-1]
            clock += steps * dt
    # the final state, with the control the last controller would apply there
    times.append(np.array([clock]))
    states.append(figure_state[None, :])
    controls.append(active.torque(active.controller_states(figure_state[None, :])[0])[None, :])
    indices.append(np.array([names.index(active.name)], dtype=np.int64))
    outside.append(np.array([False]))
    figure_states = np.concatenate(states)
    return ScriptRun(
        t=np.concatenate(times),
        figure_states=figure_states,
        state=first.controller_states(figure_states),
        control=np.concatenate(controls),
        controller=np.concatenate(indices),
        outside=np.concatenate(outside),
        controllers=names,
        state_order=first.state_order,
        control_names=first.table.control_names,
        switches=tuple(switches),
    )
