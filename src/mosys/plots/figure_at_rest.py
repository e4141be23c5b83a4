"""A 3-D figure at rest, drawn for the README (``docs/figures``) and beside each 3-D motion's
plots: its first pose large, seen obliquely over the floor with every rod named, and small from
its right side, its front and above, to one scale (``plot_figure_at_rest``;
``plot_result_at_rest`` draws a 3-D BSR result's).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from mosys.io.trajectory import FigureMotion
from mosys.plots.bsr_results import (
    read_result,
)
from mosys.plots.scene3d import (
    FLOOR_DARK,
    FLOOR_EDGE,
    FLOOR_MARGIN,
    FRONT,
    KEY_SIZE,
    SIDE,
    TOP,
    VIEW,
    Camera,
    camera_text,
    draw_axes_key,
    draw_floor,
    draw_shadows,
    floor_cells,
    floor_corners,
    pose_size,
    project,
)
from mosys.plots.style import (
    JOINT_SIZE,
    MARGIN_BOTTOM,
    MARGIN_RIGHT,
    MARGIN_TOP,
    OUTLINE,
    ROD_WIDTH,
    TITLE_LINE,
    PlotInputError,
    controller_colors,
    new_figure,
    plot_style,
    save_figure,
    spread_labels,
    text_color,
)

REST_VIEWS = (("side", SIDE), ("front", FRONT), ("top", TOP))  # the small views, top to bottom
REST_TITLES = {"side": "from its right side", "front": "from its front", "top": "from above"}
# the small views' axes: the world coordinate along the picture's right and up axes
REST_AXES = {"side": ("x (m)", "y (m)"), "front": ("−z (m)", "y (m)"), "top": ("x (m)", "−z (m)")}
REST_MAIN = (7.4, 6.6)  # inches: the oblique view's width and greatest height
REST_PAD = 1.2  # inches of the oblique view's height above and below its drawing
REST_SMALL = 1.75  # inches: the small views' side
REST_SMALL_GAP = 0.8  # inches above each small view: its title and the x label of the one above
REST_SMALL_LEFT = 0.75  # inches left of the small views: their y labels
REST_SMALL_LABELS = 0.45  # inches above a small view for its title, below it for its x label
REST_MAIN_TITLE = 0.3  # inches above the oblique view, where it is as wide as the figure
LABEL_COLUMN = 1.3  # inches left and right of the oblique view's drawing for the rod names
LABEL_SIZE = 9.0  # pt
LABEL_GAP = 0.2  # inches between two rod names' middles
FOOT_MARKER = "^"


@dataclass(frozen=True)
class RestLayout:
    """Where ``figure_at_rest_figure`` puts its views, in inches: the figure's ``size`` (width,
    height), the oblique view's box ``main`` and the small views' ``small`` (side, front, top),
    each (left, bottom, width, height) from the figure's bottom left corner."""

    size: tuple[float, float]
    main: tuple[float, float, float, float]
    small: tuple[tuple[float, float, float, float], ...]


def rest_layout(span: np.ndarray, title_lines: int) -> RestLayout:
    """The views of a figure at rest whose oblique drawing (floor included) spans ``span``
    (width, height, any unit) under a title of ``title_lines`` lines. The small views stand in
    a column right of the oblique view or, where that leaves less blank, in a row under it, the
    oblique view then as wide as the figure: a long, low figure (Rex, Cujo) drawn in the
    column's narrow view left wide empty bands above and below it; a tall one (Bob) keeps the
    column."""
    top = MARGIN_TOP + 0.1 + TITLE_LINE * title_lines
    main_width, most = REST_MAIN
    width = 0.2 + main_width + REST_SMALL_LEFT + REST_SMALL + MARGIN_RIGHT + 0.1
    small_row = REST_SMALL + 2 * REST_SMALL_LABELS  # inches: a small view, its title and labels

    def main_height(view_width: float) -> float:  # as tall as the drawing needs at that width
        return min(most, span[1] / span[0] * (view_width - 2 * LABEL_COLUMN) + REST_PAD)

    column_room = max(most, 3 * (REST_SMALL + REST_SMALL_GAP))  # inches under the title
    row_width = width - 0.2 - MARGIN_RIGHT
    row_main = main_height(row_width)
    if REST_MAIN_TITLE + row_main + small_row < column_room + MARGIN_BOTTOM:
        height = top + REST_MAIN_TITLE + row_main + small_row
        slot = row_width / len(REST_VIEWS)
        small = tuple(
            (0.2 + k * slot + REST_SMALL_LEFT, REST_SMALL_LABELS, REST_SMALL, REST_SMALL)
            for k in range(len(REST_VIEWS))
        )
        main = (0.2, small_row, row_width, row_main)
        return RestLayout((width, height), main, small)
    height = top + column_room + MARGIN_BOTTOM
    column_main = main_height(main_width)  # centred in the room
    main = (0.2, MARGIN_BOTTOM + (column_room - column_main) / 2, main_width, column_main)
    left = 0.2 + main_width + REST_SMALL_LEFT
    small = tuple(
        (
            left,
            height - top - (k + 1) * (REST_SMALL + REST_SMALL_GAP) + REST_SMALL_LABELS,
            REST_SMALL,
            REST_SMALL,
        )
        for k in range(len(REST_VIEWS))
    )
    return RestLayout((width, height), main, small)


