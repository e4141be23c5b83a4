"""Start states of a 3-D BSR figure: a pose stood on the floor, facing +x."""

from __future__ import annotations

import math

import numpy as np

from mosys.bsr.figure3d import BsrFigure3D
from mosys.kernels.bsr3d_simulate import CX, CY, JOINTS, QW, body_frame, new_scratch


def state_size(figure: BsrFigure3D) -> int:
    """S = 13 + 2J: centre of mass, its velocity, orientation, angular momentum, angles, rates."""
    return JOINTS + 2 * len(figure.joint_names)


def pose_at_rest(figure: BsrFigure3D, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The figure in the pose ``angles`` (J,) rad, in its body frame about its centre of mass:
    each rod's proximal and distal end (N, 2, 3) m, and each distinct endpoint's offset (E, 3)
    m."""
    n_rods = figure.parent.shape[0]
    rod_ends = np.empty((n_rods, 2, 3))
    offsets = np.empty((figure.endpoints.shape[0], 3))
    arrays = figure.arrays
    body_frame(
        *arrays[:9],
        np.asarray(angles, np.float64),
        np.zeros(len(figure.joint_names)),
        rod_ends,
        offsets,
        np.empty_like(offsets),
        np.empty((n_rods, 3, 3)),
        new_scratch(n_rods),
        np.empty((3, 3)),
        np.empty(3),
    )
    return rod_ends, offsets


def standing_state(
    figure: BsrFigure3D, root_angle: float, angles: np.ndarray, x: float = 0.0
) -> np.ndarray:
    """The state (S,) of the figure at rest in a pose with its lowest endpoint on the floor (at
    height 0 if there is no floor), its centre of mass at (x, ·, 0) m: the body frame turned by
    root_angle rad about the world z axis (as a 2-D figure's root angle), angles (J,) rad held
    inside their ranges."""
    n_angles = len(figure.joint_names)
    state = np.zeros(state_size(figure))
    angles = np.clip(np.asarray(angles, np.float64), figure.joint_min, figure.joint_max)
    state[JOINTS : JOINTS + n_angles] = angles
    _, offsets = pose_at_rest(figure, angles)
    heights = math.sin(root_angle) * offsets[:, 0] + math.cos(root_angle) * offsets[:, 1]
    floor = 0.0 if math.isnan(figure.floor) else figure.floor
    state[CX] = x
    state[CY] = floor - heights.min()
    state[QW] = math.cos(root_angle / 2.0)
    state[QW + 3] = math.sin(root_angle / 2.0)
    return state
