"""Car benchmark: generating the parking controller (the 1990 paper's §6) at the paper's size
(about 13,250 states after removing collisions), at about 7x as many states, and at the grid
specs/controllers/car/park.ssc ships.

    python benchmarks/car.py            # all three, warm numba cache (after one filling run)
    python benchmarks/car.py --smoke    # CI: the paper's size only

Writes results/benchmarks/car.{csv,md} (car_smoke.* with --smoke) and prints them. The paper
gives only its table's size (13,250 states) and none of its steps; the paper's size here is
park.ssc (its scene, controls and destination) on steps chosen to come near it: 0.5 m in x,
0.25 m in y, 15 deg of heading, 15 deg of steer and 0.5 m/s. The 7x grid halves the step of x, y and
heading over the same ranges (2n - 1 nodes on each of those axes). dp_s_warm is the DP's time,
split into its exit transitions and its value iteration (transitions_s_warm,
value_iteration_s_warm), so that the table shows where the time goes. Each table then runs the
start grid of the pipeline's config (config/config.yaml's car.start_grid, 1,680 starts; with
--smoke, its second heading and steer, 140 starts), ``mosys starts`` on two threads in a new
process as the pipeline runs it: start_grid_s_warm is that process's wall time,
start_grid_parked how many of the counted starts parked.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import pandas as pd
import yaml
from generation import cache_environment, generate, numba_cache, write_results

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs/controllers/car/park.ssc"
REFINED_AXES = ("x", "y", "heading")
PAPER_STATES = 13250
PAPER_GRID = {  # ssd NAME MIN MAX SAMPLES near the paper's 13,250 states, dest on nodes
    "x": "-3.0 6.0 19",
    "y": "0.9 3.65 12",
    "heading": "-30 45 6",
    "steer": "-30 30 5",
    "speed": "-1.0 1.0 5",
}


def paper_spec(text: str) -> str:
    """park.ssc on a grid of the paper's size (PAPER_GRID)."""
    for name, axis in PAPER_GRID.items():
        text = re.sub(rf"^ssd {name} .*$", f"ssd {name} {axis}", text, flags=re.M)
    return text


def refined_spec(text: str) -> str:
    """The spec with the steps of x, y and heading halved: n nodes -> 2n - 1."""

    def refine(match: re.Match) -> str:
        name, low, high, count = match.groups()
        return f"ssd {name} {low} {high} {2 * int(count) - 1}"

    pattern = r"^ssd (" + "|".join(REFINED_AXES) + r") (\S+) (\S+) (\d+)"
    return re.sub(pattern, refine, text, flags=re.M)


def start_grid(table: Path, dynamics: Path, out: Path, cache: Path | None, smoke: bool) -> dict:
    """Run the config's start grid (with ``smoke``, its second heading and steer alone) from
    ``table`` as the pipeline's rule does, in a new process; its wall seconds and the counted
    and parked starts."""
    grid = yaml.safe_load((ROOT / "config/config.yaml").read_text())["car"]["start_grid"]
    if smoke:
        grid = grid | {"heading": grid["heading"][1:2], "steer": grid["steer"][1:2]}
    mosys = str(Path(sys.executable).parent / "mosys")  # this environment's
    command = [mosys, "starts", str(table), "--dynamics", str(dynamics)]
    for name in ("x", "y", "heading", "steer"):
        command += [f"--{name}", *(str(v) for v in grid[name])]
    command += ["--seconds", str(grid["seconds"]), "--dt", str(grid["dt"]), "--threads", "2"]
    started = time.perf_counter()
    subprocess.run(
        [*command, "-o", str(out)],
        env=cache_environment(cache) | {"NUMBA_NUM_THREADS": "1"},
        check=True,
        capture_output=True,
    )
    seconds = time.perf_counter() - started
    with h5py.File(out) as f:
        counted = int((f["excluded"][()] == b"").sum())
        parked = int(f["parked"][()].sum())
    return {"start_grid_s_warm": round(seconds, 2), "start_grid_counted": counted,
            "start_grid_parked": parked}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="the paper's size only, for CI")
    args = parser.parse_args()
    from mosys.dynamics.compile import compile_figure

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cache = numba_cache(tmp, args.smoke)
        dynamics = tmp / "car.py"
        compile_figure(ROOT / "specs/figures/car.fig", dynamics)
        paper = paper_spec(SPEC.read_text())
        cases = [("paper size", paper)]
        if not args.smoke:
            cases.append(("paper size, x, y, heading steps halved", refined_spec(paper)))
            cases.append(("park.ssc as shipped", SPEC.read_text()))
        for label, text in cases:
            spec = tmp / "park.ssc"
            spec.write_text(text)
            generate(dynamics, spec, tmp / "park.h5", cache)  # fill the numba cache
            warm = generate(dynamics, spec, tmp / "park.h5", cache)
            if cache is not None and not rows:  # fill it with the start grid's kernels too
                start_grid(tmp / "park.h5", dynamics, tmp / "grid.h5", cache, smoke=True)
            rows.append(
                {
                    "case": label,
                    "grid_nodes": warm["nodes"],
                    "table_states": warm["table_states"],
                    "paper_states": PAPER_STATES,
                    "iterations": warm["iterations"],
                    "policy_sweeps": warm["policy_sweeps"],
                    "dp_s_warm": round(warm["dp_seconds"], 2),
                    "transitions_s_warm": round(warm["transition_seconds"], 2),
                    "value_iteration_s_warm": round(warm["iteration_seconds"], 2),
                    "process_s_warm": round(warm["process_seconds"], 2),
                    "peak_rss_MiB": round(warm["peak_rss_bytes"] / 2**20, 1),
                }
                | start_grid(tmp / "park.h5", dynamics, tmp / "grid.h5", cache, args.smoke)
            )
    frame = pd.DataFrame(rows)
    if len(frame) > 1:  # growth against the paper's size
        base = frame.iloc[0]
        frame["states_ratio"] = (frame.table_states / base.table_states).round(2)
        frame["time_ratio"] = (frame.dp_s_warm / base.dp_s_warm).round(2)
        frame["memory_ratio"] = (frame.peak_rss_MiB / base.peak_rss_MiB).round(2)
    write_results(frame, "car", args.smoke)


if __name__ == "__main__":
    main()
