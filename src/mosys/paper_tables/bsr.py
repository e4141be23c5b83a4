"""The BSR runs table: per search, how it ran (budget, evaluations, speed against the 1995
paper's figures) and what it found over its seeds (best and median fitness, the measured terms).

The helpers that read, group and summarise a search's seed files are shared with the 3-D runs
table (``mosys.paper_tables.bsr3d``)."""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from mosys.errors import InputError
from mosys.io.atomic import write_text_atomically
from mosys.io.bsr_result import BsrResult, read_bsr_result
from mosys.parsing.bsr import FITNESS_TERMS

PAPER_EVALUATIONS = 40_000
# §2.1.3: 40,000 sense-based evaluations took 3-6 minutes on a DEC 3000/400 AXP; footnote 6:
# good time-based controllers are found in "a few tens of seconds" on the same machine, by a
# serial search of no stated length, so that figure is compared with a whole search of ours.
PAPER_SECONDS = {"sense": (180.0, 360.0), "time": (20.0, 60.0)}
PAPER_FIGURE = {
    "sense": "3-6 min per 40,000 evaluations (DEC 3000/400)",
    "time": "a good controller in a few tens of seconds (DEC 3000/400)",
}


def group_by_search(results: Iterable[BsrResult]) -> dict[str, list[BsrResult]]:
    """The seed results grouped by their ``name`` attribute (the search), searches in the order
    first met and seeds in the order given."""
    by_search: dict[str, list[BsrResult]] = {}
    for result in results:
        by_search.setdefault(str(result.attrs["name"]), []).append(result)
    return by_search


def search_seconds(result: BsrResult) -> float:
    """A search's wall time without numba's compilation of kernels that missed its cache
    (``compile_seconds``; none recorded before 2026-12-05): a fresh install's first search
    spent most of its minute compiling, and its rate read 10 to 40 times too slow."""
    return float(result.attrs["wall_seconds"]) - float(result.attrs.get("compile_seconds", 0.0))


def median_ms_per_evaluation(results: Sequence[BsrResult]) -> float:
    """The median over a search's seeds of search time (``search_seconds``) per evaluation, ms
    (unrounded)."""
    evaluations = np.array([result.attrs["evaluations"] for result in results], np.int64)
    seconds = np.array([search_seconds(result) for result in results])
    return float(np.median(seconds / evaluations * 1000.0))


def setup_columns(results: Sequence[BsrResult]) -> dict[str, object]:
    """How a search was set up, from its first seed file: figure, controller kind, rules, T (s),
    dt (s), budget (the config's name) and generations."""
    first = results[0].attrs
    return {
        "figure": str(first["figure"]),
        "kind": str(first["controller_kind"]),
        "rules": int(first["rules"]),
        "T (s)": float(first["duration"]),
        "dt (s)": float(first["dt"]),
        "budget": str(first["budget"]),
        "generations": int(first["generations"]),
    }


def cost_columns(results: Sequence[BsrResult]) -> dict[str, object]:
    """What a search's seeds cost: their number, the median evaluations and wall time (s) per
    seed and the median ms per evaluation (``median_ms_per_evaluation``, rounded)."""
    evaluations = np.array([result.attrs["evaluations"] for result in results], np.int64)
    wall = np.array([result.attrs["wall_seconds"] for result in results])
    return {
        "seeds": len(results),
        "evaluations per seed": int(np.median(evaluations)),
        "wall per seed (s)": round(float(np.median(wall)), 2),
        "ms per evaluation": round(median_ms_per_evaluation(results), 3),
    }


def fitness_columns(results: Sequence[BsrResult]) -> dict[str, float]:
    """The best and the median over a search's seeds of their best fitness."""
    fitness = np.array([result.attrs["best_fitness"] for result in results])
    return {
        "best fitness": round(float(fitness.max()), 3),
        "median fitness": round(float(np.median(fitness)), 3),
    }


def write_table(frame: pd.DataFrame, caption: str, csv_path: str, md_path: str) -> None:
    """Write ``frame`` as CSV and as Markdown under ``caption`` (each file atomically)."""
    write_text_atomically(csv_path, frame.to_csv(index=False))
    write_text_atomically(md_path, caption + frame.to_markdown(index=False) + "\n")


TABLE_VERBS = {2: "bsr-table", 3: "bsr3d-table"}  # the runs table of each figure dimension


def check_dimensions(result: BsrResult, path: str | Path, dimensions: int) -> None:
    """InputError naming the file unless ``result`` is the search of a ``dimensions``-D figure,
    which ``TABLE_VERBS[dimensions]`` tabulates."""
    found = result.motion.dimensions
    if found != dimensions:
        other = f" ({TABLE_VERBS[found]} the {found}-D ones)" if found in TABLE_VERBS else ""
        raise InputError(
            f"{path}: a {found}-D search result; {TABLE_VERBS[dimensions]} tabulates "
            f"{dimensions}-D searches{other}"
        )


