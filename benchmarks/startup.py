"""Start-up benchmarks: how long each ``mosys`` verb takes to start when it has nothing to compute
(target <= 0.5 s), and the pipeline around the DP step: ``snakemake results/pendulum_all`` from
an empty results/ with a warm numba cache (target <= 8 s) and with cold caches (target <= 30 s),
Snakemake's own dry run, and two ``mosys dp`` jobs started at once with a cold cache (cold
compilation should happen once per machine, not once per parallel job).

    python benchmarks/startup.py            # full: verbs, then the pipeline cold and warm
    python benchmarks/startup.py --smoke    # CI: the verbs' start-up only (a few seconds)

Writes results/benchmarks/startup.{csv,md} (startup_smoke.* with --smoke) and prints them.
Every measurement runs in new processes: ``mosys VERB --help`` for each verb (argument parsing
and the imports ``--help`` needs, nothing else), ``mosys --help``, ``mosys --version`` and a real
``mosys index``. The pipeline runs in a temporary copy of the workflow, its specs and sources
(the real results/ is not touched) with its own numba and mosys caches (NUMBA_CACHE_DIR,
MOSYS_CACHE_DIR): the cold build starts from empty ones, the warm builds reuse what it left and
start from an empty results/ each. The machine may be shared: each figure is the best (minimum)
of the repeats, beside their median.

Columns: ``wall_s_best``/``wall_s_median`` the wall time; ``cpu_s_best``/``cpu_s_median`` the
user + system time of the process and everything it ran (for a build, Snakemake and all its
jobs); ``target_s`` and ``meets_target`` (the best wall time against it); ``heavy_imports``
the numerical libraries a verb's ``--help`` imported (numpy, h5py, sympy, numba, matplotlib,
pandas, scipy: there should be none); ``detail`` for a build the sum of its jobs' wall times
(their ``benchmark:`` files), for the two cold jobs how many kernel signatures each compiled
(numba's machine-code files, one per kernel and signature) and how many both did (none: each
compiles once per machine; the two compile different ones side by side).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from generation import copy_workflow, write_results

ROOT = Path(__file__).resolve().parents[1]
VERB_TARGET_S = 0.5
WARM_TARGET_S = 8.0
COLD_TARGET_S = 30.0
TARGET = "results/pendulum_all"
HEAVY = ("numpy", "h5py", "sympy", "numba", "matplotlib", "pandas", "scipy")
# mosys's main with argv, then the heavy libraries it imported ("imported: ..." on stderr)
IMPORTED = (
    "import sys\n"
    "from mosys.cli import main\n"
    "try:\n"
    "    main(sys.argv[1:])\n"
    "except SystemExit:\n"
    "    pass\n"
    f"heavy = {HEAVY!r}\n"
    "loaded = {name.partition('.')[0] for name in sys.modules}\n"
    "print('imported:', *(name for name in heavy if name in loaded), file=sys.stderr)\n"
)


def environment(**overrides: str) -> dict[str, str]:
    """This environment with this interpreter's scripts (mosys, snakemake) first on PATH."""
    bin_dir = str(Path(sys.executable).parent)
    return dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), **overrides)


def timed(command: list[str], cwd: Path, env: dict[str, str]) -> tuple[float, float, str]:
    """Run ``command`` to completion: its wall and CPU seconds (user + system, its children
    included) and its stdout + stderr; CalledProcessError if it fails."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    if done.returncode != 0:
        raise subprocess.CalledProcessError(done.returncode, command, done.stdout, done.stderr)
    return wall, cpu, done.stdout + done.stderr


def row(kind: str, what: str, runs: list[tuple[float, float]], target: float | None, **extra):
    walls, cpus = [wall for wall, _ in runs], [cpu for _, cpu in runs]
    return {
        "kind": kind,
        "what": what,
        "runs": len(runs),
        "wall_s_best": round(min(walls), 3),
        "wall_s_median": round(statistics.median(walls), 3),
        "cpu_s_best": round(min(cpus), 3),
        "cpu_s_median": round(statistics.median(cpus), 3),
        "target_s": target,
        "meets_target": None if target is None else bool(min(walls) <= target),
        **extra,
    }


def verb_rows(repeats: int, tmp: Path) -> list[dict]:
    """Each verb's ``--help``, the top-level ``--help`` and ``--version``, and a real
    ``mosys index``, ``repeats`` times each in new processes."""
    from mosys.cli import FAMILIES

    listed = tmp / "listed.txt"
    listed.write_text("")
    invocations = {
        "mosys --help": ["--help"],
        "mosys --version": ["--version"],
        "mosys index FILE -o INDEX": ["index", str(listed), "-o", str(tmp / "index")],
    }
    for family in FAMILIES:
        for verb in family.verbs:
            invocations[f"mosys {verb.name} --help"] = [*verb.name.split(), "--help"]
    env = environment()
    rows = []
    for what, argv in invocations.items():
        command = [sys.executable, "-m", "mosys.cli", *argv]
        runs = [timed(command, tmp, env)[:2] for _ in range(repeats)]
        output = timed([sys.executable, "-c", IMPORTED, *argv], tmp, env)[2]
        heavy = [line for line in output.splitlines() if line.startswith("imported:")][-1]
        heavy = heavy.removeprefix("imported:").strip()
        rows.append(row("verb start-up", what, runs, VERB_TARGET_S, heavy_imports=heavy))
    return rows


def job_seconds(work: Path) -> float:
    """The sum of the jobs' wall times, from the rules' ``benchmark:`` files."""
    total = 0.0
    for path in (work / "results" / "benchmarks").rglob("*.tsv"):
        total += float(pd.read_csv(path, sep="\t")["s"].iloc[-1])
    return total


def build(work: Path, env: dict[str, str]) -> tuple[float, float, float]:
    """``snakemake -c2 results/pendulum_all`` from an empty results/: wall and CPU seconds,
    and the sum of its jobs' wall times."""
    shutil.rmtree(work / "results", ignore_errors=True)
    command = [sys.executable, "-m", "snakemake", "-c2", TARGET, "--quiet", "all"]
    wall, cpu, _ = timed(command, work, env)
    return wall, cpu, job_seconds(work)


