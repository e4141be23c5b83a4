"""A ``.ssc`` spec checked against its figure's dynamics and laid out as the arrays the DP
kernels take (``Problem``, SI units): the grid, the sampled controls, the destinations, the
obstacles and the nodes they remove; and what the spec's ``policy`` line asks of the figure.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from mosys.kernels.dp_exits import free_nodes, node_coordinates
from mosys.parsing.controller import ControllerSpec
from mosys.ssc.grid import FigureGrid, control_scale, figure_grid, figure_state_names
from mosys.ssc.obstacles import Obstacles, blocked_reason, spec_obstacles


@dataclass(frozen=True)
class Problem:
    """Everything the DP kernels need for one spec, SI units."""

    spec: ControllerSpec
    grid: FigureGrid
    base_state: np.ndarray  # (S,) values of the state slots the controller leaves out
    control_samples: np.ndarray  # (U, m) every combination of the sampled controls, spec units
    control_scale: np.ndarray  # (m,) spec unit -> SI factor of each control
    control_slot: np.ndarray  # (m,) entry of the model's inputs each control drives
    input_size: int  # how many inputs the model takes
    is_destination: np.ndarray  # (N,) bool: the nodes of any dest line
    destination_label: np.ndarray  # (N,) int64: the first dest line a node matches, else -1
    obstacles: Obstacles
    node_valid: np.ndarray  # (N,) bool: False for nodes removed (collision, outside the domain)


def build_problem(spec: ControllerSpec, dynamics: ModuleType) -> Problem:
    """Check the spec against the figure (SpecError naming the line) and lay out the arrays."""
    names = figure_state_names(dynamics)
    ordered = spec.ordered_state(names)
    grid = figure_grid(
        dynamics,
        tuple(d.name for d in ordered),
        np.array([d.minimum for d in ordered]),
        np.array([d.step for d in ordered]),
        np.array([d.samples for d in ordered]),
        np.array([d.wrap for d in ordered]),
    )
    for k, dimension in enumerate(ordered):
        if dimension.wrap and grid.units[k] == "deg" and abs(dimension.period - 360.0) > 1e-9:
            raise spec.error(
                dimension.token,
                f"an angle whose wrap period samples*step is 360 deg (it is {dimension.period:g})",
            )
    actuators = tuple(dynamics.INPUT_NAMES)
    control_slot = []
    for control in spec.controls:
        if control.name not in actuators or not control.name:
            choices = ", ".join(f"'{a}'" for a in actuators if a)
            raise spec.error(
                control.token, f"an actuator of figure '{spec.figure}' (one of {choices})"
            )
        control_slot.append(actuators.index(control.name))
    check_policy(spec, dynamics)
    samples = np.array(
        list(itertools.product(*(control.values() for control in spec.controls))),
        dtype=np.float64,
    ).reshape(-1, len(spec.controls))
    destination_label = destination_labels(spec, grid)
    is_destination = np.ascontiguousarray(destination_label >= 0)
    base_state = np.zeros(len(names))
    obstacles = spec_obstacles(spec, dynamics, grid)
    node_valid = np.ones(grid.node_count, dtype=np.bool_)
    if obstacles.active:
        free_nodes(
            grid.axis_min,
            grid.axis_step,
            grid.axis_count,
            grid.state_slot,
            base_state,
            *obstacles.kernel_arguments(),
            node_valid,
        )
        blocked = np.flatnonzero(is_destination & ~node_valid)
        if blocked.size:
            line = spec.destinations[int(destination_label[blocked[0]])]
            state = np.empty(len(grid.names))
            node_coordinates(grid.axis_min, grid.axis_step, grid.axis_count, blocked[0], state)
            pose = np.array([state[grid.names.index(n)] for n in ("x", "y", "heading")])
            reason = blocked_reason(spec, obstacles, pose)
            raise spec.error(line[0].token, f"a destination the car can occupy ({reason})")
    return Problem(
        spec=spec,
        grid=grid,
        base_state=base_state,
        control_samples=np.ascontiguousarray(samples),
        control_scale=np.array([control_scale(dynamics, c.name) for c in spec.controls]),
        control_slot=np.array(control_slot, dtype=np.int64),
        input_size=len(actuators),
        is_destination=is_destination,
        destination_label=destination_label,
        obstacles=obstacles,
        node_valid=node_valid,
    )


def destination_labels(spec: ControllerSpec, grid: FigureGrid) -> np.ndarray:
    """(N,) int64: for each node, the index of the first ``dest`` line (file order) whose
    coordinates it matches (dimensions a line does not name are free), -1 for the other nodes.
    The DP's destination is the union of these node sets."""
    label = np.full(grid.shape, -1, dtype=np.int64)
    for number, line in enumerate(spec.destinations):
        destination = np.ones(grid.shape, dtype=bool)
        for entry in line:
            axis = grid.names.index(entry.name)
            on_node = np.zeros(grid.shape[axis], dtype=bool)
            on_node[entry.index] = True
            broadcast = [1] * len(grid.names)
            broadcast[axis] = grid.shape[axis]
            destination &= on_node.reshape(broadcast)
        label[destination & (label < 0)] = number
    return np.ascontiguousarray(label.reshape(-1))


def check_policy(spec: ControllerSpec, dynamics: ModuleType) -> None:
    """SpecError at the ``policy`` line when ``lookahead`` cannot run the figure: it steers and
    brakes a vehicle, and brakes no harder than the ``wheel_accel`` samples reach."""
    if spec.policy is None or spec.policy.kind != "lookahead":
        return
    if getattr(dynamics, "MODEL_KIND", "figure") != "vehicle":
        raise spec.error(
            spec.policy.token, f"'interpolate': figure '{spec.figure}' is not a vehicle"
        )
    accel = [control for control in spec.controls if control.name == "wheel_accel"]
    if not accel:
        raise spec.error(spec.policy.token, "a torq line for wheel_accel (lookahead brakes by it)")
    if not accel[0].minimum < 0.0 < accel[0].maximum:
        raise spec.error(
            spec.policy.token,
            f"a wheel_accel range from below 0 to above 0 (line {accel[0].token.line}): "
            "lookahead brakes by it",
        )


def policy_attributes(spec: ControllerSpec) -> dict:
    """Root attrs ``policy`` (how the table runs) and, for ``lookahead``,
    ``arrival_tolerance`` (JSON object: dest name -> tolerance, spec units) and
    ``arrival_aim`` (the DP's box: the arrival box scaled by it)."""
    if spec.policy is None or spec.policy.kind == "interpolate":
        return {"policy": "interpolate"}
    return {
        "policy": "lookahead",
        "arrival_tolerance": json.dumps(dict(spec.policy.arrival)),
        "arrival_aim": spec.policy.aim,
    }
