"""Motor programs at run time: a parsed ``.mot`` bound to its figure's dynamics, laid out one
row per step (phases held, keyframes interpolated), and its open-loop simulation
(``kernels.motor``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from mosys.errors import NonFiniteStateError
from mosys.kernels.motor import run_motor_program
from mosys.kernels.soundness import steps_before_blow_up
from mosys.parsing.motor import (
    BoundProgram,
    MotorProgram,
    bind_motor_program,
    parse_motor_program,
)


@dataclass(frozen=True)
class MotorRun:
    """A motor program's motion: states (steps+1, S) SI, the first the start; controls
    (steps, A) N m of its actuators; phase (steps,) int64, the phase of each step (of a
    keyframed program: the key interval, k for the steps from key k up to key k + 1);
    final_controls (A,) N m, each actuator's torque on the last step (the ``previous`` passed
    in when the program has no steps), to carry a slew limit on to what drives the figure next.
    """

    states: np.ndarray
    controls: np.ndarray
    phase: np.ndarray
    final_controls: np.ndarray


@dataclass(frozen=True)
class StepRows:
    """What a program asks of each of A actuators on each step, for ``run_motor_program``:
    mode (steps, A) int64 (LIMP, TORQUE, SERVO); value (steps, A) float64, the constant torque
    (N m) or the servo's target angle (rad); rate (steps, A) float64, the target's rate, rad/s
    (0 for phases); kp (steps, A) N m/rad, kd (steps, A) N m s/rad; phase (steps,) int64, the
    phase (or key interval) of each step."""

    mode: np.ndarray
    value: np.ndarray
    rate: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    phase: np.ndarray


def keyframe_curve(
    times: np.ndarray, values: np.ndarray, t: np.ndarray | float
) -> tuple[np.ndarray, np.ndarray]:
    """The keyframe interpolant and its rate at times ``t``.

    times: (K,) float64, s, strictly increasing, K >= 2; values: (K,) or (K, A), any unit;
    t: (T,) or a scalar, s. Returns (target, rate), each of shape t.shape + values.shape[1:],
    in values' unit and that unit per second.

    The curve is the C1 cubic Hermite spline through the keys with Catmull-Rom (cardinal,
    tension 0; Kochanek & Bartels 1984 with tension, continuity and bias 0) tangents for uneven
    spacing, ``m_k = (v[k+1] - v[k-1]) / (t[k+1] - t[k-1])``, and zero tangents at the first and
    last keys, so a keyframed motion starts and ends at rest. On [t_k, t_k+1], with
    h = t_k+1 - t_k and s = (t - t_k) / h:
    ``v_k + (v_k+1 - v_k) (3s² - 2s³) + h (m_k (s³ - 2s² + s) + m_k+1 (s³ - s²))``.
    The curve passes exactly through every key, and holds the first (last) key's value, at rate
    0, before (after) the keys.
    """
    times = np.asarray(times, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    flat = values.reshape(len(times), -1)  # (K, A)
    tangent = np.zeros_like(flat)
    tangent[1:-1] = (flat[2:] - flat[:-2]) / (times[2:] - times[:-2])[:, None]
    when = t.reshape(-1)
    k = np.clip(np.searchsorted(times, when, side="right") - 1, 0, len(times) - 2)
    h = (times[k + 1] - times[k])[:, None]
    s = np.clip((when - times[k]) / h[:, 0], 0.0, 1.0)[:, None]
    rise = flat[k + 1] - flat[k]
    target = (
        flat[k]
        + rise * (s * s * (3.0 - 2.0 * s))
        + h * (tangent[k] * (s * (s - 1.0) * (s - 1.0)) + tangent[k + 1] * (s * s * (s - 1.0)))
    )
    rate = rise * (6.0 * s * (1.0 - s)) / h + (
        tangent[k] * ((3.0 * s - 1.0) * (s - 1.0)) + tangent[k + 1] * (s * (3.0 * s - 2.0))
    )
    after = when >= times[-1]  # the last key exactly (a + (b - a) need not give b)
    target[after] = flat[-1]
    rate[after] = 0.0
    shape = t.shape + values.shape[1:]
    return target.reshape(shape), rate.reshape(shape)


def step_rows(bound: BoundProgram, dt: float) -> StepRows:
    """Lay ``bound`` out one row per RK4 step of dt seconds.

    Phases: each lasts its duration rounded to whole steps, its row repeated, target rate 0.
    Keyframes: round(duration / dt) steps; step i servos towards ``keyframe_curve`` (target and
    rate) at its start, i dt.
    """
    if bound.key_times is None:
        phase_steps = np.rint(bound.durations / dt).astype(np.int64)

        def rows(array: np.ndarray) -> np.ndarray:
            return np.ascontiguousarray(np.repeat(array, phase_steps, axis=0))

        value = rows(bound.value)
        return StepRows(
            mode=rows(bound.mode),
            value=value,
            rate=np.zeros_like(value),
            kp=rows(bound.kp),
            kd=rows(bound.kd),
            phase=np.repeat(np.arange(len(phase_steps), dtype=np.int64), phase_steps),
        )
    times = bound.key_times
    steps = int(np.rint(times[-1] / dt))
    t = dt * np.arange(steps, dtype=np.float64)
    target, rate = keyframe_curve(times, bound.value, t)  # limp actuators' values: all 0
    interval = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)

    def held(array: np.ndarray) -> np.ndarray:
        """Row 0 of ``array`` for every step, (steps, A), writable: a copy (for 0 or 1 steps,
        ``ascontiguousarray`` would hand back the read-only broadcast view itself)."""
        return np.broadcast_to(array[0], (steps, array.shape[1])).copy()

    return StepRows(
        mode=held(bound.mode),
        value=np.ascontiguousarray(target),
        rate=np.ascontiguousarray(rate),
        kp=held(bound.kp),
        kd=held(bound.kd),
        phase=interval.astype(np.int64),
    )


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
        return self.bound.duration()

    def step_rows(self, dt: float) -> StepRows:
        """The program one row per step of dt seconds (``step_rows``)."""
        return step_rows(self.bound, dt)

    def _per_actuator(self, name: str, values: np.ndarray) -> np.ndarray:
        """``values`` as a new (A,) float64 array, one per actuator; ValueError naming
        ``name`` for any other shape."""
        array = np.array(values, dtype=np.float64)
        if array.shape != (len(self.coordinate),):
            raise ValueError(
                f"{name} has shape {array.shape}, expected ({len(self.coordinate)},): one per "
                f"actuator of {self.bound.actuator_names}"
            )
        return array

    def run(
        self,
        figure_state: np.ndarray,
        dt: float,
        slew_rate: np.ndarray | None = None,
        previous: np.ndarray | None = None,
    ) -> MotorRun:
        """Run the program from ``figure_state`` (S,) SI with RK4 steps of dt seconds; each
        phase lasts its duration rounded to whole steps, a keyframed program its last key's
        time rounded to whole steps.

        slew_rate: (A,) N m/s, the fastest each actuator's torque may change (actuators in
        ``self.coordinate`` order; inf: no limit; None: no limit for any). previous: (A,) N m,
        the torques before the first step, where the slew limit starts from (None: zeros).
        Each step's torque moves at most slew_rate dt from the step before; ``final_controls``
        of the result is the last step's, to pass as ``previous`` to what follows. A slew_rate
        or previous of the wrong shape, a negative or NaN slew_rate, or a non-finite previous
        raises ValueError. A state that becomes non-finite (``kernels.motor``) raises
        ``errors.NonFiniteStateError`` with the time from the run's start and that state.
        """
        actuators = len(self.coordinate)
        slew_step = np.full(actuators, np.inf)
        if slew_rate is not None:
            slew_rate = self._per_actuator("slew_rate", slew_rate)
            if not (slew_rate >= 0).all():  # NaN fails too
                raise ValueError(f"slew_rate must be >= 0 N m/s, got {slew_rate.tolist()}")
            slew_step = slew_rate * float(dt)
        torque = np.zeros(actuators)
        if previous is not None:
            torque = self._per_actuator("previous", previous)
            if not np.isfinite(torque).all():
                raise ValueError(f"previous must be finite N m, got {torque.tolist()}")
        rows = self.step_rows(dt)
        steps = len(rows.phase)
        state = np.ascontiguousarray(figure_state, dtype=np.float64).copy()
        states = np.empty((steps + 1, len(state)))
        controls = np.empty((steps, actuators))
        taken = run_motor_program(
            self.dynamics.derivative_into,
            rows.mode,
            rows.value,
            rows.rate,
            rows.kp,
            rows.kd,
            np.ascontiguousarray(self.bound.limit, dtype=np.float64),
            np.ascontiguousarray(slew_step),
            torque,
            self.coordinate,
            len(self.dynamics.INPUT_NAMES),
            state,
            float(dt),
            states[:-1],
            controls,
        )
        if taken < 0:
            from mosys.ssc.controller import non_finite_message

            t = steps_before_blow_up(taken) * dt
            driver = f"motor program {self.name}"
            raise NonFiniteStateError(non_finite_message(self.dynamics, t, state, driver), t, state)
        states[-1] = state
        return MotorRun(states, controls, rows.phase, torque)


def load_motor_program(path: str | Path, figure: str, dynamics: ModuleType) -> BoundMotorProgram:
    """Parse the ``.mot`` at ``path`` and bind it to ``dynamics``; SpecError (naming the line)
    when it is written for another figure than ``figure`` or names what the figure lacks."""
    program = parse_motor_program(path)
    if program.figure != figure:
        raise program.error(program.figure_token, f"figure '{figure}' (the script's object)")
    return BoundMotorProgram(program, dynamics)
