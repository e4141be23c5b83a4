"""BSR 3-D benchmarks (the 1995 paper's §4): one 1,000-step evaluation of Rex on one core (the
paper: 300 ms on a DEC 3000/400 AXP; target <= 1 ms), and the same per 1,000 steps for Bob
(sense-based, 600 steps) and Cujo (time-based, 500 steps); Rex's population on 1 and 2 threads
(C = 10 and 40: the speed-up, and whether the results are bit-identical); a whole search of Rex
(rex_walk.bsr) on 1 and 2 threads (whether the learning curves are identical); and the first
search of a fresh install (cold numba cache: JIT compilation included).

    python benchmarks/bsr3d.py            # full: G = 300, the cold start
    python benchmarks/bsr3d.py --smoke    # CI: the same code paths, G = 5, no cold start, the
                                          # install's numba cache

Writes results/benchmarks/bsr3d.{csv,md} (bsr3d_smoke.* with --smoke) and prints them. The
populations run in this process (``run_population`` called once first, untimed): C random
controllers of the spec's figure, rules, period, steps, dt and task (as ``bind_search3d`` binds
them), from its start pose, targets uniform in the joints' ranges, tau uniform in [0.05, 0.25]
s, time segments' weights uniform in [0.2, 1] (as the search draws them), sense boxes' centres
uniform in [-0.5, 1.5] and sides log-uniform in [0.4, 4]. The searches run ``mosys
bsr-search`` in a new process (bsr.py's ``search``), timed by the search's own wall clock (the
search alone) and by the process. This process and every search but the cold one share one
numba cache, filled first. The machine may be shared: each speed is the best (minimum) of the
repeats, beside their median.

Columns: ``wall_s_best``/``wall_s_median`` one population (``run_population``) or one search
(its own clock, JIT of a cold search included); ``process_s_*`` the search's whole process;
``ms_per_evaluation`` the best wall over the evaluations, ``ms_per_1000_steps`` that per 1,000
simulated steps (and the median's); ``paper_300ms_over_ours`` 300 ms over that; ``speed_up``
the 1-thread best over the 2-thread best; ``bit_identical`` whether the two thread counts (and,
for searches, every repeat) give the same terms and rules, or learning curves and best fitness.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from bsr import search
from generation import numba_cache, write_results

from mosys.io.bsr_result import read_bsr_result

if TYPE_CHECKING:
    from mosys.bsr.search import SearchSetup
    from mosys.kernels.bsr_controller import ControllerArrays

ROOT = Path(__file__).resolve().parents[1]
PAPER_MS = 300.0  # Rex, one 1,000-step evaluation, DEC 3000/400 AXP (the 1995 paper)
TARGET_MS = 1.0  # per 1,000 steps on one core
TAU_RANGE = (0.05, 0.25)  # s
FIGURES = (  # spec, what it runs
    ("rex_walk.bsr", "Rex, time-based"),
    ("bob_walk.bsr", "Bob, sense-based"),
    ("cujo_bound.bsr", "Cujo, time-based"),
)
SEARCH_SPEC = "rex_walk.bsr"


def bind(spec_name: str) -> SearchSetup:
    """The search set-up of specs/bsr/``spec_name`` (a 3-D figure), at the spec's G."""
    from mosys.bsr.figure3d import load_bsr_figure3d
    from mosys.bsr.search3d import bind_search3d
    from mosys.parsing.bsr import parse_bsr_spec

    spec = parse_bsr_spec(ROOT / "specs/bsr" / spec_name)
    figure = load_bsr_figure3d(ROOT / "specs/figures", spec.path, spec.tokens["figure"])
    return bind_search3d(spec, figure)


