"""Lone contacts in a recorded figure motion (planar or 3-D): the 1995 paper's friction rule
"when only one rod endpoint is in contact with the ground, it is not allowed to move
horizontally" (§2.1.1), checked on a ``figure_motion`` group after the fact.

A *lone contact* is a stretch of consecutive samples during which exactly one distinct rod
endpoint is down (within ``CONTACT_HEIGHT`` of the floor and moving vertically slower than
``STILL_SPEED``) while every other distinct endpoint is at least ``CLEAR_HEIGHT`` above the
floor, lasting at least ``MIN_DURATION``. Its *excursion* is the horizontal extent (max x − min x)
of that endpoint over the stretch (3-D: the diagonal of its x-z extent); the rule holds if the
excursion stays under ``MAX_EXCURSION``.

Choices: an endpoint below the floor counts as down; the vertical speed of sample i is the
central difference (y[i+1] − y[i−1]) / (t[i+1] − t[i−1]), one-sided at the first and last
sample; rod ends at the same place (within ``SAME_POINT`` in x and y) at every sample are one
endpoint, named by the first of them in (rod, end) order; a stretch's duration is
t_end − t_start over its first and last samples, compared with ``MIN_DURATION`` to within
``TIME_TOLERANCE``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mosys.errors import InputError

# m: an endpoint at most this far above the floor is down: the simulators' own contact
# tolerance, kernels.bsr_simulate.CONTACT_TOLERANCE (an endpoint higher is in the air for them,
# and every endpoint the floor pushes ends its step exactly on the floor). A literal, so that
# reading a file (``mosys info``) does not load numba; tests/test_lone_contact.py holds the two
# equal.
CONTACT_HEIGHT = 1e-3
STILL_SPEED = 1e-2  # m/s: ... if it also moves vertically slower than this
CLEAR_HEIGHT = 1e-2  # m: every other endpoint at least this far above the floor
MIN_DURATION = 20e-3  # s: the shortest stretch that counts as a lone contact
MAX_EXCURSION = 5e-3  # m: a lone contact sliding this far or more breaks the rule
SAME_POINT = 1e-9  # m: rod ends this close at every sample are one endpoint
TIME_TOLERANCE = 1e-9  # s: slack on MIN_DURATION for sample times that are not exact


@dataclass(frozen=True)
class LoneContact:
    """One lone contact: endpoint ``end`` (0 proximal, 1 distal) of rod ``rod`` (index into
    the motion's rods) alone on the floor from ``t_start`` to ``t_end`` (s, its first and last
    samples), its x spanning ``excursion`` m over them."""

    rod: int
    end: int
    t_start: float
    t_end: float
    excursion: float

    @property
    def duration(self) -> float:
        """t_end − t_start, s."""
        return self.t_end - self.t_start


def distinct_endpoints(endpoints: np.ndarray) -> np.ndarray:
    """(E, 2) int64 rod and end (0 proximal, 1 distal) of each distinct endpoint of a motion's
    endpoints (N, n_rods, 2, D) m (D = 2 or 3): a rod end that stays within ``SAME_POINT`` of an
    earlier one (in (rod, end) order) at every sample is that one, not a new endpoint."""
    n_rods = endpoints.shape[1]
    points = endpoints.reshape(endpoints.shape[0], 2 * n_rods, endpoints.shape[3])
    kept: list[int] = []
    for slot in range(2 * n_rods):
        if not any(
            np.all(np.abs(points[:, slot] - points[:, other]) <= SAME_POINT) for other in kept
        ):
            kept.append(slot)
    return np.array([(slot // 2, slot % 2) for slot in kept], np.int64).reshape(-1, 2)


def vertical_speed(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Vertical speed (N, E) m/s of heights y (N, E) m sampled at t (N,) s, strictly
    increasing, N >= 2: central differences inside, one-sided at both ends."""
    speed = np.empty_like(y)
    speed[1:-1] = (y[2:] - y[:-2]) / (t[2:] - t[:-2])[:, None]
    speed[0] = (y[1] - y[0]) / (t[1] - t[0])
    speed[-1] = (y[-1] - y[-2]) / (t[-1] - t[-2])
    return speed


def lone_contacts(t: np.ndarray, endpoints: np.ndarray, floor: float = 0.0) -> list[LoneContact]:
    """Every maximal lone contact lasting at least ``MIN_DURATION`` in a motion, in order of
    start time (then rod, then end).

    t: (N,) s, strictly increasing; endpoints: (N, n_rods, 2, D) m, per sample and rod its
    proximal then distal end (x, y) or (x, y, z), y up (the ``figure_motion`` contract); floor:
    the floor's height, m. Raises InputError for arrays of another shape or times that do not
    increase.
    """
    t = np.asarray(t, np.float64)
    endpoints = np.asarray(endpoints, np.float64)
    if t.ndim != 1:
        raise InputError(f"t must be 1-D (N,), got shape {t.shape}")
    if (
        endpoints.ndim != 4
        or endpoints.shape[0] != t.shape[0]
        or endpoints.shape[2:] not in ((2, 2), (2, 3))
    ):
        raise InputError(
            f"endpoints must have shape (N, n_rods, 2, 2) or (N, n_rods, 2, 3) with N = "
            f"{t.shape[0]} samples of t, got {endpoints.shape}"
        )
    steps = np.diff(t)
    if np.any(~(steps > 0.0)):
        first = int(np.flatnonzero(~(steps > 0.0))[0])
        raise InputError(
            f"t must increase strictly: t[{first + 1}] = {t[first + 1]} s follows "
            f"t[{first}] = {t[first]} s"
        )
    if t.shape[0] < 2 or endpoints.shape[1] == 0:
        return []
    ends = distinct_endpoints(endpoints)
    horizontal = [axis for axis in range(endpoints.shape[3]) if axis != 1]
    places = endpoints[:, ends[:, 0], ends[:, 1]][:, :, horizontal]  # (N, E, 1 or 2)
    height = endpoints[:, ends[:, 0], ends[:, 1], 1] - floor
    down = (height <= CONTACT_HEIGHT) & (np.abs(vertical_speed(t, height)) < STILL_SPEED)
    clear = height >= CLEAR_HEIGHT
    clear_count = clear.sum(axis=1)
    # endpoint e is alone: it is down and every other endpoint is clear
    alone = down & (clear_count[:, None] - clear == ends.shape[0] - 1)
    found = []
    for e in range(ends.shape[0]):
        edges = np.diff(np.concatenate(([0], alone[:, e].astype(np.int8), [0])))
        starts = np.flatnonzero(edges == 1)
        stops = np.flatnonzero(edges == -1)
        for first, stop in zip(starts, stops, strict=True):
            last = stop - 1
            if t[last] - t[first] < MIN_DURATION - TIME_TOLERANCE:
                continue
            span = places[first:stop, e]
            extent = span.max(axis=0) - span.min(axis=0)
            found.append(
                LoneContact(
                    rod=int(ends[e, 0]),
                    end=int(ends[e, 1]),
                    t_start=float(t[first]),
                    t_end=float(t[last]),
                    excursion=float(np.sqrt((extent**2).sum())),
                )
            )
    return sorted(found, key=lambda c: (c.t_start, c.rod, c.end))


def sliding(contacts: list[LoneContact], limit: float = MAX_EXCURSION) -> list[LoneContact]:
    """The lone contacts whose excursion is ``limit`` m (default ``MAX_EXCURSION``) or more."""
    return [contact for contact in contacts if contact.excursion >= limit]
