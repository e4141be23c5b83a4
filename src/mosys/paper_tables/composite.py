"""The composite-motion table (the 1995 paper, §3): per script, the transition search's size and
time against the paper's, and the score and phase durations before and after it."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from mosys.io.atomic import write_text_atomically
from mosys.io.composite_result import read_composite_result

# §3: "in under a minute on a DEC 3000/400 AXP workstation", Q x G x H = 16 x 16 x 4.
PAPER_SIMULATIONS = 1024
PAPER_SECONDS = 60.0
PAPER_FIGURE = "1,024 simulations in under a minute (DEC 3000/400)"


def composite_frame(result_paths: Sequence[str | Path]) -> pd.DataFrame:
    """One row per composite result file."""
    return pd.DataFrame(composite_rows(result_paths))


def composite_rows(result_paths: Sequence[str | Path]) -> list[dict]:
    """``composite_frame``'s rows, each with the columns of its own script's phases."""
    rows = []
    for path in result_paths:
        result = read_composite_result(path)
        attrs = result.attrs
        wall = float(attrs["wall_seconds"])
        paper_wall = PAPER_SECONDS * int(attrs["simulations"]) / PAPER_SIMULATIONS
        row = {
            "script": str(attrs["script"]),
            "budget": str(attrs["budget"]),
            "Q x G x H": f"{attrs['search_q']} x {attrs['search_g']} x {attrs['search_h']}",
            "simulations": int(attrs["simulations"]),
            "wall (s)": round(wall, 2),
            "paper": PAPER_FIGURE,
            "speed-up vs paper": f"up to {paper_wall / wall:.0f}x",
            "score before": round(float(attrs["score_before"]), 3),
            "score after": round(float(attrs["score_after"]), 3),
        }
        before, after = result.scores_before, result.scores_after
        for guess, refined in zip(result.phases_before, result.phases, strict=True):
            name = guess["name"]
            row[f"{name} ticks before"] = guess["ticks"]
            row[f"{name} ticks after"] = refined["ticks"]
            row[f"{name} score before"] = round(before[name], 3)
            row[f"{name} score after"] = round(after[name], 3)
        rows.append(row)
    return rows


def write_composite_table(
    result_paths: Sequence[str | Path], csv_path: str | Path, md_path: str | Path
) -> pd.DataFrame:
    """Write the composite table as CSV and Markdown (each atomically)."""
    rows = composite_rows(result_paths)
    frame = pd.DataFrame(rows)
    write_text_atomically(csv_path, frame.to_csv(index=False))
    caption = (
        "Composite motions after Auslander et al. (1995), §3 (Table 4, Figures 13-14): the "
        "transition-point search of Figure 5 from the script's guessed durations. simulations: "
        "the concatenations the search ran (Q x G x H mutants and the guess). wall: the search "
        "alone, one thread, kernels compiled. speed-up: the paper's minute scaled to our "
        "simulations over our wall time (an upper bound: the paper says only 'under a minute', so "
        "its time, and the speed-up, may be less). budget: "
        "the config the pipeline ran with (the robustness table gives each controller's budget "
        "and generations). Scores are the script's; ticks are 0.01 s. A score of nan or inf is a "
        "division by zero in the script's expressions (IEEE arithmetic); the search ranks nan "
        "as -inf, never as the best.\n\n"
    )
    write_text_atomically(md_path, caption + markdown_table(frame, rows) + "\n")
    return frame


def markdown_table(frame: pd.DataFrame, rows: list[dict]) -> str:
    """``frame`` (made of ``rows``) as Markdown, the cells of phases a script does not have
    left empty (as the CSV leaves them) rather than ``nan``, which the caption gives to a
    division by zero."""
    has = pd.DataFrame([dict.fromkeys(row, True) for row in rows], columns=frame.columns)
    return frame.astype(object).where(has.notna(), "").to_markdown(index=False)
