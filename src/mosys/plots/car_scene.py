"""The self-parking car's scene, as every car plot draws it (``mosys.plots.car``'s manoeuvres,
``mosys.plots.car_starts``'s start grids): the scene read from a file's attributes, the view's
limits, a figure of panels to scale, and the obstacles, the domain and the destination drawn.

Everything is drawn in metres in the world frame, equal aspect. Car states are in spec units and
located by name through ``state_order``: x, y (m) of the reference point midway between the front
wheels; heading (deg, 0 along +x, counter-clockwise); steer (deg, the road wheels' angle, positive
left); speed (m/s).
"""

from __future__ import annotations

from collections.abc import Container, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon
from numpy.typing import ArrayLike

from mosys.errors import InputError
from mosys.io.car_scene import CarScene, read_car_scene
from mosys.plots.style import (
    DESTINATION_COLOR,
    LEGEND_ROW,
    MARGIN_BOTTOM,
    MARGIN_RIGHT,
    PlotInputError,
    fit_aspect,
    minus_signs,
    new_figure,
)

COLUMNS = 3  # panels per row
PANEL_WIDTH = 3.3  # inches of one panel's data area in a multi-panel figure
SINGLE_PANEL_WIDTH = 6.0  # inches of the data area when there is one panel
PANEL_ASPECT_RANGE = (0.35, 1.25)  # height / width of a panel: its limits widen to stay inside
VIEW_MARGIN = 1.5  # m: obstacles are shown this far beyond the region the cars use
EDGE_MARGIN = 0.4  # m: blank border around everything shown

STATE_UNITS = {"x": "m", "y": "m", "heading": "deg", "steer": "deg", "speed": "m/s"}
SCENE_ATTRS = ("body_outline", "obstacles", "obstacle_names", "destination")

OBSTACLE_FACE, OBSTACLE_EDGE = "0.72", "0.45"
DOMAIN_STYLE = {"edgecolor": "0.35", "linestyle": "--", "linewidth": 1.0}
FAILURE_COLOR = "#d62728"  # the collision outline, the FAILED titles, the collision markers
TITLE_SIZE = 10.0  # pt, panel titles
SUPTITLE_SIZE = 12.0  # pt
OBSTACLE_LABEL_SIZE = 8.0  # pt


def check_present(path: str | Path, kind: str, names: Sequence[str], present: Container) -> None:
    """PlotInputError naming those of ``names`` (a file's required attributes or datasets) that
    ``present`` lacks: the file at ``path`` is not a ``kind``."""
    absent = [name for name in names if name not in present]
    if absent:
        raise PlotInputError(f"{path}: not a {kind}: missing {', '.join(absent)}")


def read_scene(path: str | Path, attrs: Mapping) -> CarScene:
    """The body outline, obstacles and destination from a file's root attributes."""
    try:
        return read_car_scene(attrs, str(path))
    except InputError as error:
        raise PlotInputError(str(error)) from None


def state_columns(
    path: str | Path, state_order: Sequence[str], required: Sequence[str]
) -> dict[str, int]:
    """Column index of each state variable by name; PlotInputError naming the absent ones."""
    absent = [name for name in required if name not in state_order]
    if absent:
        raise PlotInputError(
            f"{path}: state_order {list(state_order)} lacks {', '.join(absent)}: not a car state"
        )
    return {name: k for k, name in enumerate(state_order)}


