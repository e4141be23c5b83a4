"""One BSR search end to end: spec and figure in, ``results/bsr/NAME/seedK.h5`` out."""

from __future__ import annotations

import json
import os
from pathlib import Path

from mosys.bsr.figure import load_bsr_figure
from mosys.bsr.search import SearchOutcome, bind_search, run_search
from mosys.io.bsr_result import BsrResult, write_bsr_result
from mosys.parsing.bsr import parse_bsr_spec
from mosys.parsing.tokens import SpecError


def search_to_file(
    spec_path: str | Path,
    figures_dir: str | Path,
    seed: int,
    output: str | Path,
    generations: int | None = None,
    budget: str = "paper",
    threads: int | None = None,
) -> SearchOutcome:
    """Parse the spec and its figure, run the search with ``seed`` (which must be one of the
    spec's seeds), write the result atomically. ``generations`` overrides the spec's G;
    ``budget`` names the config that chose it; ``threads``: numba threads for the population."""
    spec = parse_bsr_spec(spec_path)
    if seed not in spec.seeds:
        raise SpecError(
            spec.path, 1, 1, f"seed {seed} among the spec's seeds {list(spec.seeds)}", None
        )
    figure = load_bsr_figure(figures_dir, spec.path, spec.tokens["figure"])
    setup = bind_search(spec, figure, generations)
    if threads:
        import numba

        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    outcome = run_search(setup, seed, label=f"{spec.name} seed {seed}")
    result = BsrResult(
        evaluations=outcome.evaluations,
        best_fitness=outcome.best_fitness,
        controller=outcome.controller,
        motion=figure.motion(outcome.rod_ends, outcome.com, spec.dt),
        active_rule=outcome.active_rule,
        joint_names=figure.joint_names,
        sense_names=figure.sense_names if spec.kind == "sense" else (),
        attrs={
            "figure": spec.figure,
            "controller_kind": spec.kind,
            "seed": seed,
            "evaluations": int(outcome.evaluations[-1]),
            "duration": spec.duration,
            "dt": spec.dt,
            "best_fitness": outcome.fitness,
            "nominal_fitness": outcome.nominal_fitness,
            "fitness_weights": json.dumps(spec.weights),
            "fitness_terms": outcome.terms_json(),
            "spec_sha256": spec.spec_sha256,
            "wall_seconds": outcome.wall_seconds,
            "name": spec.name,
            "budget": budget,
            "generations": setup.generations,
            "controllers": spec.controllers,
            "reseed": spec.reseed,
            "rules": spec.rules,
            "period": setup.period if spec.kind == "time" else float("nan"),
            "tau_min": setup.tau_range[0],
            "steps": spec.steps,
            "perturbed": spec.perturbation.any,
            "steps_per_second": outcome.steps_per_second,
            "threads": threads or int(os.environ.get("NUMBA_NUM_THREADS", "0") or 0),
        },
    )
    write_bsr_result(output, result)
    return outcome