def read_table_result(
    path: str | Path, dimensions: int, attrs: Sequence[str], terms: Sequence[str]
) -> BsrResult:
    """Read one seed file for a runs table, checking that it is a ``dimensions``-D search's
    with the root ``attrs`` and fitness ``terms`` the table reads. Raises InputError naming the
    file otherwise (a file without one had the table stop with a KeyError traceback)."""
    result = read_bsr_result(path)  # InputError naming the file if it is not one
    absent = [key for key in attrs if key not in result.attrs]
    if absent:
        raise InputError(
            f"{path}: not a {dimensions}-D BSR result file: no root attribute {', '.join(absent)}"
        )
    check_dimensions(result, path, dimensions)
    try:
        found = result.fitness_terms
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: fitness_terms is not JSON: {error}") from None
    absent = [term for term in terms if term not in found]
    if absent:
        raise InputError(f"{path}: fitness_terms has no {', '.join(absent)}")
    return result


# the root attributes the 2-D table reads
PLANAR_ATTRS = (
    "name",
    "figure",
    "controller_kind",
    "rules",
    "duration",
    "dt",
    "budget",
    "generations",
    "evaluations",
    "wall_seconds",
    "best_fitness",
    "steps_per_second",
    "fitness_terms",
)


def read_planar_result(path: str | Path) -> BsrResult:
    """A 2-D search's result file, checked as ``read_table_result`` does."""
    return read_table_result(path, 2, PLANAR_ATTRS, FITNESS_TERMS)


def speed_up(ratio: float) -> str:
    """A speed-up factor as text: ``375x``; below 10 two significant digits, ``2.5x``, ``0.03x``
    (a reduced budget's slow run printed ``0x``)."""
    return f"{ratio:.0f}x" if ratio >= 10 else f"{ratio:.2g}x"


def runs_frame(result_paths: list[str | Path]) -> pd.DataFrame:
    """One row per search (the seed files grouped by their ``name`` attribute, in order)."""
    rows = []
    for name, results in group_by_search(map(read_planar_result, result_paths)).items():
        setup = setup_columns(results)
        kind = str(setup["kind"])
        seconds_40k = median_ms_per_evaluation(results) * PAPER_EVALUATIONS / 1000.0
        paper_low, paper_high = PAPER_SECONDS[kind]
        ours = seconds_40k  # the paper's sense-based figure is per 40,000 evaluations
        if kind == "time":  # its time-based one is per search: against a whole search of ours
            ours = float(np.median([search_seconds(result) for result in results]))
        steps_per_second = np.median([result.attrs["steps_per_second"] for result in results])
        row = {
            "search": name,
            **setup,
            **cost_columns(results),
            "steps per second": f"{steps_per_second:.3g}",
            "40k evaluations (s)": round(seconds_40k, 1),
            "paper": PAPER_FIGURE[kind],
            "speed-up vs paper": (
                f"{speed_up(paper_low / ours).removesuffix('x')}-{speed_up(paper_high / ours)}"
            ),
            **fitness_columns(results),
        }
        for term in FITNESS_TERMS:
            values = [result.fitness_terms[term] for result in results]
            row[f"median {term}"] = round(float(np.median(values)), 3)
        rows.append(row)
    return pd.DataFrame(rows)


def write_bsr_table(result_paths: list[str | Path], csv_path: str, md_path: str) -> pd.DataFrame:
    """Write the runs table as CSV and Markdown (each atomically)."""
    frame = runs_frame(result_paths)
    caption = (
        "BSR searches after Auslander et al. (1995), §2: one row per search spec over its seeds "
        "(each seed a separate job). budget: the config that set the generations (paper: the "
        "spec's own G; ci: a reduced one). ms per evaluation: wall time of the search (one "
        "thread unless the config gives more), numba's compilation of its kernels left out, "
        "over its evaluations, median over seeds; 40k "
        "evaluations: that rate times 40,000. speed-up: the paper's DEC 3000/400 figure over "
        "ours: for sense-based searches its 3-6 min per 40,000 evaluations over our 40k "
        "evaluations; for time-based ones, whose figure is a whole search's ('a few tens of "
        "seconds', footnote 6, no evaluation count), over our whole search, median over "
        "seeds (a search of the row's budget: under a reduced one, shorter than the paper's, "
        "so that ratio is larger than like for like). The "
        "terms are measured on each seed's best motion from the nominal start; medians over "
        "seeds. contact_distance counts endpoints within 1 mm of the floor at both ends of a "
        "step.\n\n"
    )
    write_table(frame, caption, csv_path, md_path)
    return frame