def cold_pair(work: Path, tmp: Path) -> dict:
    """Two ``mosys dp`` jobs (controllers A and B) started at once with an empty numba cache,
    as Snakemake starts them: wall and CPU seconds, and the kernel signatures each compiled and
    both did."""
    cache = tmp / "pair_cache"
    env = environment(
        NUMBA_CACHE_DIR=str(cache / "numba"),
        MOSYS_CACHE_DIR=str(cache / "mosys"),
        NUMBA_NUM_THREADS="1",
        NUMBA_DEBUG_CACHE="1",  # each process says which cache entries it wrote
    )
    commands = [
        [
            sys.executable,
            "-m",
            "mosys.cli",
            "dp",
            f"specs/controllers/pendulum/{name}.ssc",
            "--dynamics-dir",
            "results/dynamics",
            "-o",
            str(tmp / f"pair_{name}.h5"),
            "--quiet",
        ]
        for name in "AB"
    ]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    jobs = [
        subprocess.Popen(command, cwd=work, env=env, stdout=subprocess.PIPE, text=True)
        for command in commands
    ]
    outputs = [job.communicate()[0] for job in jobs]
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if any(job.returncode for job in jobs):
        raise RuntimeError("a cold mosys dp failed:\n" + "\n".join(outputs))
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    saved = [  # the machine code each process compiled and wrote: a file per kernel and
        # signature (a kernel's index file is written again for each of its signatures: two
        # jobs that compiled different signatures of one kernel both write it)
        {
            line.split("data saved to", 1)[1].strip()
            for line in output.splitlines()
            if "data saved to" in line
        }
        for output in outputs
    ]
    return row(
        "pipeline",
        "two mosys dp (A, B) at once, cold numba cache",
        [(wall, cpu)],
        None,
        detail=f"kernel signatures compiled: {len(saved[0])} and {len(saved[1])}, "
        f"{len(saved[0] & saved[1])} by both",
    )


def pipeline_rows(repeats: int, tmp: Path) -> list[dict]:
    """The pipeline's rows: the cold build, the warm builds, the dry run, the cold pair."""
    work = copy_workflow(tmp / "work")
    cache = tmp / "cache"
    env = environment(NUMBA_CACHE_DIR=str(cache / "numba"), MOSYS_CACHE_DIR=str(cache / "mosys"))
    rows = []
    wall, cpu, jobs = build(work, env)
    rows.append(
        row(
            "pipeline",
            f"snakemake -c2 {TARGET}, empty results/, cold numba and mosys caches",
            [(wall, cpu)],
            COLD_TARGET_S,
            detail=f"jobs' wall times sum to {jobs:.1f} s",
        )
    )
    warm = [build(work, env) for _ in range(repeats)]
    rows.append(
        row(
            "pipeline",
            f"snakemake -c2 {TARGET}, empty results/, warm numba cache",
            [(wall, cpu) for wall, cpu, _ in warm],
            WARM_TARGET_S,
            detail=f"jobs' wall times sum to {min(jobs for *_, jobs in warm):.1f} s (best)",
        )
    )
    dry_run = [sys.executable, "-m", "snakemake", "-n", TARGET, "--quiet", "all"]
    shutil.rmtree(work / "results", ignore_errors=True)
    runs = [timed(dry_run, work, env)[:2] for _ in range(repeats)]
    rows.append(row("pipeline", f"snakemake -n {TARGET} (Snakemake alone)", runs, None))
    build(work, env)  # the dynamics the pair needs
    rows.append(cold_pair(work, tmp))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="the verbs' start-up only, for CI")
    parser.add_argument("--runs", type=int, help="repeats of each measurement (default 5; 3 warm)")
    args = parser.parse_args()
    verb_repeats = args.runs or (2 if args.smoke else 5)
    build_repeats = args.runs or 3
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rows = verb_rows(verb_repeats, tmp)
        if not args.smoke:
            rows += pipeline_rows(build_repeats, tmp)
    frame = pd.DataFrame(rows).fillna({"heavy_imports": "", "detail": ""})
    write_results(frame, "startup", args.smoke)


if __name__ == "__main__":
    main()
