"""Controller generation (paper §3.4–3.5): a ``.ssc`` spec and a figure's dynamics → a table.

The spec is checked and laid out (``ssc.problem``), its exit transitions computed
(``ssc.exits``) and value iteration run (``ssc.solution``); here the table's torques at
rest, its attributes and the HDF5 write. The numeric work is in ``mosys.kernels.dp_exits`` (the
exit transitions), ``mosys.kernels.dp`` (value iteration) and ``mosys.kernels.dp_destinations``
(which destination a node's path ends at).
"""

from __future__ import annotations

import json
import resource
import time
from pathlib import Path
from types import ModuleType

import numpy as np
from numba import float64

from mosys.io.attributes import string_list
from mosys.io.controller_table import ControllerTable, write_controller_table
from mosys.kernels.dp_exits import node_coordinates
from mosys.limits import check_job
from mosys.parsing.controller import ControllerSpec
from mosys.parsing.tokens import location
from mosys.ssc.grid import control_units
from mosys.ssc.problem import Problem, build_problem, policy_attributes
from mosys.ssc.solution import arrival_solution, solve


def forcing_load_seconds(dynamics: ModuleType) -> float:
    """Seconds taken to load the figure's ``forcing`` kernel from numba's cache (on a cold
    cache, to compile it) for ``holding_torques``: kernel time, apart from the generation's;
    0 for a figure without one (a vehicle, which ``holding_torques`` refuses)."""
    if not hasattr(dynamics, "forcing"):
        return 0.0
    started = time.perf_counter()  # for the arguments holding_torques passes, and not run
    dynamics.forcing.compile((float64[::1],) * 3)
    return time.perf_counter() - started


def holding_torques(problem: Problem, dynamics: ModuleType) -> np.ndarray:
    """(D, m) controls, spec units, that hold the figure at rest at each of the D destination
    nodes (``hold``; the nodes of every ``dest`` line): with every rate 0, the actuators
    cancel the generalised forces of gravity, joint stops and contacts, ``-forcing(q, 0, 0)``.
    SpecError at the ``hold`` line when the figure has no equations of motion (a vehicle), a
    destination is not at rest, a coordinate without an actuator would need a force, or a
    torque lies outside its ``torq`` range."""
    spec, grid = problem.spec, problem.grid
    assert spec.hold is not None
    if not hasattr(dynamics, "forcing"):
        raise spec.error(spec.hold, "no 'hold' line: a vehicle is held by braking, not torques")
    n = dynamics.COORDINATE_COUNT
    coordinates = grid.state_slot < n
    several = len(spec.destinations) > 1
    for line in spec.destinations:
        rates_named = {entry.name for entry in line}
        for k, name in enumerate(grid.names):
            if not coordinates[k] and name not in rates_named:
                where = f" (line {line[0].token.line} does not)" if several else ""
                raise spec.error(
                    spec.hold, f"a 'dest' that names the rate '{name}' (= 0) for 'hold'{where}"
                )
    lower = np.array([c.minimum for c in spec.controls])
    upper = np.array([c.maximum for c in spec.controls])
    nodes = np.flatnonzero(problem.is_destination)
    held = np.empty((len(nodes), len(spec.controls)))
    state = np.empty(len(problem.base_state))
    center = np.empty(len(grid.names))
    for row, node in enumerate(nodes):
        node_coordinates(grid.axis_min, grid.axis_step, grid.axis_count, node, center)
        state[:] = problem.base_state
        state[grid.state_slot] = center
        if np.any(state[n:] != 0.0):
            raise spec.error(spec.hold, "a destination at rest (every rate 0) for 'hold'")
        force = -np.asarray(dynamics.forcing(state[:n], state[n:], np.zeros(n)))
        unheld = np.ones(n, dtype=bool)
        unheld[problem.control_slot] = False
        if np.any(np.abs(force[unheld]) > 1e-9):
            name = dynamics.Q_NAMES[int(np.flatnonzero(unheld & (np.abs(force) > 1e-9))[0])]
            raise spec.error(
                spec.hold, f"a destination where '{name}', which has no actuator, is at rest"
            )
        held[row] = force[problem.control_slot] / problem.control_scale
        outside = np.flatnonzero((held[row] < lower) | (held[row] > upper))
        if outside.size:
            control = spec.controls[int(outside[0])]
            raise spec.error(
                spec.hold,
                f"holding torques within the torq range of '{control.name}' "
                f"(it needs {held[row, outside[0]]:.4g})",
            )
    return held


def peak_rss_bytes() -> int:
    """This process's peak resident set size so far, bytes (Linux reports KiB)."""
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024


