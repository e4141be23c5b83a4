"""The robustness table of the enhanced controllers (the 1995 paper, §3): each robust search
and its plain twin, their best controllers run from the same randomly perturbed starts."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from mosys.composite.robustness import bind_spec, perturbed_starts, seed_fitness
from mosys.composite.session import files_by_search
from mosys.io.atomic import write_text_atomically

STARTS = 50
STARTS_SEED = 1


def robustness_frame(
    pairs: Sequence[tuple[str, str]],
    result_paths: Sequence[str | Path],
    specs_dir: str | Path = "specs/bsr",
    figures_dir: str | Path = "specs/figures",
    starts: int = STARTS,
    seed: int = STARTS_SEED,
) -> pd.DataFrame:
    """Two rows per (robust, plain) pair of search names: every seed's best controller run
    under the robust spec (its T, weights and fall endpoints: the conditions the robust
    controller is made for) from its nominal start and from ``starts`` start states drawn with
    its perturbation (generator seed ``seed``). The chosen controller is the seed with the best
    nominal fitness so measured, as a composite script picks it by its own search's."""
    found = files_by_search(result_paths)
    rows = []
    for robust, plain in pairs:
        setup = bind_spec(Path(specs_dir) / f"{robust}.bsr", figures_dir)
        perturbation = setup.spec.perturbation
        drawn = perturbed_starts(setup, perturbation, starts, seed)
        for name, role in ((robust, "robust"), (plain, "plain")):
            seeds = seed_fitness(setup, sorted(found.get(name, [])), drawn)
            if not seeds:
                raise FileNotFoundError(f"no result files of the search {name!r} were given")
            chosen = max(seeds, key=lambda row: row.nominal)
            means = np.array([row.perturbed.mean() for row in seeds])
            rows.append(
                {
                    "search": name,
                    "controller": role,
                    "starts": starts,
                    "perturbation": (
                        f"angle ±{perturbation.angle:g}°, joints ±{perturbation.joints:g}°, "
                        f"speed ±{perturbation.speed:g} m/s, spin ±{perturbation.spin:g}°/s"
                    ),
                    "budget": ", ".join(sorted({row.budget for row in seeds})),
                    "generations": ", ".join(
                        str(g) for g in sorted({row.generations for row in seeds})
                    ),
                    "T (s)": setup.spec.duration,
                    "seeds": len(seeds),
                    "median nominal fitness": round(
                        float(np.median([r.nominal for r in seeds])), 2
                    ),
                    "mean perturbed fitness (seed average)": round(float(means.mean()), 2),
                    "chosen seed": chosen.seed,
                    "chosen nominal": round(chosen.nominal, 2),
                    "chosen perturbed mean": round(float(chosen.perturbed.mean()), 2),
                    "chosen perturbed 10th pct": round(
                        float(np.percentile(chosen.perturbed, 10)), 2
                    ),
                    "chosen perturbed min": round(float(chosen.perturbed.min()), 2),
                }
            )
    return pd.DataFrame(rows)


def write_robustness_table(
    pairs: Sequence[tuple[str, str]],
    result_paths: Sequence[str | Path],
    csv_path: str | Path,
    md_path: str | Path,
    specs_dir: str | Path = "specs/bsr",
    figures_dir: str | Path = "specs/figures",
) -> pd.DataFrame:
    """Write the robustness table as CSV and Markdown (each atomically)."""
    frame = robustness_frame(pairs, result_paths, specs_dir, figures_dir)
    write_text_atomically(csv_path, frame.to_csv(index=False))
    caption = (
        "Enhanced (robust) BSR controllers after Auslander et al. (1995), §3: each robust search "
        "and its plain twin, every seed's best controller run under the robust spec (its T, "
        f"fitness and fall endpoints) from the same {STARTS} start states, drawn at random with "
        f"the robust spec's perturbation (uniform in each range; generator seed {STARTS_SEED}). "
        "nominal: from the unperturbed start. chosen: the seed with the best nominal fitness. "
        "The robust search perturbs its start at every evaluation; the plain one never does. "
        "budget, generations: what the searches ran at (a reduced CI budget may exempt the "
        "robust searches, so compare the twins at one budget).\n\n"
    )
    write_text_atomically(md_path, caption + frame.to_markdown(index=False) + "\n")
    return frame