def draw_population(
    setup: SearchSetup, controllers: int, rng: np.random.Generator
) -> ControllerArrays:
    """``controllers`` random controllers of the set-up's kind and rules (the module's
    docstring gives the distributions), arrays with a leading axis C."""
    from mosys.bsr.search import SEGMENT_WEIGHT_MAX, SEGMENT_WEIGHT_MIN
    from mosys.kernels.bsr_controller import (
        CENTER_MAX,
        CENTER_MIN,
        SIDE_MAX,
        SIDE_MIN,
        ControllerArrays,
    )

    spec, figure = setup.spec, setup.figure
    c, r, j = controllers, spec.rules, len(figure.joint_names)
    v = len(figure.sense_names) if spec.kind == "sense" else 0
    weights = rng.uniform(SEGMENT_WEIGHT_MIN, SEGMENT_WEIGHT_MAX, (c, r))
    segment_end = np.cumsum(weights / weights.sum(axis=1, keepdims=True), axis=1) * setup.period
    segment_end[:, -1] = setup.period
    return ControllerArrays(
        spec.kind == "time",
        rng.uniform(figure.joint_min, figure.joint_max, (c, r, j)),
        rng.uniform(*TAU_RANGE, (c, r)),
        rng.uniform(CENTER_MIN, CENTER_MAX, (c, r, v)),
        np.exp(rng.uniform(np.log(SIDE_MIN), np.log(SIDE_MAX), (c, r, v))),
        segment_end,
        setup.period,
    )


def time_population(
    setup: SearchSetup, population: ControllerArrays, threads: int, repeats: int
) -> tuple[list[float], np.ndarray, np.ndarray]:
    """Evaluate the population on ``threads`` numba threads once untimed, then ``repeats``
    times; returns the repeats' wall seconds, and the last run's terms (C, TERM_COUNT) and
    rules (C, steps + 1)."""
    import numba

    from mosys.kernels.bsr3d_controller import TERM_COUNT
    from mosys.kernels.bsr3d_population import run_population

    numba.set_num_threads(threads)
    spec, simulation = setup.spec, setup.simulation
    c, v = population.center.shape[0], population.center.shape[2]
    starts = np.repeat(simulation.start[None, :], c, axis=0)
    seconds = []
    for _ in range(repeats + 1):
        senses = np.zeros((c, spec.steps + 1, v))
        rules = np.zeros((c, spec.steps + 1), np.int64)
        terms = np.zeros((c, TERM_COUNT))
        taken = np.zeros(c, np.int64)  # each run's steps (< 0: where its state blew up)
        final = np.empty_like(starts)
        started = time.perf_counter()
        run_population(
            setup.figure.arrays,
            population,
            simulation.task,
            starts,
            spec.steps,
            spec.dt,
            senses,
            rules,
            terms,
            taken,
            final,
        )
        seconds.append(time.perf_counter() - started)
        assert (taken == spec.steps).all(), "a benchmark run blew up"
    return seconds[1:], terms, rules


def timing_row(case: str, threads: int, evaluations: int, steps: int, seconds: list) -> dict:
    """A table row: the wall seconds' best and median, and the best per 1,000 steps against
    the paper and the target."""
    best = min(seconds)
    median = statistics.median(seconds)
    per_thousand = 1000 * best / evaluations * 1000 / steps
    return {
        "case": case,
        "threads": threads,
        "evaluations": evaluations,
        "repeats": len(seconds),
        "wall_s_best": round(best, 4),
        "wall_s_median": round(median, 4),
        "ms_per_evaluation": round(1000 * best / evaluations, 3),
        "ms_per_1000_steps": round(per_thousand, 3),
        "ms_per_1000_steps_median": round(1000 * median / evaluations * 1000 / steps, 3),
        "paper_300ms_over_ours": round(PAPER_MS / per_thousand),
        "target_1ms": "met" if per_thousand <= TARGET_MS else "not met",
    }


def yes_no(same: bool) -> str:
    return "yes" if same else "no"


def population_rows(repeats: int) -> list[dict]:
    """One evaluation of each figure on one thread (wall over C = 10), and Rex's population (C
    = 10, the same controllers, and 40: those and 30 more) on 1 and 2 threads."""
    rows = []
    for spec_name, label in FIGURES:
        setup = bind(spec_name)
        spec = setup.spec
        rex = spec_name == SEARCH_SPEC
        drawn = draw_population(setup, 40 if rex else 10, np.random.default_rng(1))
        for controllers in (10, 40) if rex else (10,):
            population = drawn._replace(
                **{
                    name: value[:controllers]
                    for name, value in drawn._asdict().items()
                    if isinstance(value, np.ndarray)
                }
            )
            one, terms, rules = time_population(setup, population, 1, repeats)
            case = f"{label} (R = {spec.rules}), {spec.steps} steps, C = {controllers}"
            rows.append(timing_row(case, 1, controllers, spec.steps, one))
            if rex:
                two, terms_two, rules_two = time_population(setup, population, 2, repeats)
                same = np.array_equal(terms, terms_two) and np.array_equal(rules, rules_two)
                rows.append(
                    timing_row(case, 2, controllers, spec.steps, two)
                    | {"speed_up": round(min(one) / min(two), 2), "bit_identical": yes_no(same)}
                )
    return rows


