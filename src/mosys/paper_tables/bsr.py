"""The BSR runs table: per search, how it ran (budget, evaluations, speed against the 1995
paper's figures) and what it found over its seeds (best and median fitness, the measured terms)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
import pandas as pd

from mosys.io.atomic import write_text_atomically
from mosys.io.bsr_result import read_bsr_result
from mosys.parsing.bsr import FITNESS_TERMS

PAPER_EVALUATIONS = 40_000
# §2.1.3: 40,000 sense-based evaluations took 3-6 minutes on a DEC 3000/400 AXP; footnote 6:
# good time-based controllers in "a few tens of seconds" on the same machine.
PAPER_SECONDS = {"sense": (180.0, 360.0), "time": (20.0, 60.0)}
PAPER_FIGURE = {
    "sense": "3-6 min per 40,000 evaluations (DEC 3000/400)",
    "time": "tens of seconds (DEC 3000/400)",
}


def runs_frame(result_paths: list[str | Path]) -> pd.DataFrame:
    """One row per search (the seed files grouped by their ``name`` attribute, in order)."""
    by_search: dict[str, list] = defaultdict(list)
    for path in result_paths:
        result = read_bsr_result(path)
        by_search[str(result.attrs["name"])].append(result)
    rows = []
    for name, results in by_search.items():
        attrs = [result.attrs for result in results]
        first = attrs[0]
        kind = str(first["controller_kind"])
        evaluations = np.array([a["evaluations"] for a in attrs], np.int64)
        wall = np.array([a["wall_seconds"] for a in attrs])
        fitness = np.array([a["best_fitness"] for a in attrs])
        ms_per_evaluation = float(np.median(wall / evaluations * 1000.0))
        seconds_40k = ms_per_evaluation * PAPER_EVALUATIONS / 1000.0
        paper_low, paper_high = PAPER_SECONDS[kind]
        row = {
            "search": name,
            "figure": str(first["figure"]),
            "kind": kind,
            "rules": int(first["rules"]),
            "T (s)": float(first["duration"]),
            "dt (s)": float(first["dt"]),
            "budget": str(first["budget"]),
            "generations": int(first["generations"]),
            "seeds": len(results),
            "evaluations per seed": int(np.median(evaluations)),
            "wall per seed (s)": round(float(np.median(wall)), 2),
            "ms per evaluation": round(ms_per_evaluation, 3),
            "steps per second": f"{np.median([a['steps_per_second'] for a in attrs]):.3g}",
            "40k evaluations (s)": round(seconds_40k, 1),
            "paper": PAPER_FIGURE[kind],
            "speed-up vs paper": f"{paper_low / seconds_40k:.0f}-{paper_high / seconds_40k:.0f}x",
            "best fitness": round(float(fitness.max()), 3),
            "median fitness": round(float(np.median(fitness)), 3),
        }
        for term in FITNESS_TERMS:
            values = [result.fitness_terms[term] for result in results]
            row[f"median {term}"] = round(float(np.median(values)), 3)
        rows.append(row)
    return pd.DataFrame(rows)


def write_bsr_table(result_paths: list[str | Path], csv_path: str, md_path: str) -> pd.DataFrame:
    """Write the runs table as CSV and Markdown (each atomically)."""
    frame = runs_frame(result_paths)
    write_text_atomically(csv_path, frame.to_csv(index=False))
    caption = (
        "BSR searches after Auslander et al. (1995), §2: one row per search spec over its seeds "
        "(each seed a separate job). budget: the config that set the generations (paper: the "
        "spec's own G; ci: a reduced one). ms per evaluation: wall time of the search (one "
        "thread unless the config gives more) over its evaluations, median over seeds; 40k "
        "evaluations: that rate times 40,000, against the paper's DEC 3000/400 figures. The "
        "terms are measured on each seed's best motion from the nominal start; medians over "
        "seeds. contact_distance counts endpoints within 1 mm of the floor at both ends of a "
        "step.\n\n"
    )
    write_text_atomically(md_path, caption + frame.to_markdown(index=False) + "\n")
    return frame
