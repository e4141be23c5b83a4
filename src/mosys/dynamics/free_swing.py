"""The free swing of a one-joint figure with its motor off: the closed orbits and the separatrix
of the 1990 paper's Figure 5, computed by simulating the compiled dynamics (no formula of the
pendulum is assumed: the equilibria and the separatrix are found from ``derivative_into``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from mosys.errors import InputError
from mosys.kernels.motor import run_motor_program
from mosys.kernels.soundness import steps_before_blow_up

FREE_SWING_DT = 0.001  # s: the simulator step of the free swing
ORBIT_SECONDS = 8.0  # s simulated per orbit: longer than one period of every drawn orbit
LIBRATION_FRACTIONS = (0.15, 0.35, 0.55, 0.75, 0.9)  # amplitudes, fractions of the way to upright
ROTATION_FACTORS = (1.15, 1.45)  # rotating orbits' rate at the bottom, times the separatrix's
BISECTION_STEPS = 40  # halvings of the separatrix's rate bracket (relative width 1e-12)
EQUILIBRIUM_SAMPLES = 3600  # angles at which the acceleration at rest is sampled


@dataclass(frozen=True)
class FreeSwing:
    """A figure swinging freely, SI. ``hanging`` and ``upright``: the stable and unstable
    equilibrium angles, rad; ``separatrix_rate``: the rate at ``hanging`` (rad/s) that just
    reaches ``upright``; ``librations``, ``rotations``: closed and rotating orbits, each an
    (N, 2) array of (angle, rate) samples over ``ORBIT_SECONDS``; ``separatrix``: the two
    halves of the separatrix (both directions of travel), each (N, 2)."""

    hanging: float
    upright: float
    separatrix_rate: float
    librations: tuple[np.ndarray, ...]
    rotations: tuple[np.ndarray, ...]
    separatrix: tuple[np.ndarray, ...]


def free_motion(dynamics: ModuleType, angle: float, rate: float, seconds: float) -> np.ndarray:
    """(N, 2) (angle rad, rate rad/s) of a one-coordinate figure with its inputs at 0, from
    (``angle``, ``rate``) for ``seconds``; InputError if the state becomes non-finite. Run by
    the motor-program kernel with no actuator: every input stays 0."""
    _check_one_coordinate(dynamics)
    steps = int(round(seconds / FREE_SWING_DT))
    record = np.empty((steps + 1, 2))
    state = np.array([angle, rate], dtype=np.float64)
    none = np.empty((steps, 0))  # per step and actuator: there is no actuator
    taken = run_motor_program(
        dynamics.derivative_into,
        np.empty((steps, 0), dtype=np.int64),
        none,
        none,
        none,
        none,
        np.empty(0),
        np.empty(0),
        np.empty(0),
        np.empty(0, dtype=np.int64),
        len(dynamics.INPUT_NAMES),
        state,
        FREE_SWING_DT,
        record[:-1],
        np.empty((steps, 0)),
    )
    if taken < 0:
        at = steps_before_blow_up(taken) * FREE_SWING_DT
        raise InputError(f"the free swing became non-finite at t = {at} s")
    record[-1] = state
    return record


def _check_one_coordinate(dynamics: ModuleType) -> None:
    """InputError unless the figure's state is one coordinate and its rate (the kernels would
    read past the end of a shorter state)."""
    if dynamics.COORDINATE_COUNT != 1 or len(dynamics.STATE_NAMES) != 2:
        coordinates = dynamics.STATE_NAMES[: dynamics.COORDINATE_COUNT]
        raise InputError(
            "expected a figure with one coordinate, such as the pendulum; this one has "
            f"{dynamics.COORDINATE_COUNT} ({', '.join(coordinates)})"
        )


def equilibria(dynamics: ModuleType) -> tuple[float, float]:
    """(hanging, upright), rad: the angles where the figure at rest has no acceleration, stable
    (the acceleration falls through 0 as the angle grows) and unstable (it rises through 0)."""
    _check_one_coordinate(dynamics)
    angles = np.linspace(-math.pi, math.pi, EQUILIBRIUM_SAMPLES, endpoint=False)
    acceleration = np.empty_like(angles)
    out = np.empty(2)
    zero = np.zeros(len(dynamics.INPUT_NAMES))
    for k, angle in enumerate(angles):
        dynamics.derivative_into(np.array([angle, 0.0]), zero, out)
        acceleration[k] = out[1]
    following = np.roll(acceleration, -1)
    stable = np.flatnonzero((acceleration > 0) & (following <= 0))
    unstable = np.flatnonzero((acceleration < 0) & (following >= 0))
    if len(stable) != 1 or len(unstable) != 1:  # e.g. a joint limit's spring adds rest angles
        raise InputError(
            "expected a figure with one stable and one unstable rest angle, such as the "
            f"pendulum; this one has {len(stable)} stable and {len(unstable)} unstable at rest "
            "(a joint limit or a contact adds rest angles, and the free-swing orbits need none)"
        )
    step = angles[1] - angles[0]

    def crossing(k: int) -> float:
        a, b = acceleration[k], following[k]
        return float(angles[k] + step * a / (a - b))

    return crossing(int(stable[0])), crossing(int(unstable[0]))


def _goes_over(dynamics: ModuleType, hanging: float, upright: float, rate: float) -> bool:
    """Whether the figure thrown from ``hanging`` at ``rate`` (> 0) passes ``upright``."""
    path = free_motion(dynamics, hanging, rate, ORBIT_SECONDS)
    ahead = (upright - hanging) % (2 * math.pi)
    return bool((path[:, 0] - hanging >= ahead).any())


def free_swing(dynamics: ModuleType) -> FreeSwing:
    """The free-swing orbits of a one-coordinate figure (the 1990 pendulum: Figure 5)."""
    hanging, upright = equilibria(dynamics)
    low, high = 0.0, 1.0
    while not _goes_over(dynamics, hanging, upright, high):
        low, high = high, 2 * high
        if high > 1e4:
            raise InputError("a figure that goes over the top when thrown hard enough")
    for _ in range(BISECTION_STEPS):
        middle = 0.5 * (low + high)
        low, high = (
            (low, middle) if _goes_over(dynamics, hanging, upright, middle) else (middle, high)
        )
    separatrix_rate = low
    ahead = (upright - hanging) % (2 * math.pi)
    librations = tuple(
        free_motion(dynamics, hanging + fraction * ahead, 0.0, ORBIT_SECONDS)
        for fraction in LIBRATION_FRACTIONS
    )
    rotations = tuple(
        free_motion(dynamics, hanging, sign * factor * separatrix_rate, ORBIT_SECONDS)
        for factor in ROTATION_FACTORS
        for sign in (1.0, -1.0)
    )
    separatrix = tuple(
        free_motion(dynamics, hanging, sign * separatrix_rate, ORBIT_SECONDS / 2)
        for sign in (1.0, -1.0)
    )
    return FreeSwing(hanging, upright, separatrix_rate, librations, rotations, separatrix)
