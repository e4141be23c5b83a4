"""``mosys run``'s step of the pipeline: an animation script parsed, run and written as a
trajectory file."""

from __future__ import annotations

import json
from pathlib import Path

from mosys.animation.runner import (
    ScriptRun,
    ScriptSources,
    controller_table_path,
    load_controllers,
    load_programs,
    run_script,
)
from mosys.dynamics.figure_motion import figure_contacts, figure_motion
from mosys.dynamics.load import figure_dynamics
from mosys.io.attributes import string_list
from mosys.io.controller_table import read_controller_table
from mosys.io.trajectory import Trajectory, write_trajectory
from mosys.parsing.script import RunMotorProgram, SwapController, parse_script
from mosys.ssc.grid import control_units, state_unit
from mosys.ssc.regions import regions


def run_animation_script(
    script_path: str | Path,
    controller_dir: str | Path,
    dynamics_dir: str | Path,
    out_path: str | Path,
    dt: float,
    motor_dir: str | Path = "specs/motor",
) -> Trajectory:
    """Run a ``.anim`` script with the tables in ``controller_dir`` and the motor programs in
    ``motor_dir/FIGURE/`` (the object's figure's dynamics from ``dynamics_dir``) and write its
    trajectory: with ``figure_motion`` (and ``contacts`` where the figure has contact points) for
    an articulated figure, with the scene and the parking outcome (``ssc.parking``) for a
    vehicle."""
    script = parse_script(script_path)
    declared = script.declared_figure
    if declared is not None:
        figure, token = declared.figure, declared.figure_token
    else:
        first = next((c for c in script.commands if isinstance(c, SwapController)), None)
        if first is None:  # motor programs alone: only an object line names the figure
            motor = next(c for c in script.commands if isinstance(c, RunMotorProgram))
            raise script.error(
                motor.token,
                f"an 'object {motor.object} figure=FIGURE' line before it (with no swapcon, "
                "nothing else names the object's figure)",
            )
        figure = read_controller_table(controller_table_path(script, first, controller_dir)).figure
        token = first.table_token
    dynamics = figure_dynamics(figure, dynamics_dir, script.error, token)
    sources = ScriptSources(
        dynamics,
        load_controllers(script, controller_dir, dynamics),
        load_programs(script, motor_dir, figure, dynamics),
    )
    run = run_script(script, sources, dt)
    contacts = None
    if getattr(dynamics, "MODEL_KIND", "figure") == "vehicle":
        from mosys.io.car_scene import car_scene_attributes, controller_table_scene
        from mosys.ssc.parking import parking_outcome

        motion = None  # not an articulated figure: no figure_motion (DESIGN.md)
        first_table = next(iter(sources.controllers.values())).table
        scene = controller_table_scene(first_table)
        outcome = parking_outcome(run.t, run.state, run.state_order, scene)
        extra = car_scene_attributes(scene) | outcome.attributes()
    else:
        motion = figure_motion(dynamics, run.t, run.figure_states)
        contacts = figure_contacts(dynamics, run.figure_states)
        extra = {}
    trajectory = Trajectory(
        t=run.t,
        state=run.state,
        control=run.control,
        controller=run.source,
        state_order=run.state_order,
        control_names=run.control_names,
        state_units=tuple(state_unit(dynamics, name)[0] for name in run.state_order),
        control_units=control_units(dynamics, run.control_names),
        controllers=run.sources,
        attrs={
            "script": str(script_path),
            "spec_sha256": script.spec_sha256,
            "figure": figure,
            "dt": dt,
            "controller_kinds": string_list(run.source_kinds),
            "switch_times": [time for time, _ in run.switches],
            "switch_controllers": string_list(name for _, name in run.switches),
            "samples_outside_domain": int(run.outside.sum()),
            "domain_violation_times": [v.t for v in run.domain_violations],
            "domain_violation_controllers": string_list(
                v.controller for v in run.domain_violations
            ),
            "breakpoints": json.dumps(
                [
                    {
                        "box": {name: list(bounds) for name, bounds in b.box.items()},
                        "controller": b.controller,
                        "once": b.once,
                        "line": b.line,
                    }
                    for b in run.breakpoints
                ]
            ),
            "slew": json.dumps(run.slew or {}),
            "simulated_seconds": float(run.t[-1] - run.t[0]),
            **extra,
        },
        motion=motion,
        contacts=contacts,
    )
    write_trajectory(out_path, trajectory)
    print(run_summary(out_path, run, sources, extra))
    return trajectory


def run_summary(out_path: str | Path, run: ScriptRun, sources: ScriptSources, extra: dict) -> str:
    """The command's one line: the motion's length and where it ends. A run whose last
    controller never brought the figure to its destination (a table that converged but cannot
    swing the figure up) wrote its file without a word."""
    head = f"{out_path}: {run.t[-1] - run.t[0]:.2f} s of motion"
    if "parked" in extra:  # a car: its own outcome
        if extra["parked"]:
            return f"{head}; parked after {extra['parking_seconds']:.2f} s"
        hit = extra["collision_index"]
        where = " (its start pose overlaps it: no run from there is free)" if hit == 0 else ""
        return f"{head}; not parked" + (
            f", hit {extra['collided_with']}{where}" if hit >= 0 else ""
        )
    last = run.sources[run.source[-1]]
    if run.source_kinds[run.source[-1]] != "controller":
        return f"{head}; ends under motor program {last}"
    controller = sources.controllers[last]
    boxes = regions(sources.dynamics, controller.arrival_boxes())
    if boxes.membership(run.figure_states[-1]).any():
        return f"{head}; ends at controller {last}'s destination (in its arrival box)"
    return f"{head}; ends away from controller {last}'s destination (not in its arrival box)"