def same_curves(paths: list[Path]) -> bool:
    """Whether every result file has the first's learning curve and best fitness."""
    results = [read_bsr_result(path) for path in paths]
    first = results[0]
    return all(
        np.array_equal(result.evaluations, first.evaluations)
        and np.array_equal(result.best_fitness, first.best_fitness)
        and result.attrs["best_fitness"] == first.attrs["best_fitness"]
        for result in results
    )


def search_rows(generations: int, repeats: int, cache: Path | None, tmp: Path) -> list[dict]:
    """The whole search of SEARCH_SPEC on 1 and 2 threads, ``repeats`` times each (the thread
    counts alternating, so that a change of the machine's load falls on both)."""
    search(SEARCH_SPEC, 2, 1, cache, tmp / "fill.h5")  # fill the cache
    runs: dict[int, list[dict]] = {1: [], 2: []}
    paths = []
    for repeat in range(repeats):
        for threads, done in runs.items():
            paths.append(tmp / f"search_{threads}_threads_{repeat}.h5")
            done.append(search(SEARCH_SPEC, generations, threads, cache, paths[-1]))
    same = same_curves(paths)
    steps = int(read_bsr_result(paths[0]).attrs["steps"])
    rows = []
    for threads, done in runs.items():
        seconds = [run["search_s"] for run in done]
        process = [run["process_s"] for run in done]
        case = f"{SEARCH_SPEC}: whole search, {done[0]['kind']}-based, C = 10, G = {generations}"
        row = timing_row(case, threads, done[0]["evaluations"], steps, seconds) | {
            "process_s_best": round(min(process), 2),
            "process_s_median": round(statistics.median(process), 2),
        }
        if threads == 2:
            best_one = min(run["search_s"] for run in runs[1])
            row |= {"speed_up": round(best_one / min(seconds), 2), "bit_identical": yes_no(same)}
        rows.append(row)
    return rows


def cold_row(repeats: int, tmp: Path) -> dict:
    """The first search of a fresh install (an empty numba cache each repeat), G = 5."""
    runs = [
        search(SEARCH_SPEC, 5, 1, tmp / f"cold_cache_{repeat}", tmp / f"cold_{repeat}.h5")
        for repeat in range(repeats)
    ]
    seconds = [run["search_s"] for run in runs]
    process = [run["process_s"] for run in runs]
    return {
        "case": f"{SEARCH_SPEC}: first search of a fresh install (cold numba cache), G = 5",
        "threads": 1,
        "evaluations": runs[0]["evaluations"],
        "repeats": repeats,
        "wall_s_best": round(min(seconds), 1),
        "wall_s_median": round(statistics.median(seconds), 1),
        "process_s_best": round(min(process), 1),
        "process_s_median": round(statistics.median(process), 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny budget, for CI")
    args = parser.parse_args()
    population_repeats, search_repeats = (2, 1) if args.smoke else (7, 3)
    generations = 5 if args.smoke else 300
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        warm = numba_cache(tmp, args.smoke)
        if warm is not None:
            # numba reads it when first imported (the kernels are imported in the functions
            # above), so this process fills the cache the searches use: the kernels compile once
            os.environ["NUMBA_CACHE_DIR"] = str(warm)
        rows = population_rows(population_repeats)
        rows += search_rows(generations, search_repeats, warm, tmp)
        if args.smoke:
            rows.append(
                {
                    "case": f"{SEARCH_SPEC}: first search of a fresh install: skipped with "
                    "--smoke (JIT of the 3-D kernels takes about a minute cold)"
                }
            )
        else:
            rows.append(cold_row(2, tmp))
    write_results(pd.DataFrame(rows), "bsr3d", args.smoke)


if __name__ == "__main__":
    main()
