"""Pendulum benchmarks: controller generation against Figure 13 of the 1990 paper.

    python benchmarks/pendulum.py            # full: six controllers warm and cold, A at 1x..8x,
                                             # and the whole results/pendulum_all pipeline
    python benchmarks/pendulum.py --smoke    # CI: the same code paths at tiny sizes

Writes results/benchmarks/pendulum.{csv,md} (pendulum_smoke.* with --smoke) and prints them. "Cold"
runs use an empty numba cache directory (NUMBA_CACHE_DIR), so they include JIT compilation, as a
user's first run does.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import pandas as pd
from generation import cache_environment, copy_workflow, generate, numba_cache, write_results

ROOT = Path(__file__).resolve().parents[1]
PAPER_SECONDS = {"A": 381.0, "B": 452.0, "C": 341.0, "D": 460.0, "E": 459.0, "F": 454.0}


def finer_spec(factor: int) -> str:
    """Controller A with every grid step divided by ``factor`` over the same domain (the angle
    axis keeps its 360° wrap: 36·factor nodes; ω keeps ±500 deg/s with 0 on a node:
    20·factor + 1 nodes), at the DP's default step (its steps are sized to the cell)."""
    return (
        "dyn link1\n"
        f"ssd omega -500.0 500.0 {20 * factor + 1}\n"
        f"ssd angle -180 {180 - 10 / factor:g} {36 * factor} wrap\n"
        "torq torque -10.0 10.0 11 0.1\n"
        "dest angle=0 omega=0\n"
    )


def pipeline_seconds(cache: Path, work: Path) -> float:
    """Wall time of `snakemake results/pendulum_all` from an empty results/ in a copy of the
    workflow."""
    if work.exists():
        shutil.rmtree(work)
    copy_workflow(work)
    env = cache_environment(cache)
    started = time.perf_counter()
    subprocess.run(
        ["snakemake", "-c2", "results/pendulum_all", "--quiet", "all"],
        cwd=work,
        env=env,
        check=True,
        capture_output=True,
    )
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny sizes, for CI")
    args = parser.parse_args()
    from mosys.dynamics.compile import compile_figure

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cold_cache, warm_cache = tmp / "cold_cache", numba_cache(tmp, args.smoke)
        dynamics = tmp / "link1.py"
        compile_figure(ROOT / "specs/figures/link1.fig", dynamics)
        names = "A" if args.smoke else "ABCDEF"
        for name in names:
            spec = ROOT / "specs/controllers/pendulum" / f"{name}.ssc"
            # smoke: no cold run (its JIT compilation is half a minute of CI for no code path)
            shutil.rmtree(cold_cache, ignore_errors=True)
            cold = None if args.smoke else generate(dynamics, spec, tmp / f"{name}.h5", cold_cache)
            generate(dynamics, spec, tmp / f"{name}.h5", warm_cache)  # fill the cache
            warm = generate(dynamics, spec, tmp / f"{name}.h5", warm_cache)
            rows.append(
                {
                    "case": f"{name} at the paper's grid",
                    "nodes": warm["nodes"],
                    "iterations": warm["iterations"],
                    "dp_s_warm": round(warm["dp_seconds"], 4),
                    "process_s_warm": round(warm["process_seconds"], 3),
                    "dp_s_cold": round(cold["dp_seconds"], 3) if cold else None,
                    "process_s_cold": round(cold["process_seconds"], 2) if cold else None,
                    "paper_s": PAPER_SECONDS[name],
                    "speedup_vs_paper": round(PAPER_SECONDS[name] / warm["dp_seconds"]),
                }
            )
        for factor in (1, 2) if args.smoke else (1, 2, 4, 8):
            spec = tmp / f"A_x{factor}.ssc"
            spec.write_text(finer_spec(factor))
            warm = generate(dynamics, spec, tmp / f"A_x{factor}.h5", warm_cache)
            rows.append(
                {
                    "case": f"A, grid {factor}x finer per axis"
                    if factor > 1
                    else "A, the paper's grid (the finer grids' base)",
                    "nodes": warm["nodes"],
                    "iterations": warm["iterations"],
                    "dp_s_warm": round(warm["dp_seconds"], 3),
                    "process_s_warm": round(warm["process_seconds"], 3),
                }
            )
        if not args.smoke:
            shutil.rmtree(cold_cache, ignore_errors=True)
            cold = pipeline_seconds(cold_cache, tmp / "work")
            warm = pipeline_seconds(cold_cache, tmp / "work")
            rows.append(
                {
                    "case": "results/pendulum_all from empty results/",
                    "process_s_cold": round(cold, 1),
                    "process_s_warm": round(warm, 1),
                }
            )
    frame = pd.DataFrame(rows)
    write_results(frame, "pendulum", args.smoke)


if __name__ == "__main__":
    main()
