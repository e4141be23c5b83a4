"""Controls against time for several animation scripts on one plot (the 1990 paper's §5: the
torque jumps at each controller exchange, and a slew limit turns the jumps into ramps): one
control over time above, its rate of change below with each script's slew limit drawn as a
dashed line."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from mosys.io.trajectory import Trajectory, read_trajectory
from mosys.plots.style import (
    PlotInputError,
    add_legend,
    axis_label,
    new_figure,
    plot_style,
    save_figure,
    script_file_name,
    unit_text,
)

SCRIPT_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
RATE_CLIP = 5.0  # the rate panel shows up to this many times the largest slew limit


def controls_figure(trajectory_paths: Sequence[str | Path], control: str | None = None) -> Figure:
    """``control`` (default: the first control of the first trajectory) against time in each
    trajectory, and its rate of change (unit per second, finite differences between samples)
    with the slew limits the trajectories record (root attr ``slew``)."""
    if not trajectory_paths:
        raise PlotInputError("plot controls: give at least one trajectory")
    trajectories = [read_trajectory(path) for path in trajectory_paths]
    name = control or trajectories[0].control_names[0]
    for trajectory, path in zip(trajectories, trajectory_paths, strict=True):
        if name not in trajectory.control_names:
            raise PlotInputError(f"{path}: no control '{name}' (it has {trajectory.control_names})")
    unit = _control_unit(trajectories[0], name)
    limits = [json.loads(str(t.attrs.get("slew", "{}"))).get(name) for t in trajectories]
    with plot_style():
        figure = new_figure(8.0, 6.6)
        top, bottom = figure.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
        legend = []
        largest_rate, rates = 0.0, 0
        for k, (trajectory, path, limit) in enumerate(
            zip(trajectories, trajectory_paths, limits, strict=True)
        ):
            color = SCRIPT_COLORS[k % len(SCRIPT_COLORS)]
            t = trajectory.t
            value = trajectory.control[:, trajectory.control_names.index(name)]
            lone = t.size == 1  # a run that began at its destination: a point, not a line
            marker = "o" if lone else None
            top.plot(t, value, color=color, linewidth=1.4, drawstyle="steps-post", marker=marker)
            moving = np.diff(t) > 0
            rate = np.diff(value)[moving] / np.diff(t)[moving]
            bottom.plot(t[1:][moving], np.abs(rate), color=color, linewidth=1.0)
            rates += rate.size
            largest_rate = max(largest_rate, float(np.abs(rate).max(initial=0.0)))
            notes = [f"slew limit {limit:g} {unit}/s" if limit is not None else "no limit"]
            notes += ["a single sample"] if lone else []
            label = f"{script_file_name(trajectory, path)} ({'; '.join(notes)})"
            legend.append((Line2D([], [], color=color, linewidth=2), label))
            if limit is not None:
                bottom.axhline(limit, color=color, linestyle="--", linewidth=1.4)
            for switch in np.atleast_1d(trajectory.attrs.get("switch_times", []))[1:]:
                top.axvline(float(switch), color=color, linewidth=0.6, alpha=0.35)
        if not rates:
            bottom.text(
                0.5,
                0.5,
                "no rate of change: no two samples apart in time",
                transform=bottom.transAxes,
                ha="center",
                va="center",
                color="0.3",
            )
        finite = [limit for limit in limits if limit is not None]
        if finite:
            legend.append(
                (Line2D([], [], color="0.3", linestyle="--"), "slew limit (in the script's colour)")
            )
            ceiling = min(largest_rate, RATE_CLIP * max(finite)) * 1.1
            bottom.set_ylim(0.0, ceiling if ceiling > 0 else 1.0)
            bottom.set_title(
                f"|rate of change| (clipped at {RATE_CLIP:g}× the largest limit; an unlimited "
                "jump is one step)",
                fontsize="small",
            )
        top.set_ylabel(axis_label(name, unit))
        bottom.set_ylabel(f"|d{name}/dt| ({unit}/s)")
        bottom.set_xlabel("time t (s)")
        scripts = " and ".join(
            script_file_name(t, p) for t, p in zip(trajectories, trajectory_paths, strict=True)
        )
        top.set_title(f"{name} against time: {scripts}\nthin lines: controller exchanges")
        add_legend(figure, legend, ncols=1)
    return figure


def _control_unit(trajectory: Trajectory, name: str) -> str:
    """The unit of a control as the trajectory's ``/control`` records it (a car's steer_rate
    deg/s); a file written before it recorded them: a torque's N·m, else "spec unit"."""
    if trajectory.control_units is not None:
        return unit_text(trajectory.control_units[trajectory.control_names.index(name)])
    return "N·m" if "torque" in name else "spec unit"


def plot_controls(
    trajectory_paths: Sequence[str | Path], out_path: str | Path, control: str | None = None
) -> None:
    """Write ``controls_figure`` to ``out_path`` (PNG)."""
    save_figure(controls_figure(trajectory_paths, control), out_path)