def place_outline(
    outline: np.ndarray, x: ArrayLike, y: ArrayLike, heading: ArrayLike
) -> np.ndarray:
    """An outline (V, 2) m in the car's frame placed at poses x, y (m), heading (deg), scalars
    or (K,) arrays: (V, 2) or (K, V, 2) m in the world frame."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    angle = np.radians(np.asarray(heading, dtype=np.float64))
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    u, v = outline[:, 0], outline[:, 1]
    return np.stack([x[..., None] + c * u - s * v, y[..., None] + s * u + c * v], axis=-1)


def describe_value(name: str, value: float) -> str:
    """A state value for a title: ``−30°``, ``3.5 m``, ``0.0 m/s`` (a true minus sign)."""
    unit = STATE_UNITS.get(name, "")
    whole = unit == "deg" and abs(value - round(value)) < 0.05
    value = round(value, 0 if whole else 1) + 0.0  # + 0.0: no "-0"
    text = f"{value:.0f}°" if whole else f"{value:.1f}°" if unit == "deg" else f"{value:.1f} {unit}"
    return minus_signs(text.rstrip())


# --------------------------------------------------------------------------- layout and drawing


def bounds(points: np.ndarray) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] of points (..., 2)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return np.array([points.min(axis=0), points.max(axis=0)])


def view_limits(car_points: np.ndarray, obstacles: Sequence[np.ndarray]) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] m of the view: the region the cars use (``car_points``
    (..., 2) m: outlines, path, destination) united with the obstacles' extents clipped to that
    region widened by VIEW_MARGIN, plus EDGE_MARGIN all round, then widened in x or y to keep
    the view's height / width within PANEL_ASPECT_RANGE (``fit_aspect``)."""
    cars = bounds(car_points)
    window = cars + [[-VIEW_MARGIN], [VIEW_MARGIN]]
    limits = cars.copy()
    for polygon in obstacles:
        box = bounds(polygon)
        low, high = np.maximum(box[0], window[0]), np.minimum(box[1], window[1])
        if np.all(high >= low):
            limits = np.array([np.minimum(limits[0], low), np.maximum(limits[1], high)])
    limits += [[-EDGE_MARGIN], [EDGE_MARGIN]]
    return fit_aspect(limits, PANEL_ASPECT_RANGE)


@dataclass(frozen=True)
class PanelLayout:
    """A figure of car scene panels: the figure, its panels in reading order and the colour
    bar's axes (None without one)."""

    figure: Figure
    panels: list[Axes]
    colorbar: Axes | None


