"""Dynamic programming against a peer: pendulum controller A (the 1990 paper's Figure 12 grid,
36 angles x 21 rates) and its 2x, 4x and 8x refinements per axis (72 x 41, 144 x 81, 288 x 161;
same ranges), each solved by mosys and by Drake's ``FittedValueIteration`` in one run, with the
times, sweeps and the cost-to-go of the rod hanging at rest (angle -90 deg, omega 0) side by side.

    python benchmarks/dp_peers.py            # full: the four grids, 3 repeats each
    python benchmarks/dp_peers.py --smoke    # CI: the two smallest grids, 1 repeat

Writes results/benchmarks/dp_peers.{csv,md} (dp_peers_smoke.* with --smoke) and prints them.
Drake is optional (``pip install -e ".[peers]"``); without it the script says so, times mosys
alone and leaves Drake's columns empty.

mosys: each grid is specs/controllers/pendulum/A.ssc with its two ``ssd`` lines changed (no ``dt``
line: mosys's default step), generated in a new process (generation.py's ``generate``) with dynamics
that ``mosys compile`` makes from specs/figures/link1.fig in a temporary directory. One run per
grid, untimed, fills the numba cache and the repeats follow; the time is the DP as the table
reports it, ``transition_seconds + iteration_seconds`` (the cell-exit transitions, parallel over
nodes on every core, and value iteration; the kernels are loaded before, as Drake's are).

Drake: the same rod (1 kg, 1 m, pinned at one end; angle from the horizontal, so -90 deg hangs
down) as a ``SymbolicVectorSystem`` with state (theta, thetadot) in rad, rad/s and input the
torque: theta_ddot = (T - m g (L/2) cos theta) / (m L^2 / 3), the generated link1 module's qdd.
``FittedValueIteration`` runs on Drake's defaults (RK3 integrator, ``convergence_tol`` 1e-4,
``discount_factor`` 1) with the time step of Drake's examples, 0.01 s (a required argument of the
call, not a field of ``DynamicProgrammingOptions``). The state mesh is the same nodes in radians
plus the angle +180 deg, a copy of -180 deg: Drake's periodic boundary condition on theta over
[-pi, pi) needs both ends on the mesh; the inputs are A's 11 torques. Drake evaluates the cost
only at mesh nodes, for the 0.01 s step from each: 1 + 0.1 |T| per second, and 0 within half a
grid step of the destination, that is at the destination node alone. Drake has no terminal
state, so the destination is made one as mosys's is (its cost-to-go fixed at 0): the dynamics
are zero at exactly that node (nowhere else). Without this the destination leaks: no torque
sample holds the rod horizontal (4.9 N m lies between the samples 4 and 6), its neighbours cost
time, and the undiscounted iteration never meets its tolerance (at 36 x 21 the cost-to-go grows
by 0.003 s every sweep, for ever). States that leave the mesh's rate range (+-500 deg/s) are
projected onto its edge by the barycentric interpolation, where mosys discards such exits; the
mesh interpolates on triangles (3 nodes in 2-D), mosys on a cell face's nodes. Drake runs on one
thread and calls the Python cost function once per node and torque. Its sweeps are counted by
``options.visualization_callback`` (called once per sweep); the time is the whole
``FittedValueIteration`` call (the 0.01 s simulations from every node and torque, then value
iteration, which starts from 0 everywhere).

The machine may be shared: each time is the best (minimum) of the repeats, beside their median.

Columns: ``grid`` angle x omega nodes; ``nodes`` mosys's table nodes (Drake's mesh has one more
angle column); ``mosys_dp_s``/``mosys_dp_s_median`` transitions + value iteration, best and median;
``drake_s``/``drake_s_median`` the FittedValueIteration call; ``drake_over_mosys`` Drake's best
over mosys's best; ``mosys_sweeps`` the table's ``iterations``, its Bellman sweeps (mosys's
default tolerance), and ``mosys_policy_sweeps`` its ``policy_sweeps`` (each under one control
per node); ``drake_sweeps`` Drake's (its default, 1e-4 s); ``mosys_value_hanging_s``/
``drake_value_hanging_s`` the cost-to-go, s, at angle -90 deg, omega 0 (a node of every grid).
"""

from __future__ import annotations

import argparse
import logging
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from generation import generate, numba_cache, write_results

