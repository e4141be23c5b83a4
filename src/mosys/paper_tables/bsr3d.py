"""The 3-D BSR runs table (the 1995 paper's §4): per search (Cujo bounding; Rex walking, turning
and walking again, each continuing the last; Rex and Bob walking sense-based, Bob over several
seeds as in Figure 8), how it ran (budget, evaluations, ms per 1,000 simulator steps against the
paper's 0.3 s per 1,000-step evaluation of Rex) and what it found (best and median fitness, the
measured terms of the best seed).

Reads the 3-D search results of DESIGN.md (``results/bsr/NAME/seedK.h5``, ``best/figure_motion``
3-D) with ``read_bsr_result``; the reading, grouping, cost and fitness columns are shared with
the 2-D table (``mosys.paper_tables.bsr``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from mosys.errors import InputError
from mosys.io.bsr_result import BsrResult
from mosys.paper_tables.bsr import (
    cost_columns,
    fitness_columns,
    group_by_search,
    median_ms_per_evaluation,
    read_table_result,
    setup_columns,
    speed_up,
    write_table,
)

# §4.1: "One evaluation of a motion controller for Rex requires 1,000 time steps of simulation,
# and about 0.3 seconds of elapsed time on a Digital 3000/400 AXP workstation. An acceptable
# controller had therefore been found in just under five hours", after "rapid progress ...
# through the first 50,000 evaluations". Its other 3-D timings are not figures: §5's "can still
# take hours", and §4.2's sense-based controllers "took longer to find" (Figure 7).
PAPER_MS_PER_1000_STEPS = 300.0
PAPER_FIGURE = "Rex: 300 ms per 1,000 steps (DEC 3000/400)"
SPEED_UP = "speed-up vs paper (300 ms / ours)"

# The root attributes the table reads, and those every seed of one search must share (one row
# shows them once).
REQUIRED_ATTRS = (
    "name",
    "figure",
    "controller_kind",
    "seed",
    "evaluations",
    "duration",
    "dt",
    "best_fitness",
    "fitness_terms",
    "wall_seconds",
    "chain",
    "chain_seed",
    "budget",
    "generations",
    "threads",
    "rules",
    "steps",
    "searched_variables",
    "min_com_height",
    "standing_com_height",
)
SHARED_ATTRS = (
    "figure",
    "controller_kind",
    "chain",
    "chain_seed",
    "rules",
    "searched_variables",
    "duration",
    "dt",
    "steps",
    "budget",
    "generations",
    "threads",
)
REQUIRED_TERMS = ("distance", "sideways", "heading_change", "foot_steps")

COLUMNS = (
    "search",
    "figure",
    "kind",
    "chain",
    "rules",
    "searched variables",
    "T (s)",
    "dt (s)",
    "steps per evaluation",
    "budget",
    "generations",
    "threads",
    "seeds",
    "evaluations per seed",
    "wall per seed (s)",
    "ms per evaluation",
    "ms per 1,000 steps",
    "paper",
    SPEED_UP,
    "best fitness",
    "median fitness",
    "best seed",
    "distance (m)",
    "sideways (m)",
    "heading change (deg)",
    "foot steps",
    "lowest com / standing com",
)


def read_3d_result(path: str | Path) -> BsrResult:
    """Read one seed file of a 3-D search, checking that it is one (``read_table_result``)."""
    return read_table_result(path, 3, REQUIRED_ATTRS, REQUIRED_TERMS)


def _check_seeds_agree(name: str, results: Sequence[BsrResult]) -> None:
    """Raise InputError if the seed files of search ``name`` differ in how the search was set up
    (``SHARED_ATTRS``): its row would show one seed's set-up for all."""
    for key in SHARED_ATTRS:
        values = {str(result.attrs[key]) for result in results}
        if len(values) > 1:
            by_seed = ", ".join(
                f"seed {int(result.attrs['seed'])}: {result.attrs[key]!s}" for result in results
            )
            raise InputError(f"search {name!r}: its seed files differ in {key} ({by_seed})")


def best_seed(results: Sequence[BsrResult]) -> BsrResult:
    """The seed with the highest ``best_fitness``, ties to the lowest seed (as the plots choose,
    and as a chained search picks the seed it continues)."""
    return min(
        results,
        key=lambda result: (-float(result.attrs["best_fitness"]), int(result.attrs["seed"])),
    )


def chain_text(attrs: dict) -> str:
    """What a search continues: ``rex_walk (seed 2)`` (the search and the seed whose final state
    it starts from), ``""`` for a search from the figure's nominal start."""
    chain = str(attrs["chain"])
    return f"{chain} (seed {int(attrs['chain_seed'])})" if chain else ""


