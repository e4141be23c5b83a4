"""What the benchmarks share: controller generation in a fresh process (the measured figures are
the DP alone (the table's transition_seconds + iteration_seconds), the whole process (Python
start-up, imports and, with a cold cache, JIT compilation) and the process's peak resident
memory), and writing a result table."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]

GENERATE = """
import json, sys, time
started = time.perf_counter()
from mosys.dynamics.load import load_dynamics
from mosys.parsing.controller import parse_controller_text
from mosys.ssc.generate import generate_controller
dynamics = load_dynamics(sys.argv[1])
spec = parse_controller_text(open(sys.argv[2]).read(), sys.argv[2])
table = generate_controller(spec, dynamics, sys.argv[3], quiet=True)
dp_seconds = table.attrs["transition_seconds"] + table.attrs["iteration_seconds"]
print(json.dumps({"dp_seconds": dp_seconds,
                  "transition_seconds": table.attrs["transition_seconds"],
                  "iteration_seconds": table.attrs["iteration_seconds"],
                  "kernel_load_seconds": table.attrs["kernel_load_seconds"],
                  "process_seconds": time.perf_counter() - started,
                  "iterations": int(table.attrs["iterations"]),
                  "policy_sweeps": int(table.attrs["policy_sweeps"]),
                  "nodes": int(table.value.size),
                  "table_states": int(table.attrs["table_states"]),
                  "peak_rss_bytes": int(table.attrs["peak_rss_bytes"])}))
"""


def numba_cache(tmp: Path, smoke: bool) -> Path | None:
    """The numba cache a benchmark's processes share: a new one under ``tmp``, filled by the
    benchmark's first (untimed) run; with ``smoke``, None: the install's own, which CI's tests
    have filled, so that a smoke run compiles no kernel a second time (minutes of CI)."""
    return None if smoke else tmp / "warm_cache"


def cache_environment(cache: Path | None) -> dict[str, str]:
    """This process's environment with NUMBA_CACHE_DIR set to ``cache`` (None: left as it is)."""
    return dict(os.environ) if cache is None else dict(os.environ, NUMBA_CACHE_DIR=str(cache))


def generate(dynamics: Path, spec: Path, out: Path, cache: Path | None) -> dict:
    """Generate ``spec`` with ``dynamics`` into ``out`` in a new process whose numba cache is
    ``cache`` (``cache_environment``); returns the figures above."""
    done = subprocess.run(
        [sys.executable, "-c", GENERATE, str(dynamics), str(spec), str(out)],
        env=cache_environment(cache),
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def write_results(frame: pd.DataFrame, name: str, smoke: bool) -> None:
    """Write results/benchmarks/NAME.{csv,md} (NAME_smoke.* for a smoke run) and print it."""
    out = ROOT / "results" / "benchmarks"
    out.mkdir(parents=True, exist_ok=True)
    suffix = "_smoke" if smoke else ""
    frame.to_csv(out / f"{name}{suffix}.csv", index=False)
    (out / f"{name}{suffix}.md").write_text(frame.to_markdown(index=False) + "\n")
    print(frame.to_markdown(index=False))


def copy_workflow(work: Path) -> Path:
    """A copy of the repository at ``work`` (which must not exist) for a pipeline run that leaves
    this one's results/ alone: everything but results/, Snakemake's state, git, the venv and
    caches (the copies keep their mtimes, which are rule inputs)."""
    ignored = ("results", ".snakemake", ".git", ".venv", "__pycache__", ".hypothesis")
    shutil.copytree(ROOT, work, ignore=shutil.ignore_patterns(*ignored))
    return work