def figure_attributes(problem: Problem, dynamics: ModuleType) -> dict:
    """Root attrs the contract adds for a vehicle (wheelbase, wheel_radius) and for a spec
    with obstacles (body_outline, obstacles, and this mosys's domain polygon)."""
    attrs: dict = {}
    if getattr(dynamics, "MODEL_KIND", "figure") == "vehicle":
        attrs["wheelbase"] = float(dynamics.WHEELBASE)
        attrs["wheel_radius"] = float(dynamics.WHEEL_RADIUS)
    obstacles = problem.obstacles
    if obstacles.active:
        attrs["body_outline"] = json.dumps(obstacles.outline.tolist())
        attrs["obstacles"] = json.dumps(obstacles.polygons())
        attrs["obstacle_names"] = string_list(obstacles.names)
        attrs["domain"] = json.dumps(obstacles.domain.tolist())
    return attrs


def dp_memory_bytes(spec: ControllerSpec) -> float:
    """About the memory the DP of ``spec`` takes, bytes: per node and control sample, and once
    more for the policy's compact copy (``dp.gather_policy``), the exit (2^(d-1) corners of an
    int32 node and a float32 weight) and the segment's cost (float64); per node, about a dozen
    float64/int64 arrays (values, policy, grid bookkeeping)."""
    nodes = float(np.prod([float(d.samples) for d in spec.state]))
    controls = float(np.prod([float(c.samples) for c in spec.controls]))
    corners = 2.0 ** (len(spec.state) - 1)
    return nodes * ((controls + 1.0) * (8.0 * corners + 8.0) + 8.0 * (12 + len(spec.state)))


def generate_controller(
    spec: ControllerSpec,
    dynamics: ModuleType,
    out_path: str | Path,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    quiet: bool = False,
) -> ControllerTable:
    """Run the DP of a parsed spec on ``dynamics`` and write the table to ``out_path``.
    ``tolerance``/``max_iterations`` override the spec's. Raises SpecError where the spec does
    not fit the figure."""
    started = time.perf_counter()
    last_torq = spec.controls[-1].token
    check_job(
        location(spec.path, last_torq),
        "the DP of this grid and these control samples",
        memory_bytes=dp_memory_bytes(spec),
    )
    problem = build_problem(spec, dynamics)
    tolerance = spec.tolerance if tolerance is None else tolerance
    max_iterations = spec.max_iterations if max_iterations is None else max_iterations
    solution = solve(problem, dynamics, tolerance, max_iterations, spec.dt, quiet=quiet)
    arrival = arrival_solution(problem, dynamics, solution, tolerance, max_iterations, quiet)
    kernel_load_seconds = solution.kernel_load_seconds
    if arrival is not None and arrival is not solution:
        kernel_load_seconds += arrival.kernel_load_seconds
    grid = problem.grid
    lower = np.array([c.minimum for c in spec.controls])
    upper = np.array([c.maximum for c in spec.controls])
    torque = problem.control_samples[solution.best_control]
    unreachable = ~np.isfinite(solution.value)
    torque[unreachable] = np.clip(0.0, lower, upper)
    if spec.hold is not None:
        kernel_load_seconds += forcing_load_seconds(dynamics)
        torque[problem.is_destination] = holding_torques(problem, dynamics)
    generation_seconds = time.perf_counter() - started - kernel_load_seconds
    table = ControllerTable(
        state_order=grid.names,
        control_names=tuple(c.name for c in spec.controls),
        control_units=control_units(dynamics, tuple(c.name for c in spec.controls)),
        axes=grid.axis_values(),
        axis_units=grid.units,
        wrap=tuple(bool(w) for w in grid.wrap),
        torque=torque.reshape(grid.shape + (len(spec.controls),)),
        value=solution.value.reshape(grid.shape),
        control_min=lower,
        control_max=upper,
        effort_weight=np.array([c.effort_weight for c in spec.controls]),
        dest=spec.destination_values(),
        figure=spec.figure,
        dead_end=solution.dead_end.reshape(grid.shape) if spec.known_weight else None,
        destinations=None
        if solution.destination_index is None
        else tuple(spec.all_destination_values()),
        destination_index=None
        if solution.destination_index is None
        else solution.destination_index.reshape(grid.shape),
        arrival_value=None if arrival is None else arrival.value.reshape(grid.shape),
        attrs={
            "spec_sha256": spec.spec_sha256,
            "generation_seconds": generation_seconds,
            "transition_seconds": solution.transition_seconds,
            "iteration_seconds": solution.iteration_seconds,
            "kernel_load_seconds": kernel_load_seconds,
            "iterations": solution.iterations,
            "policy_sweeps": solution.policy_sweeps,
            "residual": solution.residual,
            "converged": bool(solution.residual < tolerance),
            "tolerance": tolerance,
            "dt": spec.dt,
            "control_samples": np.array([c.samples for c in spec.controls], dtype=np.int64),
            "unreachable_nodes": int((unreachable & ~solution.dead_end).sum()),
            "dead_end_nodes": int(solution.dead_end.sum()),
            "removed_nodes": int((~problem.node_valid).sum()),
            "minimum_known_weight": spec.known_weight,
            "table_states": int(problem.node_valid.sum()),
            "peak_rss_bytes": peak_rss_bytes(),
            "hold": spec.hold is not None,
            **figure_attributes(problem, dynamics),
            **policy_attributes(spec),
        },
    )
    write_controller_table(out_path, table)
    return table
