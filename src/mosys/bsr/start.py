"""Start states of a BSR figure: a pose stood on the floor, and its random perturbations."""

from __future__ import annotations

import math

import numpy as np

from mosys.bsr.figure import BsrFigure
from mosys.kernels.bsr_simulate import CX, CY, JOINTS, MOMENTUM, PHI, VX, VY, figure_body_frame
from mosys.parsing.bsr import Perturbation


def state_size(figure: BsrFigure) -> int:
    """S = 6 + 2J: centre of mass, its velocity, root angle, angular momentum, joints, rates."""
    return JOINTS + 2 * len(figure.joint_names)


def standing_state(
    figure: BsrFigure,
    root_angle: float,
    joints: np.ndarray,
    x: float = 0.0,
    velocity: tuple[float, float] = (0.0, 0.0),
    spin: float = 0.0,
) -> np.ndarray:
    """The state (S,) of the figure in a pose with its lowest endpoint on the floor (at height 0
    if there is no floor) and its centre of mass at ``x`` m: root_angle rad, joints (J,) rad
    (held inside their ranges), velocity m/s of the centre of mass, spin rad/s, joints at rest."""
    n_joints = len(figure.joint_names)
    state = np.zeros(state_size(figure))
    theta = np.clip(np.asarray(joints, np.float64), figure.joint_min, figure.joint_max)
    state[JOINTS : JOINTS + n_joints] = theta
    rod_ends = np.empty((figure.parent.shape[0], 2, 2))
    offsets = np.empty((figure.endpoints.shape[0], 2))
    velocities = np.empty_like(offsets)
    _, inertia, _ = figure_body_frame(
        figure.arrays,
        theta,
        np.zeros(n_joints),
        rod_ends,
        offsets,
        velocities,
        np.empty((figure.parent.shape[0], 8)),
    )
    heights = math.sin(root_angle) * offsets[:, 0] + math.cos(root_angle) * offsets[:, 1]
    floor = 0.0 if math.isnan(figure.floor) else figure.floor
    state[CX] = x
    state[CY] = floor - heights.min()
    state[VX], state[VY] = velocity
    state[PHI] = root_angle
    state[MOMENTUM] = inertia * spin
    return state


def perturbed_state(
    figure: BsrFigure,
    root_angle: float,
    joints: np.ndarray,
    x: float,
    perturbation: Perturbation,
    rng: np.random.Generator,
) -> np.ndarray:
    """A start state drawn uniformly around the pose: root angle ± perturbation.angle deg, each
    joint ± perturbation.joints deg, each velocity component ± speed m/s, spin ± spin deg/s
    (always five draws of the generator per joint-free part, so the stream stays aligned)."""
    unit = rng.uniform(-1.0, 1.0, size=4 + len(figure.joint_names))
    return standing_state(
        figure,
        root_angle + math.radians(perturbation.angle) * unit[0],
        joints + math.radians(perturbation.joints) * unit[4:],
        x,
        (perturbation.speed * unit[1], perturbation.speed * unit[2]),
        math.radians(perturbation.spin) * unit[3],
    )
