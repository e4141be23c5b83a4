"""BSR benchmarks: 40,000 sense-based evaluations of Mr. Star-Man (target <= 60 s on 2
cores; the paper: 3-6 min on a DEC 3000/400) and a whole time-based search of Beryl Biped (target
<= 20 s; the paper: tens of seconds), each on 1 and 2 threads, and the first search of a fresh
install (cold numba cache: JIT compilation included).

    python benchmarks/bsr.py            # full: the paper's C = 10, G = 4000
    python benchmarks/bsr.py --smoke    # CI: the same code paths, G = 20

Writes results/benchmarks/bsr.{csv,md} (bsr_smoke.* with --smoke) and prints them. Each case runs
``mosys bsr-search`` in a new process with a warm numba cache (filled first), timed by the search's
own wall clock (the search alone, not the imports) and by the process.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from generation import cache_environment, numba_cache, write_results

from mosys.io.bsr_result import read_bsr_result

ROOT = Path(__file__).resolve().parents[1]
PAPER_SECONDS = {"sense": "180-360 s (DEC 3000/400)", "time": "tens of seconds (DEC 3000/400)"}
TARGET = {"sense": "<= 60 s on 2 cores", "time": "<= 20 s on 2 cores"}


def search(spec: str, generations: int, threads: int, cache: Path | None, out: Path) -> dict:
    """One search in a new process with the numba cache ``cache`` (``cache_environment``);
    returns its wall times and the result's numbers."""
    started = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-m",
            "mosys.cli",
            "bsr-search",
            str(ROOT / "specs/bsr" / spec),
            "--seed",
            "1",
            "--generations",
            str(generations),
            "--threads",
            str(threads),
            "--figures",
            str(ROOT / "specs/figures"),
            "-o",
            str(out),
        ],
        env=cache_environment(cache),
        check=True,
        capture_output=True,
        text=True,
    )
    process = time.perf_counter() - started
    attrs = read_bsr_result(out).attrs
    return {
        "kind": str(attrs["controller_kind"]),
        "evaluations": int(attrs["evaluations"]),
        "search_s": float(attrs["wall_seconds"]),
        "process_s": process,
        "steps_per_second": float(attrs["steps_per_second"]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny budget, for CI")
    args = parser.parse_args()
    generations = 20 if args.smoke else 4000
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        warm = numba_cache(tmp, args.smoke)
        if not args.smoke:
            cold = search("starman_cartwheel.bsr", 20, 1, tmp / "cold_cache", tmp / "cold.h5")
            rows.append(
                {
                    "case": "first search of a fresh install (cold numba cache), 210 evaluations",
                    "threads": 1,
                    "process_s": round(cold["process_s"], 1),
                }
            )
        search("starman_cartwheel.bsr", 2, 1, warm, tmp / "fill.h5")  # fill the cache
        for spec in ("starman_cartwheel.bsr", "beryl_shuffle.bsr"):
            for threads in (1, 2):
                run = search(spec, generations, threads, warm, tmp / "run.h5")
                rows.append(
                    {
                        "case": f"{spec}: {run['kind']}-based, C = 10, G = {generations}",
                        "threads": threads,
                        "evaluations": run["evaluations"],
                        "search_s": round(run["search_s"], 2),
                        "process_s": round(run["process_s"], 2),
                        "ms_per_evaluation": round(1000 * run["search_s"] / run["evaluations"], 3),
                        "steps_per_second": f"{run['steps_per_second']:.3g}",
                        "paper": PAPER_SECONDS[run["kind"]],
                        "target": TARGET[run["kind"]],
                    }
                )
    write_results(pd.DataFrame(rows), "bsr", args.smoke)


if __name__ == "__main__":
    main()