def _figure_box(box: tuple[float, float, float, float], size: tuple[float, float]) -> tuple:
    """``box`` (left, bottom, width, height) inches as fractions of a figure of ``size``."""
    width, height = size
    return (box[0] / width, box[1] / height, box[2] / width, box[3] / height)


def plot_figure_at_rest(motion: FigureMotion, path: str | Path, name: str = "") -> None:
    """Write ``figure_at_rest_figure`` as a PNG to ``path``."""
    with plot_style():
        save_figure(figure_at_rest_figure(motion, name), path)


def figure_at_rest_figure(motion: FigureMotion, name: str = "") -> Figure:
    """A 3-D figure at rest (``motion`` at its first sample; ``name`` for the title): large,
    seen by ``VIEW`` over a patch of checkered floor with its shadow, each rod its own colour
    and named in a column beside the drawing (a leader line to the rod's middle); and small,
    from its right side, its front and above, all three to one scale in metres, each with the
    world axes it shows. In every view the rod ends it walks on (``feet``) are triangles and
    the heading rod is drawn thicker. PlotInputError for a motion that is not 3-D or has no
    samples."""
    endpoints = np.asarray(motion.endpoints, dtype=np.float64)
    if motion.dimensions != 3 or endpoints.ndim != 4 or endpoints.shape[2:] != (2, 3):
        raise PlotInputError(
            "plot_figure_at_rest: needs a 3-D figure's motion, endpoints (N, rods, 2, 3); got "
            f"dimensions {motion.dimensions}, endpoints {endpoints.shape}"
        )
    if len(endpoints) == 0:
        raise PlotInputError("plot_figure_at_rest: the motion has no samples")
    pose = endpoints[0]
    colors = controller_colors(list(motion.rod_names))
    heading = motion.heading_rod or "(none)"
    title = (
        f"{name or 'The figure'} at rest (t = {float(motion.t[0]):g} s): "
        f"{len(motion.rod_names)} rods, {float(np.sum(motion.rod_mass)):.3g} kg, heading rod "
        f"{heading}\n▲ the rod ends it walks on; the heading rod is drawn thicker"
    )
    size = pose_size(pose[None])
    floor = floor_cells(pose, FLOOR_MARGIN * size, size)
    drawn = project(np.concatenate([pose.reshape(-1, 3), floor_corners(*floor[1:])]))
    layout = rest_layout(np.ptp(drawn[:, :2], axis=0), title.count("\n") + 1)
    width, height = layout.size
    with plot_style():
        figure = new_figure(width, height)
        figure.suptitle(title, y=1 - 0.1 / height, va="top", fontsize=11)
        main = figure.add_axes(_figure_box(layout.main, layout.size))
        _draw_rest_oblique(main, motion, pose, colors, floor)
        main.set_title(camera_text(VIEW), fontsize=10)
        seen = {view: project(pose, camera)[..., :2].reshape(-1, 2) for view, camera in REST_VIEWS}
        half = 0.55 * max(float(np.ptp(points, axis=0).max()) for points in seen.values())
        half = max(half, 0.05)  # m: every small view spans twice this, to one scale
        for (view, camera), box in zip(REST_VIEWS, layout.small, strict=True):
            ax = figure.add_axes(_figure_box(box, layout.size))
            middle = (seen[view].min(axis=0) + seen[view].max(axis=0)) / 2
            if view != "top":  # the floor at the bottom of the view, a little of it showing
                middle[1] = max(middle[1], 0.9 * half)
            ax.set_xlim(middle[0] - half, middle[0] + half)
            ax.set_ylim(middle[1] - half, middle[1] + half)
            ax.set_aspect("equal")
            if view != "top":
                ax.axhspan(-2 * half, 0.0, color=FLOOR_DARK, zorder=0.5)
                ax.axhline(0.0, color=FLOOR_EDGE, linewidth=1.0, zorder=0.6)
            _draw_rest_pose(ax, motion, pose, colors, camera)
            xlabel, ylabel = REST_AXES[view]
            ax.set_xlabel(xlabel, labelpad=1)
            ax.set_ylabel(ylabel, labelpad=1)
            ax.tick_params(labelsize=7.5)
            ax.set_title(REST_TITLES[view], fontsize=9.5)
    return figure


