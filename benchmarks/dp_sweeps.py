"""DP sweep benchmark: value iteration's sweeps (``kernels.dp``) over exit tables larger than the
processor's caches, with and without the cache hints (``kernels.prefetch``), in one block and in
two (``blocked_gauss_seidel_sweep``, ``blocked_policy_sweep``).

    python benchmarks/dp_sweeps.py            # park.ssc, heading every 5 deg: 840,840 nodes
    python benchmarks/dp_sweeps.py --smoke    # CI: y to 3.15 m, heading every 15 deg

The tables are park.ssc's scene and controls, twice: with exit shapes of every node's own (the
motion classes off, as for a model without ignorable axes: 1.2 GB of shapes on the full grid,
where ``prefetch_pays``), then with shapes shared by the motion classes, as ``mosys dp`` builds
the car's (a few MB: the cost tables and values are what the sweeps stream). Value iteration
runs to the spec's tolerance first (untimed); each timed sweep then starts from a copy of those
values, once in each of the 2**5 orders of ``sweep_order``, and the policy sweeps follow the
controls of its last Bellman sweep (``gather_policy``). The sweeps are the DP's own kernels,
loaded from the install's numba cache.

Writes results/benchmarks/dp_sweeps.{csv,md} (dp_sweeps_smoke.* with --smoke) and prints them.
Columns: ``shapes`` (own or shared), ``sweep`` (bellman or policy), ``blocks`` (1 or 2),
``hints`` (whether the sweep asked the cache ahead), ``ms_mean``/``ms_min`` over the orders, and
``hints_speed_up`` (the same sweep without hints over with them, by mean).
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import numpy as np
import pandas as pd
from generation import write_results

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs/controllers/car/park.ssc"
GRIDS = {  # ssd NAME MIN MAX SAMPLES replaced in park.ssc, every dest value on a node
    False: {"heading": "-45 60 22"},
    True: {"y": "0.9 3.15 19", "heading": "-45 60 8"},  # 223,440 nodes: still two blocks
}


def spec_text(smoke: bool) -> str:
    """park.ssc with the axes of GRIDS[smoke]."""
    text = SPEC.read_text()
    for name, axis in GRIDS[smoke].items():
        text, count = re.subn(rf"^ssd {name} .*$", f"ssd {name} {axis}", text, flags=re.M)
        assert count == 1, name
    return text


def tables(smoke: bool, work: Path, shared: bool) -> tuple:
    """(problem, transitions, values): the exit tables, each node's own or (``shared``) shared by
    the motion classes as ``mosys dp`` builds them, and the converged cost-to-go; the car's
    compiled figure is ``work``/car.py."""
    from mosys.dynamics.load import figure_dynamics
    from mosys.kernels.dp import discard_poorly_known_exits
    from mosys.kernels.dp_exits import exit_transitions_template
    from mosys.kernels.specialise import specialise
    from mosys.parsing.controller import parse_controller_spec
    from mosys.ssc import solution
    from mosys.ssc.exits import MotionClasses, compute_transitions, exit_transition_arguments
    from mosys.ssc.problem import build_problem

    path = work / "park_sweeps.ssc"
    path.write_text(spec_text(smoke))
    spec = parse_controller_spec(path)
    dynamics = figure_dynamics(spec.figure, work, spec.error, spec.figure_token)
    problem = build_problem(spec, dynamics)
    exits = specialise(exit_transitions_template, dynamics, parallel=True)
    arguments = exit_transition_arguments(problem, dynamics, spec.dt)
    classes = MotionClasses.of(problem, dynamics) if shared else None
    solution.load_kernels(exits, arguments, problem, classes)
    transitions = compute_transitions(
        exits, arguments, problem, problem.node_valid, classes, quiet=False
    )
    reachable = solution.reachable_nodes(
        transitions, problem.is_destination, problem.grid.axis_count
    )
    discard_poorly_known_exits(*transitions.arrays(), reachable, spec.known_weight)
    value, *_ = solution.value_iteration(
        problem, transitions, reachable, spec.tolerance, spec.max_iterations, quiet=False
    )
    return problem, transitions, value


def time_sweeps(problem, transitions, value: np.ndarray) -> pd.DataFrame:
    """Each sweep kernel, one block and two, with and without hints, once in every order."""
    from mosys.kernels.dp import (
        DEAD_END_SECONDS,
        blocked_gauss_seidel_sweep,
        blocked_policy_sweep,
        copy_block_edges,
        gather_policy,
        gauss_seidel_sweep,
        policy_sweep,
        policy_tables,
        prefetch_pays,
        sweep_order,
    )
    from mosys.ssc.solution import sweep_blocks

    grid, arrays = problem.grid, transitions.arrays()
    order = np.empty(grid.node_count, dtype=np.int64)
    control = np.zeros(grid.node_count, dtype=np.int64)
    blocks, edges = sweep_blocks(grid.axis_count, transitions)
    largest = np.empty(blocks.shape[0] - 1)
    sweep_order(grid.axis_count, 0, order)
    gauss_seidel_sweep(*arrays, problem.is_destination, value.copy(), order, np.inf, False, control)
    policy = policy_tables(transitions.segment_cost.shape[0], transitions.exit_index.shape[2])
    gather_policy(*arrays, problem.is_destination, value, control, *policy)
    row_of = transitions.row_of

    def run(sweep: str, blocked: bool, hints: bool, v: np.ndarray) -> None:
        if blocked:
            copy_block_edges(v, snapshot := v.copy(), edges)
        if sweep == "bellman" and blocked:
            blocked_gauss_seidel_sweep(
                *arrays, problem.is_destination, v, snapshot, order, blocks, largest,
                DEAD_END_SECONDS, hints, control.copy(),
            )  # fmt: skip
        elif sweep == "bellman":
            gauss_seidel_sweep(
                *arrays, problem.is_destination, v, order, DEAD_END_SECONDS, hints, control.copy()
            )
        elif blocked:
            blocked_policy_sweep(
                *policy[:5], row_of, v, snapshot, order, blocks, largest, DEAD_END_SECONDS, hints
            )
        else:
            policy_sweep(*policy[:5], row_of, v, order, DEAD_END_SECONDS, hints)

    rows = []
    orders = 2 ** len(grid.axis_count)
    for sweep in ("bellman", "policy"):
        for blocked in (False, True):
            if blocked and edges is None:
                continue
            for hints in (False, True):
                run(sweep, blocked, hints, value.copy())  # loads the kernel
                seconds = []
                for k in range(orders):
                    sweep_order(grid.axis_count, k, order)
                    v = value.copy()
                    started = time.perf_counter()
                    run(sweep, blocked, hints, v)
                    seconds.append(time.perf_counter() - started)
                rows.append(
                    {
                        "sweep": sweep,
                        "blocks": 2 if blocked else 1,
                        "hints": hints,
                        "ms_mean": round(1e3 * float(np.mean(seconds)), 2),
                        "ms_min": round(1e3 * min(seconds), 2),
                    }
                )
    frame = pd.DataFrame(rows)
    plain = frame[~frame.hints].set_index(["sweep", "blocks"]).ms_mean
    frame["hints_speed_up"] = [
        round(plain[(s, b)] / m, 3)
        for s, b, m in zip(frame.sweep, frame.blocks, frame.ms_mean, strict=True)
    ]
    frame.insert(0, "shapes", "own" if transitions.shape_row_of is None else "shared")
    frame["nodes"] = grid.node_count
    frame["exit_shapes_mb"] = round(
        (transitions.exit_index.nbytes + transitions.exit_weight.nbytes) / 1e6, 1
    )
    frame["hints_pay"] = bool(prefetch_pays(transitions.exit_index, transitions.exit_weight))
    return frame


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--smoke", action="store_true", help="CI: a small grid")
    args = parser.parse_args()
    import tempfile

    from mosys.dynamics.compile import compile_figure

    frames = []
    with tempfile.TemporaryDirectory() as tmp:  # its own car.py: results/ may hold none
        compile_figure(ROOT / "specs/figures/car.fig", Path(tmp) / "car.py")
        for shared in (False, True):
            problem, transitions, value = tables(args.smoke, Path(tmp), shared)
            frames.append(time_sweeps(problem, transitions, value))
            del problem, transitions, value
    write_results(pd.concat(frames, ignore_index=True), "dp_sweeps", args.smoke)


if __name__ == "__main__":
    main()
