"""The 1990 paper's Figure 5: the state-space cycles of the pendulum swinging freely (motor off),
closed orbits around hanging at rest, rotations beyond them, and the separatrix between the
two, from ``mosys.dynamics.free_swing``."""

from __future__ import annotations

import math
from pathlib import Path
from types import ModuleType

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from mosys.dynamics.free_swing import free_swing
from mosys.plots.state_space import StateAxis, format_state_axes, plot_state_path
from mosys.plots.style import add_legend, new_figure, plot_style, save_figure

LIBRATION_COLOR = "tab:blue"
ROTATION_COLOR = "tab:green"
SEPARATRIX_COLOR = "black"


def free_swing_figure(dynamics: ModuleType) -> Figure:
    """Figure 5 for a one-coordinate figure (the pendulum): angle across over one period
    (deg, cylindrical), rate up (deg/s)."""
    swing = free_swing(dynamics)
    degrees = np.degrees
    fastest = max(float(np.abs(degrees(orbit[:, 1])).max()) for orbit in swing.rotations)
    reach = 100.0 * math.ceil(fastest * 1.05 / 100.0)  # deg/s, to the next hundred
    axes = (
        StateAxis(dynamics.Q_NAMES[0], "deg", -180.0, 180.0, 360.0),
        StateAxis(dynamics.QD_NAMES[0], "deg/s", -reach, reach, None),
    )

    def wrapped(orbit: np.ndarray) -> np.ndarray:
        points = degrees(orbit)
        points[:, 0] = (points[:, 0] + 180.0) % 360.0 - 180.0
        return points

    with plot_style():
        figure = new_figure(7.6, 6.0)
        ax = figure.add_subplot()
        for orbit in swing.librations:
            plot_state_path(ax, wrapped(orbit), axes, color=LIBRATION_COLOR, linewidth=1.3)
        for orbit in swing.rotations:
            plot_state_path(ax, wrapped(orbit), axes, color=ROTATION_COLOR, linewidth=1.3)
        for half in swing.separatrix:  # and its mirror image: the swing run backwards in time
            for points in (wrapped(half), wrapped(half * np.array([1.0, -1.0]))):
                plot_state_path(ax, points, axes, color=SEPARATRIX_COLOR, linewidth=2.2)
        hanging, upright = degrees(swing.hanging), degrees(swing.upright)
        ax.plot([hanging], [0.0], marker="o", color="tab:red", markersize=7, linestyle="none")
        for angle in (upright, upright - 360.0 if upright > 0 else upright + 360.0):
            ax.plot([angle], [0.0], marker="x", color="tab:red", markersize=9, mew=2)
        format_state_axes(ax, axes)
        ax.set_title(
            "Figure 5: free swing of the unpowered pendulum\n"
            f"separatrix through upright ({upright:.0f}°), "
            f"{degrees(swing.separatrix_rate):.1f}°/s at the bottom"
        )
        legend = [
            (Line2D([], [], color=LIBRATION_COLOR, linewidth=1.5), "closed orbits (swinging)"),
            (Line2D([], [], color=ROTATION_COLOR, linewidth=1.5), "rotations (going over)"),
            (Line2D([], [], color=SEPARATRIX_COLOR, linewidth=2.2), "separatrix"),
            (
                Line2D([], [], marker="o", color="tab:red", linestyle="none"),
                f"hanging at rest ({hanging:.0f}°)",
            ),
            (
                Line2D([], [], marker="x", color="tab:red", mew=2, linestyle="none"),
                "upright (unstable)",
            ),
        ]
        add_legend(figure, legend, ncols=3)
    return figure


def plot_free_swing(dynamics: ModuleType, out_path: str | Path) -> None:
    """Write Figure 5 of ``dynamics`` (a one-coordinate figure) to ``out_path`` (PNG)."""
    save_figure(free_swing_figure(dynamics), out_path)
