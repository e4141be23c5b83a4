"""A BSR controller's parameters as arrays (what the kernels read and the result file stores).

A **sense-based** controller (the 1995 paper's §2.1.2) has R rules, each a stimulus
hyper-rectangle over the V normalised sense variables, given by its ``center`` (mu) and ``side``
(2/lambda) per variable, and a response: a target pose (one angle per joint) and a time constant.
A **time-based** controller (§2.3) has R rules, each active for its ``segment`` of the period
``t_per``, one after another, the sequence repeating to fill the run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Table 2 of the paper: the hyper-rectangle's side 2/lambda lies in [SIDE_MIN, SIDE_MAX], so
# lambda_min = 2 / SIDE_MAX (the rule weights of kernels.bsr_run); centres are drawn in
# [CENTER_MIN, CENTER_MAX].
SIDE_MIN = 0.4
SIDE_MAX = 4.0
CENTER_MIN = -0.5
CENTER_MAX = 1.5


@dataclass(frozen=True)
class BsrController:
    """R rules. ``target``: (R, J) joint angles, rad; ``tau``: (R,) time constants, s.
    Sense-based: ``center`` and ``side``: (R, V), in normalised sense units; ``segment`` is
    empty. Time-based: ``segment``: (R,) seconds, summing to ``period`` (s); ``center`` and
    ``side`` are (R, 0)."""

    kind: str
    target: np.ndarray
    tau: np.ndarray
    center: np.ndarray
    side: np.ndarray
    segment: np.ndarray
    period: float

    @property
    def rules(self) -> int:
        return int(self.tau.shape[0])

    def copy(self) -> BsrController:
        return BsrController(
            self.kind,
            self.target.copy(),
            self.tau.copy(),
            self.center.copy(),
            self.side.copy(),
            self.segment.copy(),
            self.period,
        )
