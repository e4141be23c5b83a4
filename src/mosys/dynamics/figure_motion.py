"""The ``figure_motion`` of a figure from its state over time (the one picture of a moving
articulated figure that plots draw)."""

from __future__ import annotations

import json
from types import ModuleType

import numpy as np

from mosys.io.trajectory import Contacts, FigureMotion
from mosys.kernels.figure_motion import endpoints_over_time


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


def figure_contacts(dynamics: ModuleType, figure_states: np.ndarray) -> Contacts | None:
    """The figure's contact points and the ground's forces on them for each state (N, 2n) SI,
    or None for a figure without contact points. (A Python loop over samples: this runs once per
    trajectory written, after the simulation.)"""
    count = len(getattr(dynamics, "CONTACT_ROD", ()))
    if count == 0:
        return None
    n = dynamics.COORDINATE_COUNT
    position = np.empty((len(figure_states), count, 2))
    force = np.empty((len(figure_states), count, 2))
    for sample, state in enumerate(figure_states):
        q, qd = np.ascontiguousarray(state[:n]), np.ascontiguousarray(state[n:])
        position[sample] = dynamics.contact_points(q)
        force[sample] = dynamics.contact_forces(q, qd)
    rods = tuple(dynamics.ROD_NAMES[rod] for rod in dynamics.CONTACT_ROD)
    return Contacts(position, force, rods, np.asarray(dynamics.CONTACT_FRACTION, np.float64))
