"""Luxo benchmarks: the landing controller's generation (target: <= 60 s warm on 2
cores) and the simulation's speed against real time (target: >= 100x once compiled).

    python benchmarks/luxo.py            # full: generation cold and warm, the show simulated
    python benchmarks/luxo.py --smoke    # CI: the same code paths (one motor program, landed)

Writes results/benchmarks/luxo.{csv,md} (luxo_smoke.* with --smoke) and prints them. "Cold" uses an
empty numba cache (NUMBA_CACHE_DIR), so it includes JIT compilation, as a user's first run does. The
simulation is timed in a fresh process with a warm cache: the first run of the script to its
trajectory file there (which loads the compiled kernels), the second, and the simulation alone
(``run_script``: motor programs, controllers, breakpoints; no file), each against the simulated
time.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd
from generation import cache_environment, generate, numba_cache, write_results

ROOT = Path(__file__).resolve().parents[1]
DT = 0.0005  # s, config/config.yaml's luxo dt

SIMULATE = """
import json, sys, time
from mosys.animation.runner import ScriptSources, load_controllers, load_programs, run_script
from mosys.dynamics.load import load_dynamics
from mosys.parsing.script import parse_script
from mosys.animation.trajectory_file import run_animation_script
script, controllers, dynamics, out, dt, motor = sys.argv[1:7]
times = []
for _ in range(2):
    started = time.perf_counter()
    trajectory = run_animation_script(script, controllers, dynamics, out, float(dt), motor)
    times.append(time.perf_counter() - started)
lamp = load_dynamics(dynamics + "/luxo.py")
parsed = parse_script(script)
sources = ScriptSources(
    lamp, load_controllers(parsed, controllers, lamp), load_programs(parsed, motor, "luxo", lamp)
)
started = time.perf_counter()
run_script(parsed, sources, float(dt))
simulation = time.perf_counter() - started
print(json.dumps({"simulated_s": float(trajectory.t[-1]), "first_s": times[0],
                  "second_s": times[1], "simulation_s": simulation}))
"""

SMOKE_SCRIPT = """object luxo figure=luxo
state luxo x=0 hip=0 elbow=120
swapcon luxo conland.ctab
motor luxo hop
sim 3 until=dest
"""


def simulate(
    script: Path, controllers: Path, dynamics: Path, out: Path, cache: Path | None
) -> dict:
    """Run ``script`` twice in one new process with the numba cache ``cache``."""
    done = subprocess.run(
        [sys.executable, "-c", SIMULATE, str(script), str(controllers), str(dynamics), str(out)]
        + [str(DT), str(ROOT / "specs" / "motor")],
        env=cache_environment(cache),
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
        cold_cache, warm_cache = tmp / "cold_cache", numba_cache(tmp, args.smoke)
        dynamics, controllers = tmp / "dynamics", tmp / "controllers"
        controllers.mkdir()
        for figure in ("luxo", "luxo_grounded"):
            compile_figure(ROOT / "specs/figures" / f"{figure}.fig", dynamics / f"{figure}.py")
        spec = ROOT / "specs/controllers/luxo/land.ssc"
        table = controllers / "land.h5"
        grounded = dynamics / "luxo_grounded.py"
        # smoke: no cold run (its JIT compilation is half a minute of CI for no code path)
        cold = None if args.smoke else generate(grounded, spec, table, cold_cache)
        generate(grounded, spec, table, warm_cache)  # fill the cache
        warm = generate(grounded, spec, table, warm_cache)
        rows.append(
            {
                "case": "landing controller (land.ssc)",
                "nodes": warm["nodes"],
                "iterations": warm["iterations"],
                "policy_sweeps": warm["policy_sweeps"],
                "generation_s_warm": round(warm["dp_seconds"], 2),
                "process_s_warm": round(warm["process_seconds"], 2),
                "process_s_cold": round(cold["process_seconds"], 1) if cold else None,
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
        cases = {
            "first_s": "first run in a process (script to trajectory file)",
            "second_s": "second run in the process (script to trajectory file)",
            "simulation_s": "the simulation alone (run_script, compiled)",
        }
        for key, what in cases.items():
            rows.append(
                {
                    "case": f"{script.name}: {run['simulated_s']:.1f} s simulated at dt {DT:g} s, "
                    + what,
                    "process_s_warm": round(run[key], 3),
                    # three significant digits: the smoke run's first run is 0.37x real time
                    "times_real_time": float(f"{run['simulated_s'] / run[key]:.3g}"),
                    "target": ">= 100x real time",
                }
            )
    write_results(pd.DataFrame(rows), "luxo", args.smoke)


if __name__ == "__main__":
    main()
