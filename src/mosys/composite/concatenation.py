"""Concatenated controllers (the 1995 paper's §3): a list of (controller, duration in simulator
ticks) run one after another from one start state. At a switch the figure's state and its
senses (the contact forces of the last step) carry over, and a sense-based controller starts
with the rule that those senses select."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mosys.bsr.figure import BsrFigure
from mosys.bsr.search import record_run
from mosys.io.bsr_result import BsrController


@dataclass(frozen=True)
class ConcatenatedMotion:
    """The whole motion, one sample per tick plus the start: rod_ends (M + 1, N, 2, 2) m, com
    (M + 1, 2) m, active_rule (M + 1,) of the phase's controller, phase (M + 1,) the phase of
    each sample (a switch sample belongs to the phase it starts), and starts (P + 1,): the sample
    where each phase starts, then M."""

    rod_ends: np.ndarray
    com: np.ndarray
    active_rule: np.ndarray
    phase: np.ndarray
    starts: np.ndarray

    def phase_samples(self, k: int) -> slice:
        """Phase k's samples, from its first (the previous phase's last) to its last."""
        return slice(int(self.starts[k]), int(self.starts[k + 1]) + 1)


def run_concatenation(
    figure: BsrFigure,
    controllers: Sequence[BsrController],
    ticks: Sequence[int],
    start: np.ndarray,
    dt: float,
) -> ConcatenatedMotion:
    """Run controllers[k] for ticks[k] steps of dt s, one after another, from the state start
    (S,). A phase of 0 ticks is skipped."""
    state = np.asarray(start, np.float64)
    force = None
    ends, coms, rules, phases = [], [], [], []
    starts = [0]
    for k, (controller, count) in enumerate(zip(controllers, ticks, strict=True)):
        if count > 0:
            run = record_run(
                figure, controller, state, int(count), dt, start_force=force, carry_over=k > 0
            )
            first = 0 if not ends else 1  # the switch sample is the last phase's end...
            if first:
                phases[-1][-1] = k  # ...and belongs to the phase it starts
            ends.append(run.rod_ends[first:])
            coms.append(run.com[first:])
            rules.append(run.active_rule[first:])
            phases.append(np.full(run.com.shape[0] - first, k))
            state, force = run.final_state, run.final_force
        starts.append(starts[-1] + int(max(count, 0)))
    return ConcatenatedMotion(
        rod_ends=np.concatenate(ends),
        com=np.concatenate(coms),
        active_rule=np.concatenate(rules),
        phase=np.concatenate(phases),
        starts=np.array(starts, np.int64),
    )
