"""Motor programs at run time: a parsed ``.mot`` bound to its figure's dynamics, and its
open-loop simulation (``kernels.motor``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from mosys.kernels.motor import run_motor_program
from mosys.parsing.motor import MotorProgram, bind_motor_program, parse_motor_program


@dataclass(frozen=True)
class MotorRun:
    """A motor program's motion: states (steps+1, S) SI, the first the start; controls
    (steps, A) N m of its actuators; phase (steps,) int64, the phase of each step."""

    states: np.ndarray
    controls: np.ndarray
    phase: np.ndarray


class BoundMotorProgram:
    """A motor program bound to a figure: the kernel's arrays, and ``run``."""

    def __init__(self, program: MotorProgram, dynamics: ModuleType):
        self.program = program
        self.name = program.name
        self.dynamics = dynamics
        n = dynamics.COORDINATE_COUNT
        self.bound = bind_motor_program(
            program, tuple(dynamics.Q_NAMES), tuple(dynamics.INPUT_NAMES)[:n]
        )
        self.coordinate = np.ascontiguousarray(self.bound.coordinate, dtype=np.int64)

    def duration(self) -> float:
        """The program's length, s."""
        return float(self.bound.durations.sum())

    def run(self, figure_state: np.ndarray, dt: float) -> MotorRun:
        """Run the program from ``figure_state`` (S,) SI with RK4 steps of dt seconds; each
        phase lasts its duration rounded to whole steps."""
        bound = self.bound
        phase_steps = np.rint(bound.durations / dt).astype(np.int64)
        steps = int(phase_steps.sum())
        state = np.ascontiguousarray(figure_state, dtype=np.float64).copy()
        states = np.empty((steps + 1, len(state)))
        controls = np.empty((steps, len(self.coordinate)))
        phase = np.empty(steps, dtype=np.int64)
        run_motor_program(
            self.dynamics.derivative_into,
            phase_steps,
            np.ascontiguousarray(bound.mode, dtype=np.int64),
            np.ascontiguousarray(bound.value, dtype=np.float64),
            np.ascontiguousarray(bound.kp, dtype=np.float64),
            np.ascontiguousarray(bound.kd, dtype=np.float64),
            np.ascontiguousarray(bound.limit, dtype=np.float64),
            self.coordinate,
            len(self.dynamics.INPUT_NAMES),
            state,
            float(dt),
            states[:-1],
            controls,
            phase,
        )
        states[-1] = state
        return MotorRun(states, controls, phase)


def load_motor_program(path: str | Path, figure: str, dynamics: ModuleType) -> BoundMotorProgram:
    """Parse the ``.mot`` at ``path`` and bind it to ``dynamics``; SpecError (naming the line)
    when it is written for another figure than ``figure`` or names what the figure lacks."""
    program = parse_motor_program(path)
    if program.figure != figure:
        raise program.error(program.figure_token, f"figure '{figure}' (the script's object)")
    return BoundMotorProgram(program, dynamics)
