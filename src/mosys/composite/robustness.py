"""How well a BSR controller holds up from starts it was not searched from (the 1995 paper's
enhanced controllers, §3): its fitness over many randomly perturbed start states.

A robust (perturbed) search and its plain twin are compared under the robust spec (its T,
fitness weights and fall endpoints: the conditions the robust controller is made for) on the
same starts, drawn with the robust spec's perturbation."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mosys.bsr.figure import load_bsr_figure
from mosys.bsr.search import SearchSetup, bind_search, nominal_run, record_run
from mosys.bsr.start import perturbed_state
from mosys.io.bsr_result import BsrController, read_bsr_result
from mosys.parsing.bsr import Perturbation, parse_bsr_spec


@dataclass(frozen=True)
class SeedFitness:
    """One seed's best controller: its fitness from the nominal start and from each perturbed
    start (starts,), and the budget and generations its search ran at."""

    seed: int
    budget: str
    generations: int
    nominal: float
    perturbed: np.ndarray


def bind_spec(spec_path: str | Path, figures_dir: str | Path) -> SearchSetup:
    """A search spec bound to its figure (its start pose, fall endpoints and weights)."""
    spec = parse_bsr_spec(spec_path)
    return bind_search(spec, load_bsr_figure(figures_dir, spec.path, spec.tokens["figure"]))


def perturbed_starts(
    setup: SearchSetup, perturbation: Perturbation, count: int, seed: int
) -> np.ndarray:
    """``count`` start states (count, S) around the setup's nominal pose, drawn as a perturbed
    search draws them, from a generator seeded with ``seed``."""
    rng = np.random.default_rng(seed)
    return np.stack(
        [
            perturbed_state(
                setup.figure, setup.root_angle, setup.joints, setup.x, perturbation, rng
            )
            for _ in range(count)
        ]
    )


def fitness_from_starts(
    setup: SearchSetup, controller: BsrController, starts: np.ndarray
) -> np.ndarray:
    """The controller's fitness (starts,) from each start (starts, S): the setup's T, dt,
    fall endpoints and weights."""
    spec = setup.spec
    return np.array(
        [
            record_run(
                setup.figure, controller, start, spec.steps, spec.dt, setup.fall_endpoints
            ).terms
            @ setup.weights
            for start in starts
        ]
    )


def seed_fitness(
    setup: SearchSetup, result_paths: list[str | Path], starts: np.ndarray
) -> list[SeedFitness]:
    """Each seed file's best controller under ``setup``: from its nominal start and from every
    start (starts, S)."""
    rows = []
    for path in result_paths:
        result = read_bsr_result(path)
        rows.append(
            SeedFitness(
                seed=int(result.attrs["seed"]),
                budget=str(result.attrs["budget"]),
                generations=int(result.attrs["generations"]),
                nominal=float(nominal_run(setup, result.controller).terms @ setup.weights),
                perturbed=fitness_from_starts(setup, result.controller, starts),
            )
        )
    return rows