def panel_figure(
    count: int,
    limits: np.ndarray,
    suptitle_lines: int,
    title_lines: int,
    legend_rows: int,
    colorbar: bool = False,
    dpi: float | None = None,
    columns: int = COLUMNS,
) -> PanelLayout:
    """A figure of ``count`` equal-aspect panels on a grid of up to ``columns`` columns, sized in
    inches so that each panel's box has the aspect of ``limits``: y tick labels on the left
    column only (all panels share the limits), x labels under the lowest panel of each column,
    room above for the figure's title and each panel's title, below for a legend, and on the
    right for a colour bar."""
    columns = min(columns, count)
    rows = -(-count // columns)
    (x0, y0), (x1, y1) = limits
    width = SINGLE_PANEL_WIDTH if count == 1 else PANEL_WIDTH
    height = width * (y1 - y0) / (x1 - x0)
    title_space = title_lines * TITLE_SIZE * 1.45 / 72 + 0.1
    left, gap_x, gap_y = 0.75, 0.22, title_space + 0.42
    top = 0.12 + suptitle_lines * SUPTITLE_SIZE * 1.5 / 72 + title_space
    bottom = MARGIN_BOTTOM + (LEGEND_ROW * (legend_rows + 1) if legend_rows else 0.0)
    right = MARGIN_RIGHT + (1.05 if colorbar else 0.0)
    fig_width = left + columns * width + (columns - 1) * gap_x + right
    fig_height = top + rows * height + (rows - 1) * gap_y + bottom
    figure = new_figure(fig_width, fig_height)
    if dpi is not None:
        figure.set_dpi(dpi)
    panels = []
    for k in range(count):
        row, column = divmod(k, columns)
        x = left + column * (width + gap_x)
        y = fig_height - top - (row + 1) * height - row * gap_y
        ax = figure.add_axes(
            (x / fig_width, y / fig_height, width / fig_width, height / fig_height)
        )
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal", adjustable="box")
        if column == 0:
            ax.set_ylabel("y (m)")
        else:
            ax.tick_params(labelleft=False)
        if k + columns >= count:
            ax.set_xlabel("x (m)")
        panels.append(ax)
    bar = None
    if colorbar:
        x = left + columns * width + (columns - 1) * gap_x + 0.2
        y = bottom
        span = fig_height - top - bottom
        bar = figure.add_axes((x / fig_width, y / fig_height, 0.16 / fig_width, span / fig_height))
    return PanelLayout(figure, panels, bar)


def suptitle(figure: Figure, text: str) -> None:
    """The figure's title, its top 0.08 in below the figure's top edge whatever its height."""
    height = figure.get_size_inches()[1]
    figure.suptitle(text, y=1 - 0.08 / height, va="top", fontsize=SUPTITLE_SIZE)


def panel_title(
    ax: Axes, first_line: str, outcome: str | None = None, failed: bool = False
) -> None:
    """A panel's title: ``first_line`` in black over an ``outcome`` line, red when ``failed``
    (the outcome text carries the gid ``outcome``)."""
    if outcome is None:
        ax.set_title(first_line, fontsize=TITLE_SIZE)
        return
    ax.set_title(first_line, fontsize=TITLE_SIZE, pad=5 + 1.3 * TITLE_SIZE)
    ax.annotate(
        outcome,
        xy=(0.5, 1.0),
        xycoords="axes fraction",
        xytext=(0, 4),
        textcoords="offset points",
        ha="center",
        va="bottom",
        fontsize=TITLE_SIZE,
        color=FAILURE_COLOR if failed else "black",
        fontweight="bold" if failed else "normal",
        gid="outcome",
    )


def domain_entries(scenes: Sequence[CarScene]) -> list[tuple[object, str]]:
    """The legend entry of the domain, if any scene has one."""
    if not any(len(scene.domain) >= 3 for scene in scenes):
        return []
    line = Line2D([], [], color=DOMAIN_STYLE["edgecolor"], linestyle="--", linewidth=1.0)
    return [(line, "domain (the front-axle midpoint stays in it)")]


def draw_scene(ax: Axes, scene: CarScene, limits: np.ndarray) -> None:
    """Obstacles as grey polygons, each named where its name fits in the part in view, and the
    destination as the car's outline, dotted, at the destination pose. Call once the axes are
    placed: the name's size in metres comes from the axes' size in inches."""
    axes_inches = ax.get_position().width * ax.figure.get_size_inches()[0]
    metres_per_point = (limits[1, 0] - limits[0, 0]) / (axes_inches * 72)
    if len(scene.domain) >= 3:  # Figure 17's dashed region: where the reference point stays
        ax.add_patch(Polygon(scene.domain, closed=True, fill=False, zorder=1.2, **DOMAIN_STYLE))
    for name, polygon in zip(scene.obstacle_names, scene.obstacles, strict=True):
        ax.add_patch(
            Polygon(
                polygon,
                closed=True,
                facecolor=OBSTACLE_FACE,
                edgecolor=OBSTACLE_EDGE,
                linewidth=0.8,
                zorder=1,
            )
        )
        box = bounds(polygon)
        low, high = np.maximum(box[0], limits[0]), np.minimum(box[1], limits[1])
        label = np.array([0.62 * len(name) + 1, 1.6]) * OBSTACLE_LABEL_SIZE * metres_per_point
        if np.all(high - low > label):
            centre = (low + high) / 2
            ax.text(
                *centre,
                name,
                ha="center",
                va="center",
                fontsize=OBSTACLE_LABEL_SIZE,
                color="0.15",
                clip_on=True,
                zorder=6.5,  # over the start map's markers (6), which hid it
                bbox={"boxstyle": "round,pad=0.2", "facecolor": OBSTACLE_FACE, "edgecolor": "none"},
            )
    destination = scene.destination
    goal = place_outline(
        scene.body_outline, destination["x"], destination["y"], destination["heading"]
    )
    ax.add_patch(
        Polygon(
            goal,
            closed=True,
            fill=False,
            edgecolor=DESTINATION_COLOR,
            linestyle=":",
            linewidth=1.4,
            zorder=4,
        )
    )


def scene_points(scene: CarScene) -> np.ndarray:
    """The car's outline (corners, 2) m placed at the scene's destination (for the view's
    limits)."""
    d = scene.destination
    return place_outline(scene.body_outline, d["x"], d["y"], d["heading"])
