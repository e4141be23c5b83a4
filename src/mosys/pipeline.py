"""Steps of the pipeline that join parsing, simulation and file writing (one per ``mosys`` verb
that is more than a single call)."""

from __future__ import annotations

from pathlib import Path

from mosys import __version__
from mosys.animation import controller_table_path, load_controllers, run_script
from mosys.dynamics.load import figure_dynamics
from mosys.dynamics.motion import figure_motion
from mosys.io.controller_table import read_controller_table
from mosys.io.trajectory import Trajectory, write_trajectory
from mosys.parsing.script import SwapController, parse_script
from mosys.ssc.parking import Scene, parking_outcome


def run_animation_script(
    script_path: str | Path,
    controller_dir: str | Path,
    dynamics_dir: str | Path,
    out_path: str | Path,
    dt: float,
) -> Trajectory:
    """Run a ``.anim`` script with the tables in ``controller_dir`` (their figure's dynamics from
    ``dynamics_dir``) and write its trajectory: with ``figure_motion`` for an articulated figure,
    with the scene and the parking outcome (``ssc.parking``) for a vehicle."""
    script = parse_script(script_path)
    first = next(c for c in script.commands if isinstance(c, SwapController))
    figure = read_controller_table(controller_table_path(script, first, controller_dir)).figure
    dynamics = figure_dynamics(figure, dynamics_dir, script.error, first.table_token)
    controllers = load_controllers(script, controller_dir, dynamics)
    run = run_script(script, controllers, dt)
    first_table = next(iter(controllers.values())).table
    if getattr(dynamics, "MODEL_KIND", "figure") == "vehicle":
        motion = None  # not an articulated figure: no figure_motion (DESIGN.md)
        scene = Scene.from_table(first_table)
        outcome = parking_outcome(run.t, run.state, run.state_order, scene)
        extra = scene.attributes() | outcome.attributes()
    else:
        motion = figure_motion(dynamics, run.t, run.figure_states)
        extra = {}
    trajectory = Trajectory(
        t=run.t,
        state=run.state,
        control=run.control,
        controller=run.controller,
        state_order=run.state_order,
        control_names=run.control_names,
        controllers=run.controllers,
        attrs={
            "script": str(script_path),
            "spec_sha256": script.spec_sha256,
            "figure": first_table.figure,
            "dt": dt,
            "switch_times": [time for time, _ in run.switches],
            "switch_controllers": [name for _, name in run.switches],
            "samples_outside_domain": int(run.outside.sum()),
            "simulated_seconds": float(run.t[-1] - run.t[0]),
            "mosys_version": __version__,
            **extra,
        },
        motion=motion,
    )
    write_trajectory(out_path, trajectory)
    return trajectory