from mosys.io.controller_table import read_controller_table

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs/controllers/pendulum/A.ssc"
FIGURE = ROOT / "specs/figures/link1.fig"
FACTORS = (1, 2, 4, 8)  # grid refinement per axis
SMOKE_FACTORS = (1, 2)
ANGLE_NODES, ANGLE_STEP = 36, 10.0  # deg, wrap over 360 deg from -180
OMEGA_NODES, OMEGA_MAX = 21, 500.0  # deg/s, -OMEGA_MAX .. OMEGA_MAX
TORQUES = np.linspace(-10.0, 10.0, 11)  # N m
EFFORT_WEIGHT = 0.1  # s per N m s
HANGING = (-90.0, 0.0)  # deg, deg/s
MASS, LENGTH, GRAVITY = 1.0, 1.0, 9.81  # kg, m, m/s²
DRAKE_TIME_STEP = 0.01  # s, as in Drake's examples
GOAL_RADIUS = 1e-9  # rad, rad/s: the destination node, frozen in Drake's dynamics
DRAKE_COLUMNS = ("drake_s", "drake_s_median", "drake_sweeps", "drake_value_hanging_s")
MISSING_DRAKE = (
    "Drake (pydrake) is not installed: timing mosys alone. "
    'Install it with: pip install -e ".[peers]"'
)


def grid_label(factor: int) -> str:
    """'angle x omega' node counts of the grid ``factor`` times finer per axis than A's."""
    return f"{ANGLE_NODES * factor} x {(OMEGA_NODES - 1) * factor + 1}"


def spec_text(factor: int) -> str:
    """A.ssc with its ``ssd`` lines for the grid ``factor`` times finer per axis."""
    ssd = {
        "omega": f"ssd omega {-OMEGA_MAX:g} {OMEGA_MAX:g} {(OMEGA_NODES - 1) * factor + 1}",
        "angle": f"ssd angle -180 {180 - ANGLE_STEP / factor:g} {ANGLE_NODES * factor} wrap",
    }
    lines = []
    for line in SPEC.read_text().splitlines():
        words = line.split()
        name = words[1] if words[:1] == ["ssd"] else None
        lines.append(ssd.get(name, line))
    return "\n".join(lines) + "\n"


def compile_dynamics(out: Path) -> None:
    """``mosys compile`` link1.fig into ``out``."""
    subprocess.run(
        [sys.executable, "-m", "mosys.cli", "compile", str(FIGURE), "-o", str(out)],
        check=True,
        capture_output=True,
        text=True,
    )


def table_value_at(path: Path, angle: float, omega: float) -> float:
    """The cost-to-go (s) of the table at ``path`` at (angle deg, omega deg/s), bilinear between
    nodes (exact on a node)."""
    table = read_controller_table(path)
    order = [table.state_order.index(name) for name in ("angle", "omega")]
    value = np.transpose(table.value, order)
    angles, omegas = (table.axes[k] for k in order)
    along_omega = [np.interp(omega, omegas, row) for row in value]
    return float(np.interp(angle, angles, along_omega))


def time_mosys(factor: int, repeats: int, dynamics: Path, work: Path, cache: Path | None) -> dict:
    """Generate the grid ``factor`` once untimed, then ``repeats`` times; mosys's columns."""
    spec = work / f"A_x{factor}.ssc"
    spec.write_text(spec_text(factor))
    table = work / f"A_x{factor}.h5"
    generate(dynamics, spec, table, cache)
    runs = [generate(dynamics, spec, table, cache) for _ in range(repeats)]
    seconds = [run["dp_seconds"] for run in runs]
    return {
        "nodes": runs[-1]["nodes"],
        "mosys_dp_s": min(seconds),
        "mosys_dp_s_median": statistics.median(seconds),
        "mosys_sweeps": runs[-1]["iterations"],
        "mosys_policy_sweeps": runs[-1]["policy_sweeps"],
        "mosys_value_hanging_s": table_value_at(table, *HANGING),
    }


def drake_available() -> bool:
    """Whether pydrake imports."""
    try:
        import pydrake  # noqa: F401
    except ImportError:
        return False
    return True


def drake_pendulum() -> Any:
    """The rod as a Drake SymbolicVectorSystem, state (theta, thetadot) rad, rad/s, input the
    torque N m, at rest for good at the destination node (theta = thetadot = 0)."""
    from pydrake.symbolic import Variable, cos, if_then_else
    from pydrake.systems.primitives import SymbolicVectorSystem

    theta, thetadot, torque = Variable("theta"), Variable("thetadot"), Variable("torque")
    inertia = MASS * LENGTH**2 / 3  # about the pin
    thetaddot = (torque - MASS * GRAVITY * LENGTH / 2 * cos(theta)) / inertia
    at_goal = theta * theta + thetadot * thetadot < GOAL_RADIUS**2
    return SymbolicVectorSystem(
        state=[theta, thetadot],
        input=[torque],
        dynamics=[if_then_else(at_goal, 0.0, thetadot), if_then_else(at_goal, 0.0, thetaddot)],
    )


