"""Luxo benchmarks (issue 5): the landing controller's generation (target: <= 60 s warm on 2
cores) and the simulation's speed against real time (target: >= 100x once compiled).

    python benchmarks/luxo.py            # full: generation cold and warm, the show simulated
    python benchmarks/luxo.py --smoke    # CI: the same code paths (one motor program, landed)

Writes results/benchmarks/luxo.{csv,md} and prints them. "Cold" uses an empty numba cache
(NUMBA_CACHE_DIR), so it includes JIT compilation, as a user's first run does. The simulation is
timed in a fresh process with a warm cache: the first run of the script there (which loads the
compiled kernels) and the second (the steady state), each against the simulated time.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd
from generation import generate, write_results

ROOT = Path(__file__).resolve().parents[1]
DT = 0.0005  # s, config/config.yaml's luxo dt

SIMULATE = """
import json, sys, time
from mosys.pipeline import run_animation_script
script, controllers, dynamics, out, dt = sys.argv[1:6]
times = []
for _ in range(2):
    started = time.perf_counter()
    trajectory = run_animation_script(script, controllers, dynamics, out, float(dt), sys.argv[6])
    times.append(time.perf_counter() - started)
print(json.dumps({"simulated_s": float(trajectory.t[-1]), "first_s": times[0],
                  "second_s": times[1]}))
"""

SMOKE_SCRIPT = """object luxo figure=luxo
state luxo x=0 hip=0 elbow=120
swapcon luxo conland.ctab
motor luxo hop
sim 3 until=dest
"""


def simulate(script: Path, controllers: Path, dynamics: Path, out: Path, cache: Path) -> dict:
    """Run ``script`` twice in one new process with the numba cache ``cache``."""
    done = subprocess.run(
        [sys.executable, "-c", SIMULATE, str(script), str(controllers), str(dynamics), str(out)]
        + [str(DT), str(ROOT / "specs" / "motor")],
        env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)),
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny sizes, for CI")
    args = parser.parse_args()
    from mosys.dynamics.compile import compile_figure

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cold_cache, warm_cache = tmp / "cold_cache", tmp / "warm_cache"
        dynamics, controllers = tmp / "dynamics", tmp / "controllers"
        controllers.mkdir()
        for figure in ("luxo", "luxo_grounded"):
            compile_figure(ROOT / "specs/figures" / f"{figure}.fig", dynamics / f"{figure}.py")
        spec = ROOT / "specs/controllers/luxo/land.ssc"
        table = controllers / "land.h5"
        grounded = dynamics / "luxo_grounded.py"
        cold = generate(grounded, spec, table, cold_cache)
        generate(grounded, spec, table, warm_cache)  # fill the cache
        warm = generate(grounded, spec, table, warm_cache)
        rows.append(
            {
                "case": "landing controller (land.ssc)",
                "nodes": warm["nodes"],
                "iterations": warm["iterations"],
                "generation_s_warm": round(warm["dp_seconds"], 2),
                "process_s_warm": round(warm["process_seconds"], 2),
                "process_s_cold": round(cold["process_seconds"], 1),
                "peak_rss_mib": round(warm["peak_rss_bytes"] / 2**20),
                "target": "<= 60 s warm",
            }
        )
        if args.smoke:
            script = tmp / "hop.anim"
            script.write_text(SMOKE_SCRIPT)
        else:
            script = ROOT / "specs/scripts/luxo_show.anim"
        run = simulate(script, controllers, dynamics, tmp / "show.h5", warm_cache)
        for which in ("first", "second"):
            seconds = run[f"{which}_s"]
            rows.append(
                {
                    "case": f"{script.name}: {run['simulated_s']:.1f} s simulated, dt {DT:g} s, "
                    f"{which} run in the process (script to trajectory file)",
                    "process_s_warm": round(seconds, 2),
                    "times_real_time": round(run["simulated_s"] / seconds),
                    "target": ">= 100x real time",
                }
            )
    write_results(pd.DataFrame(rows), "luxo", args.smoke)


if __name__ == "__main__":
    main()
