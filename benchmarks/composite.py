"""Composite-motion benchmark: the transition-point search of Figure 5 on Table 4's
script, Q x G x H = 16 x 16 x 4 = 1,024 concatenations of the three robust Star-Man controllers
(target <= 10 s on 2 cores with the controllers built; the paper: under a minute on a DEC
3000/400), and the whole ``mosys composite`` command in a new process (imports, numba cache
loads, both motions written).

    python benchmarks/composite.py            # the controllers in results/bsr (build them with
                                              # snakemake results/composite_all)
    python benchmarks/composite.py --smoke    # CI: controllers from tiny searches (G = 20)

Writes results/benchmarks/composite{,_smoke}.{csv,md} and prints them.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from generation import write_results

from mosys.bsr.result_file import search_to_file
from mosys.composite.result_file import composite_to_file
from mosys.composite.session import find_controller_files
from mosys.io.composite_result import read_composite_result
from mosys.parsing.composite import parse_composite_script

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "specs/composite/starman_show.comp"
PAPER = "1,024 simulations in under a minute (DEC 3000/400)"
PAPER_SECONDS = 60.0  # "under a minute": at most this, so a ratio to it bounds ours from above


def tiny_controllers(directory: Path) -> Path:
    """The script's robust searches at G = 20, seed 1 (what --smoke concatenates)."""
    for phase in parse_composite_script(SCRIPT).phases:
        search_to_file(
            ROOT / "specs/bsr" / f"{phase.controller}.bsr",
            ROOT / "specs/figures",
            1,
            directory / phase.controller / "seed1.h5",
            generations=20,
            budget="smoke",
        )
    return directory


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny controllers, for CI")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        controllers = tiny_controllers(tmp / "bsr") if args.smoke else ROOT / "results/bsr"
        files = find_controller_files(parse_composite_script(SCRIPT), controllers)
        missing = [search for search, found in files.items() if not found]
        if missing:
            sys.exit(f"no controllers for {missing} in {controllers}: build results/composite_all")
        dirs = (ROOT / "specs/figures", ROOT / "specs/bsr")
        composite_to_file(SCRIPT, files, tmp / "warm.h5", *dirs)  # compiles or loads kernels
        rows = []
        for repeat in range(3):
            found = composite_to_file(SCRIPT, files, tmp / "run.h5", *dirs)
            attrs = read_composite_result(tmp / "run.h5").attrs
            wall = float(attrs["wall_seconds"])
            rows.append(
                {
                    "case": f"transition search, Q x G x H = 16 x 16 x 4 (run {repeat + 1})",
                    "threads": 1,
                    "simulations": found.simulations,
                    "seconds": round(wall, 3),
                    "ms per simulation": round(1000 * wall / found.simulations, 3),
                    "score before": round(found.guess_score, 3),
                    "score after": round(found.score, 3),
                    "paper": PAPER,
                    "vs paper": f"up to {PAPER_SECONDS / wall:.0f}x faster",
                    "target": "<= 10 s on 2 cores",
                }
            )
        started = time.perf_counter()
        subprocess.run(
            [
                sys.executable,
                "-m",
                "mosys.cli",
                "composite",
                str(SCRIPT),
                "--bsr-results",
                str(controllers),
                "--figures",
                str(ROOT / "specs/figures"),
                "--bsr-specs",
                str(ROOT / "specs/bsr"),
                "-o",
                str(tmp / "process.h5"),
            ],
            check=True,
            capture_output=True,
            text=True,
        )
        process = time.perf_counter() - started
        rows.append(
            {
                "case": "mosys composite in a new process (warm numba cache, files written)",
                "threads": 1,
                "simulations": found.simulations,
                "seconds": round(process, 2),
                "paper": PAPER,
                "vs paper": f"up to {PAPER_SECONDS / process:.0f}x faster",
                "target": "<= 10 s on 2 cores",
            }
        )
    write_results(pd.DataFrame(rows), "composite", args.smoke)


if __name__ == "__main__":
    main()