def drake_state_grid(factor: int) -> list[set[float]]:
    """The grid ``factor`` in radians; the angle axis closed with +pi for the periodic boundary."""
    angles = np.linspace(-180.0, 180.0, ANGLE_NODES * factor + 1)
    omegas = np.linspace(-OMEGA_MAX, OMEGA_MAX, (OMEGA_NODES - 1) * factor + 1)
    return [set(np.deg2rad(angles).tolist()), set(np.deg2rad(omegas).tolist())]


def drake_cost(system: Any, factor: int) -> Any:
    """Running cost per second at a context: 1 + K|T|, 0 within half a grid step of the goal."""
    half_steps = np.deg2rad([ANGLE_STEP / factor, 2 * OMEGA_MAX / (OMEGA_NODES - 1) / factor]) / 2
    port = system.get_input_port(0)

    def cost(context: Any) -> float:
        state = context.get_continuous_state_vector()
        if abs(state[0]) < half_steps[0] and abs(state[1]) < half_steps[1]:
            return 0.0
        return 1.0 + EFFORT_WEIGHT * abs(port.Eval(context)[0])

    return cost


def drake_solve(factor: int) -> tuple[float, int, float]:
    """One FittedValueIteration of the grid ``factor``: seconds, sweeps, cost-to-go (s) at
    hanging rest."""
    from pydrake.math import BarycentricMesh
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.controllers import DynamicProgrammingOptions, FittedValueIteration

    system = drake_pendulum()
    simulator = Simulator(system)
    grid = drake_state_grid(factor)
    options = DynamicProgrammingOptions()
    options.periodic_boundary_conditions = [
        DynamicProgrammingOptions.PeriodicBoundaryCondition(0, -math.pi, math.pi)
    ]
    sweeps = []
    options.visualization_callback = lambda sweep, mesh, cost_to_go, policy: sweeps.append(sweep)
    cost = drake_cost(system, factor)
    started = time.perf_counter()
    _, cost_to_go = FittedValueIteration(
        simulator, cost, grid, [set(TORQUES.tolist())], DRAKE_TIME_STEP, options
    )
    seconds = time.perf_counter() - started
    hanging = np.deg2rad(HANGING)
    value = BarycentricMesh(grid).Eval(np.asarray(cost_to_go).reshape(1, -1), hanging)
    return seconds, sweeps[-1], float(value[0])


def time_drake(factor: int, repeats: int) -> dict:
    """``repeats`` FittedValueIterations of the grid ``factor``; Drake's columns."""
    logging.getLogger("drake").setLevel(logging.WARNING)
    runs = [drake_solve(factor) for _ in range(repeats)]
    seconds = [run[0] for run in runs]
    return {
        "drake_s": min(seconds),
        "drake_s_median": statistics.median(seconds),
        "drake_sweeps": runs[-1][1],
        "drake_value_hanging_s": runs[-1][2],
    }


def rounded(number: float | None, digits: int) -> float | None:
    """``number`` rounded, or None (an empty cell) for None."""
    return None if number is None else round(number, digits)


def grid_row(mosys: dict, drake: dict | None, factor: int) -> dict:
    """One table row; Drake's columns empty (None) without Drake."""
    drake = drake or dict.fromkeys(DRAKE_COLUMNS)
    ratio = None if drake["drake_s"] is None else drake["drake_s"] / mosys["mosys_dp_s"]
    return {
        "grid": grid_label(factor),
        "nodes": mosys["nodes"],
        "mosys_dp_s": round(mosys["mosys_dp_s"], 4),
        "mosys_dp_s_median": round(mosys["mosys_dp_s_median"], 4),
        "drake_s": rounded(drake["drake_s"], 4),
        "drake_s_median": rounded(drake["drake_s_median"], 4),
        "drake_over_mosys": rounded(ratio, 2),
        "mosys_sweeps": mosys["mosys_sweeps"],
        "mosys_policy_sweeps": mosys["mosys_policy_sweeps"],
        "drake_sweeps": drake["drake_sweeps"],
        "mosys_value_hanging_s": round(mosys["mosys_value_hanging_s"], 4),
        "drake_value_hanging_s": rounded(drake["drake_value_hanging_s"], 4),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="two smallest grids, for CI")
    args = parser.parse_args()
    factors, repeats = (SMOKE_FACTORS, 1) if args.smoke else (FACTORS, 3)
    with_drake = drake_available()
    if not with_drake:
        print(MISSING_DRAKE)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        dynamics = tmp / "link1.py"
        compile_dynamics(dynamics)
        for factor in factors:
            mosys = time_mosys(factor, repeats, dynamics, tmp, numba_cache(tmp, args.smoke))
            drake = time_drake(factor, repeats) if with_drake else None
            rows.append(grid_row(mosys, drake, factor))
    write_results(pd.DataFrame(rows), "dp_peers", args.smoke)


if __name__ == "__main__":
    main()
