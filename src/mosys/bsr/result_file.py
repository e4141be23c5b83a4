"""One BSR search end to end: spec and figure (2-D or 3-D) in, ``results/bsr/NAME/seedK.h5``
out; a 3-D search that continues another also takes that search's result files."""

from __future__ import annotations

import json
from pathlib import Path

from mosys.bsr.figure import bsr_figure, load_rod_figure
from mosys.bsr.figure3d import bsr_figure3d
from mosys.bsr.search import (
    SearchOutcome,
    SearchSetup,
    bind_search,
    run_search,
    search_memory_bytes,
    searched_variables,
)
from mosys.bsr.search3d import bind_search3d, chain_start, standing_height
from mosys.errors import InputError
from mosys.io.bsr_result import BsrResult, write_bsr_result
from mosys.limits import check_job
from mosys.parsing.bsr import BsrSpec, parse_bsr_spec
from mosys.parsing.tokens import SpecError, location


def motion_step_bytes(endpoints: int) -> int:
    """About what one recorded step of a BSR run takes, bytes: each endpoint's position (3
    float64, 3-D at most) in the kernel's record, the best run's copy and ``figure_motion``; the
    state and senses beside them."""
    return 8 * (3 * 3 * endpoints + 64)


def search_to_file(
    spec_path: str | Path,
    figures_dir: str | Path,
    seed: int,
    output: str | Path,
    generations: int | None = None,
    budget: str = "paper",
    threads: int | None = None,
    chain_results: list[str | Path] | None = None,
) -> SearchOutcome:
    """Parse the spec and its figure, run the search with ``seed`` (which must be one of the
    spec's seeds), write the result atomically. ``generations`` overrides the spec's G;
    ``budget`` names the config that chose it; ``threads``: numba threads for the population;
    ``chain_results``: the result files of the search a ``chain`` line continues."""
    spec = parse_bsr_spec(spec_path)
    if seed not in spec.seeds:  # the argument's mistake, or the spec's: say both
        seeds = ", ".join(map(str, spec.seeds))
        raise InputError(
            f"{spec.path}: --seed {seed} is not one of its seeds ({seeds}, line "
            f"{spec.tokens['seeds'].line}): give one of them, or add it there"
        )
    setup, extra = _bind(spec, figures_dir, generations, chain_results or [])
    figure = setup.figure
    simulate = spec.simulate_token
    check_job(
        location(spec.path, simulate),
        f"{spec.controllers:,} controllers of {spec.rules:,} rules, {spec.steps:,} steps a run",
        spec.steps,
        search_memory_bytes(setup, motion_step_bytes(len(figure.endpoint_names))),
    )
    import numba

    if threads:
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
            "compile_seconds": outcome.compile_seconds,
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
            "threads": numba.get_num_threads(),  # those that ran it (0 was written by hand)
            "searched_variables": searched_variables(setup),
            "min_com_height": float(outcome.com[:, 1].min()),
            **extra,
        },
        final_state=outcome.final_state,
        final_force=outcome.final_force,
    )
    write_bsr_result(output, result)
    return outcome


def _bind(
    spec: BsrSpec, figures_dir: str | Path, generations: int | None, chain_results: list
) -> tuple[SearchSetup, dict]:
    """The search set-up of a 2-D or 3-D figure (as its .fig says), and the root attrs only
    3-D results have."""
    if chain_results and not spec.chain:  # given to continue a search the spec does not
        raise InputError(
            f"{spec.path}: --chain given, but the spec has no 'chain' line (it starts at rest)"
        )
    parsed = load_rod_figure(figures_dir, spec.path, spec.tokens["figure"])
    if parsed.dimensions != 3:
        if spec.chain:
            raise SpecError.at(spec.path, spec.tokens["chain"], "a 3-D figure to continue")
        return bind_search(spec, bsr_figure(parsed), generations), {}
    figure = bsr_figure3d(parsed)
    chain = None
    if spec.chain:
        if not chain_results:
            raise SpecError.at(
                spec.path, spec.tokens["chain"], f"the result files of '{spec.chain}' (--chain)"
            )
        chain = chain_start(spec.chain, chain_results)
    setup = bind_search3d(spec, figure, generations, chain)
    standing = standing_height(figure)
    return setup, {
        "chain": spec.chain,
        "chain_seed": 0 if chain is None else chain.seed,
        "standing_com_height": standing,
    }
