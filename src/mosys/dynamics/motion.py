"""The ``figure_motion`` of a figure from its state over time (the one picture of a moving
articulated figure that plots draw)."""

from __future__ import annotations

import json
from types import ModuleType

import numpy as np

from mosys.io.trajectory import FigureMotion
from mosys.kernels.motion import endpoints_over_time


def figure_motion(dynamics: ModuleType, t: np.ndarray, figure_states: np.ndarray) -> FigureMotion:
    """FigureMotion for samples ``t`` (N,) s of figure states (N, 2n) q‖qd, SI (the first
    ``COORDINATE_COUNT`` entries of each state are q)."""
    n = dynamics.COORDINATE_COUNT
    coordinates = np.ascontiguousarray(figure_states[:, :n])
    endpoints = np.empty((len(t), len(dynamics.ROD_NAMES), 2, 2))
    endpoints_over_time(dynamics.endpoints_into, coordinates, endpoints)
    mass = np.asarray(dynamics.ROD_MASS, dtype=np.float64)
    fraction = np.asarray(dynamics.ROD_COM, dtype=np.float64)
    proximal, distal = endpoints[:, :, 0, :], endpoints[:, :, 1, :]
    rod_centres = proximal + fraction[None, :, None] * (distal - proximal)
    com = np.einsum("r,nrk->nk", mass, rod_centres) / mass.sum()
    return FigureMotion(
        t=np.asarray(t, dtype=np.float64),
        endpoints=endpoints,
        com=com,
        rod_names=tuple(dynamics.ROD_NAMES),
        rod_mass=mass,
        rod_length=np.asarray(dynamics.ROD_LENGTH, dtype=np.float64),
        rod_com=fraction,
        rod_inertia=np.asarray(dynamics.ROD_INERTIA, dtype=np.float64),
        gravity=float(dynamics.GRAVITY),
        terrain=json.loads(dynamics.TERRAIN_JSON),
        contact=str(dynamics.CONTACT_MODEL),
    )
