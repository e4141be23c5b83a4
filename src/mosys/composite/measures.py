"""What each phase of a stored composite motion did, measured on its samples: how far the centre
of mass went (m), how far rod 0 turned (turns), how high the lowest rod endpoint got (m, the
height the figure cleared: above 0 only when no endpoint touches the ground), and how high it
got after the phase first touched the ground (a flight of the phase's own, not one the phase
before launched)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mosys.io.composite_result import CompositeMotion
from mosys.kernels.libm import arctan2_each

GROUND = 0.001  # m: an endpoint this close to the ground touches it (the BSR contact tolerance)


@dataclass(frozen=True)
class PhaseMeasures:
    """One phase: ``distance`` m (com x at its end − at its start), ``rotations`` (|net
    unwrapped turn of rod 0| / 360°), ``clearance`` m (max over its samples of the lowest
    endpoint's height) and ``flight`` m: the same from the phase's first sample on the ground
    (within ``GROUND`` m) on, 0 if none."""

    distance: float
    rotations: float
    clearance: float
    flight: float


def phase_measures(stored: CompositeMotion) -> list[PhaseMeasures]:
    """Each phase's measures, in phase order; a phase's samples run from its switch sample to
    the next phase's (the shared sample belongs to both, as the script's scores see it)."""
    ends = stored.motion.endpoints
    com = stored.motion.com
    rod = ends[:, 0, 1] - ends[:, 0, 0]
    angle = np.unwrap(arctan2_each(rod[:, 1], rod[:, 0]))
    lowest = ends[..., 1].min(axis=(1, 2))
    measures = []
    for k in range(int(stored.phase.max()) + 1):
        samples = np.flatnonzero(stored.phase == k)
        if samples.size == 0:
            continue
        first, last = samples[0], min(samples[-1] + 1, com.shape[0] - 1)
        span = slice(first, last + 1)
        grounded = np.flatnonzero(lowest[span] <= GROUND)
        after = lowest[first + grounded[0] : last + 1] if grounded.size else np.zeros(1)
        measures.append(
            PhaseMeasures(
                distance=float(com[last, 0] - com[first, 0]),
                rotations=float(abs(angle[last] - angle[first]) / (2.0 * np.pi)),
                clearance=float(lowest[span].max()),
                flight=float(after.max()),
            )
        )
    return measures
