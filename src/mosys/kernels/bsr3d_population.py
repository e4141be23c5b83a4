"""A population of 3-D BSR controllers evaluated at once: ``run_population`` runs them in
groups of up to four in lockstep (``bsr3d_controller.run_lockstep``), the groups in parallel.
Every controller's numbers are those of its own ``run_controller``, bit for bit, whichever group
and lane it ran in (tested), so a search's results do not depend on the population's size or
the number of threads, and the best controller's motion, replayed on its own, is the one the
search scored.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

from mosys.kernels.bsr3d_controller import run_lockstep
from mosys.kernels.bsr_controller import RunRecord
from mosys.kernels.lanes import LANES


@njit(cache=True)
def lockstep_groups(population, threads):
    """The groups (G, LANES) int64 of controllers 0..population - 1 that ``run_population``
    runs in lockstep (-1: an empty lane): G a multiple of ``threads``, as few as hold them, and
    each thread's G / threads consecutive groups (numba's parallel loop gives each thread a
    block of consecutive iterations) holding as even a share of the controllers as can be, so
    that every thread has about the same number of lanes to run."""
    full = (population + LANES - 1) // LANES  # the fewest groups that hold them
    per_thread = max(1, (full + threads - 1) // threads)
    groups = np.full((per_thread * threads, LANES), -1, np.int64)
    controller = 0
    for thread in range(threads):
        share = population // threads + (1 if thread < population % threads else 0)
        for k in range(per_thread):
            size = share // per_thread + (1 if k < share % per_thread else 0)
            for lane in range(size):
                groups[thread * per_thread + k, lane] = controller
                controller += 1
    return groups


def run_population(
    figure,
    controllers,
    task,
    starts: np.ndarray,
    steps: int,
    dt: float,
    senses_out: np.ndarray,
    rule_out: np.ndarray,
    terms_out: np.ndarray,
    taken_out: np.ndarray,
    final_out: np.ndarray,
) -> None:
    """``run_controller`` for C controllers at once: controllers a ControllerArrays whose arrays
    have a leading axis C, starts (C, S); fills senses_out (C, steps + 1, V), rule_out (C, steps
    + 1), terms_out (C, TERM_COUNT), taken_out (C,) int64 what each run returned (steps, or
    ``blown_up(n)`` < 0: its terms are NaN) and final_out (C, S) each run's last state (the
    unsound one where it stopped). In groups of up to four in lockstep (``lockstep_groups``),
    the groups in parallel on numba's threads; each run's numbers are its own
    ``run_controller``'s."""
    population = starts.shape[0]
    n_rods = figure.parent.shape[0]
    n_ends = figure.endpoints.shape[0]
    records = RunRecord(
        senses_out,
        rule_out,
        terms_out,
        np.empty((population, 0, n_rods, 2, 3)),
        np.empty((population, 0, 3)),
        final_out,
        np.empty((population, n_ends)),
    )
    groups = lockstep_groups(population, numba.get_num_threads())
    forces = np.zeros((population, n_ends))
    _run_groups(figure, controllers, task, groups, starts, forces, steps, dt, records, taken_out)


@njit(cache=True, parallel=True)
def _run_groups(figure, controllers, task, groups, starts, start_forces, steps, dt, records, taken):
    """``run_lockstep`` for each group (G, LANES) of controllers, in parallel, from rule 0."""
    for g in prange(groups.shape[0]):
        run_lockstep(
            figure,
            controllers,
            task,
            groups[g],
            starts,
            start_forces,
            np.bool_(False),  # a bool, not the literal False: the run_lockstep that
            steps,  # run_controller calls (a literal is a signature of its own)
            dt,
            records,
            taken,
        )