def plot_result_at_rest(result_path: str | Path, path: str | Path) -> None:
    """``plot_figure_at_rest`` of a 3-D BSR result's best motion, named by its ``figure``."""
    result = read_result(result_path, dimensions=3)
    plot_figure_at_rest(result.motion, path, str(result.attrs.get("figure", "")))


def _draw_rest_pose(
    ax: Axes, motion: FigureMotion, pose: np.ndarray, colors: dict, camera: Camera
) -> np.ndarray:
    """The rods of ``pose`` (rods, 2, 3) m seen by ``camera``, the farthest first, each in its
    colour with round ends, the heading rod thicker, the feet marked; returns the projected
    pose (rods, 2, 3)."""
    seen = project(pose, camera)
    names = list(motion.rod_names)
    for rank, rod in enumerate(np.argsort(seen[..., 2].mean(axis=1), kind="stable")):
        width = ROD_WIDTH + (2.5 if names[rod] == motion.heading_rod else 1.0)
        ax.plot(
            seen[rod, :, 0],
            seen[rod, :, 1],
            color=colors[names[rod]],
            linewidth=width,
            solid_capstyle="round",
            marker="o",
            markersize=JOINT_SIZE,
            markeredgecolor=OUTLINE,
            markeredgewidth=0.5,
            zorder=3 + rank / len(names),
        )
    for rod, end in motion.feet:
        ax.plot(
            seen[rod, end, 0],
            seen[rod, end, 1],
            FOOT_MARKER,
            color="black",
            markersize=7,
            markerfacecolor="white",
            markeredgewidth=1.3,
            zorder=5,
        )
    return seen


def _draw_rest_oblique(
    ax: Axes, motion: FigureMotion, pose: np.ndarray, colors: dict, floor: tuple
) -> None:
    """The large view of ``figure_at_rest_figure``: the ``floor`` (``floor_cells``), the
    shadow, the rods and their names in a column each side (rods left of the middle named on
    the left), LABEL_COLUMN inches wide, the names spread apart (``spread_labels``) and joined
    to their rods."""
    cell, x_edges, z_edges = floor
    ax.set_axis_off()
    draw_floor(ax, x_edges, z_edges)
    draw_shadows(ax, pose[None], VIEW)
    seen = _draw_rest_pose(ax, motion, pose, colors, VIEW)
    drawn = np.concatenate([seen.reshape(-1, 3), project(floor_corners(x_edges, z_edges))])
    low, high = drawn[:, :2].min(axis=0), drawn[:, :2].max(axis=0)
    centre = (low + high) / 2
    box = ax.get_position()
    inches = np.array([box.width, box.height]) * ax.figure.get_size_inches()
    room = inches - [2 * LABEL_COLUMN, REST_PAD]  # inches for the drawing
    scale = float(max((high - low) / room))  # m per inch
    ax.set_xlim(centre[0] - inches[0] * scale / 2, centre[0] + inches[0] * scale / 2)
    ax.set_ylim(centre[1] - inches[1] * scale / 2, centre[1] + inches[1] * scale / 2)
    ax.set_aspect("equal")
    middles = seen[..., :2].mean(axis=1)
    names = list(motion.rod_names)
    reach = (high[0] - low[0]) / 2 + 0.1 * scale
    y_low, y_high = ax.get_ylim()
    for side in (-1, 1):
        rods = [r for r in range(len(names)) if (middles[r, 0] >= centre[0]) == (side > 0)]
        if not rods:
            continue
        column = centre[0] + side * reach
        heights = spread_labels(middles[rods, 1], LABEL_GAP * scale, y_low, y_high)
        for rod, y in zip(rods, heights, strict=True):
            color = colors[names[rod]]
            ax.plot(
                [middles[rod, 0], column], [middles[rod, 1], y], color=color, lw=0.7, zorder=2.5
            )
            ax.text(
                column + side * 0.05 * scale,
                y,
                names[rod],
                ha="left" if side > 0 else "right",
                va="center",
                fontsize=LABEL_SIZE,
                color=text_color(color),
                fontweight="bold",
                zorder=6,
            )
    ax.text(0.02, 0.02, f"floor squares {cell:g} m", transform=ax.transAxes, color="0.3")
    width, height = ax.figure.get_size_inches()
    # the key in the bottom left corner, above the floor's note: in the top left it sat on the
    # names of the left column
    bottom = box.y0 + 0.3 / height
    draw_axes_key(ax.figure, (box.x0, bottom, KEY_SIZE / width, KEY_SIZE / height), VIEW)