def runs3d_frame(result_paths: Sequence[str | Path]) -> pd.DataFrame:
    """One row per 3-D search (the seed files grouped by their ``name`` attribute, searches in
    the order first met), columns ``COLUMNS``. Raises InputError for no files, a file that is
    not a 3-D search result, or seeds of one search set up differently."""
    if not result_paths:
        raise InputError("no 3-D BSR result files given")
    rows = []
    for name, results in group_by_search(map(read_3d_result, result_paths)).items():
        _check_seeds_agree(name, results)
        first = results[0].attrs
        steps = int(first["steps"])
        ms_per_1000_steps = median_ms_per_evaluation(results) * 1000.0 / steps
        best = best_seed(results)
        terms = best.fitness_terms
        lowest = float(best.attrs["min_com_height"]) / float(best.attrs["standing_com_height"])
        rows.append(
            {
                "search": name,
                **setup_columns(results),
                "chain": chain_text(first),
                "searched variables": int(first["searched_variables"]),
                "steps per evaluation": steps,
                "threads": int(first["threads"]),
                **cost_columns(results),
                "ms per 1,000 steps": round(ms_per_1000_steps, 3),
                "paper": PAPER_FIGURE,
                SPEED_UP: speed_up(PAPER_MS_PER_1000_STEPS / ms_per_1000_steps),
                **fitness_columns(results),
                "best seed": int(best.attrs["seed"]),
                "distance (m)": round(float(terms["distance"]), 3),
                "sideways (m)": round(float(terms["sideways"]), 3),
                "heading change (deg)": round(float(terms["heading_change"]), 1),
                "foot steps": int(terms["foot_steps"]),
                "lowest com / standing com": round(lowest, 2),
            }
        )
    return pd.DataFrame(rows, columns=list(COLUMNS))


def budget_sentence(frame: pd.DataFrame) -> str:
    """Which budget (the config that set the generations) made the rows: ``All rows: the ci
    budget.`` or, mixed, ``Budget ci: a, b; paper: c.``"""
    searches_by_budget: dict[str, list[str]] = {}
    for search, budget in zip(frame["search"], frame["budget"], strict=True):
        searches_by_budget.setdefault(str(budget), []).append(str(search))
    if len(searches_by_budget) == 1:
        return f"All rows: the {next(iter(searches_by_budget))} budget."
    parts = [f"{budget}: {', '.join(names)}" for budget, names in searches_by_budget.items()]
    return f"Budget {'; '.join(parts)}."


def write_bsr3d_table(
    result_paths: Sequence[str | Path], csv_path: str, md_path: str
) -> pd.DataFrame:
    """Write the 3-D runs table as CSV and Markdown (each atomically); returns the frame."""
    frame = runs3d_frame(result_paths)
    caption = (
        "3-D BSR searches after Auslander et al. (1995), §4: one row per search over its seeds "
        "(each seed a separate job). chain: the search (and its best seed) whose final state "
        "this one starts from; blank: the figure's nominal start. searched variables: the free "
        "variables the search varies. steps per evaluation: simulator steps of T/dt. budget: "
        "the config that set the generations (paper: each spec's own G, for the shipped specs "
        "6,000 generations of 10, about the paper's Rex: just under five hours at 0.3 s an "
        "evaluation is 60,000 evaluations; ci: a reduced one; custom: a G given by hand). "
        f"{budget_sentence(frame)} threads: those a seed's search ran on. wall per seed: median "
        "over seeds, numba's compilation included (a fresh install's first 3-D search spends "
        "about a minute compiling); ms per evaluation: wall time of a seed's search, that "
        "compilation left out, over its evaluations, "
        "median over seeds; ms per 1,000 steps: that per 1,000 simulator steps, beside the "
        "paper's 300 ms for one 1,000-step evaluation of Rex (15 rods) on one DEC 3000/400 AXP "
        "(a scale only for the other figures); speed-up: 300 ms / ours. The paper's Rex walk "
        "made rapid progress over its first 50,000 evaluations and had an acceptable controller "
        "in just under five hours (compare evaluations and wall per seed). best and median "
        "fitness: over the seeds' best fitness. The terms are measured on the best seed's best "
        "motion: distance along and sideways across the heading at t = 0 (m), heading change "
        "(deg, signed), foot steps (alternating foot touch-downs); lowest com / standing com: "
        "the lowest height of the centre of mass over the motion over its height at t = 0.\n\n"
    )
    write_table(frame, caption, csv_path, md_path)
    return frame
