"""The 3-D plots' scene (``mosys.plots.bsr3d``'s filmstrips and animations and
``mosys.plots.figure_at_rest``): the camera, the checkered floor, the figure's shadow on it and
a key of the world's axes.

The camera is orthographic: a point (x, y, z) m (y up, the floor y = 0, the figure facing +x at
t = 0) is drawn at its distances along the picture plane's right and up axes (``project``), so
that one metre is as long wherever it is, the floor's squares all alike and the view can pan.
``VIEW`` looks from the figure's right (+z) side, turned CAMERA_AZIMUTH towards its front
(+x) and CAMERA_ELEVATION above the floor: walking forward runs left to right, a left turn heads
away from the camera, a right turn towards it. A motion's filmstrip and animation turn the
camera further towards the front where that spreads the poses out (``choose_camera``: a walk
that turns left and walks on, as Rex's, whose second walk would pile its poses up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure

from mosys.plots.style import ROD_WIDTH

# the camera
CAMERA_AZIMUTH = 30.0  # deg from the figure's right side (+z) towards its front (+x)
CAMERA_ELEVATION = 30.0  # deg above the floor
CAMERA_AZIMUTHS = tuple(np.arange(CAMERA_AZIMUTH, 61.0, 5.0))  # deg: a motion's camera's choice


@dataclass(frozen=True)
class Camera:
    """An orthographic camera looking at the world from ``azimuth`` deg round from +z towards
    +x (0: from the figure's right side, +x to the right; 90: from its front) and
    ``elevation`` deg above the floor (90: from straight above, +x to the right and -z up).
    The picture plane's right axis stays level."""

    azimuth: float = CAMERA_AZIMUTH
    elevation: float = CAMERA_ELEVATION

    def basis(self) -> np.ndarray:
        """(3, 3): rows the picture's right and up axes and the direction towards the
        camera, unit vectors in world (x, y, z)."""
        a, e = math.radians(self.azimuth), math.radians(self.elevation)
        toward = np.array([math.sin(a) * math.cos(e), math.sin(e), math.cos(a) * math.cos(e)])
        right = np.array([math.cos(a), 0.0, -math.sin(a)])
        return np.array([right, np.cross(toward, right), toward])


VIEW = Camera()  # the rest poses' camera, and a straight walk's (``choose_camera``)
SIDE, FRONT, TOP = Camera(0.0, 0.0), Camera(90.0, 0.0), Camera(0.0, 90.0)


def project(points: np.ndarray, camera: Camera = VIEW) -> np.ndarray:
    """Points (..., 3) world (x, y, z) m as the ``camera`` sees them: (..., 3), the distance
    along the picture's right axis (u, m), along its up axis (v, m) and towards the camera
    (depth, m; nearer is larger)."""
    return np.asarray(points, dtype=np.float64) @ camera.basis().T


def choose_camera(com: np.ndarray, size: float, elevation: float = CAMERA_ELEVATION) -> Camera:
    """The camera of a filmstrip and its animation: the one among CAMERA_AZIMUTHS (front right
    views) that draws the filmstrip's poses furthest apart.
    com (k, 3) m: the poses' centres of mass in order; size m: the figure's (``pose_size``).
    Each consecutive pair's distance on the picture counts by its logarithm, taken between 0.1
    and 1 times the size (poses a size apart no longer overlap, and a figure standing still
    overlaps itself from anywhere), and the largest sum wins, the first of equals: a walk
    straight forward is seen from CAMERA_AZIMUTH, and one that turns away from the camera,
    which piles its poses up there, from further round (Rex's second walk, from 50°). Every
    view is ``elevation`` deg above the floor."""
    best, best_score = Camera(CAMERA_AZIMUTH, elevation), -math.inf
    for azimuth in CAMERA_AZIMUTHS:
        camera = Camera(float(azimuth), elevation)
        gaps = np.linalg.norm(np.diff(project(com, camera)[:, :2], axis=0), axis=1)
        score = float(np.log(np.clip(gaps, 0.1 * size, size)).sum())
        if score > best_score + 1e-9:
            best, best_score = camera, score
    return best


def camera_text(camera: Camera) -> str:
    """Where ``camera`` looks from, in words."""
    if camera.elevation >= 90:
        return "seen from above"
    side = {0.0: "its right side", 90.0: "its front"}.get(camera.azimuth)
    if side is None and 0 < camera.azimuth < 90:
        side = f"its front right ({camera.azimuth:g}° round from its right side)"
    elif side is None:
        side = f"azimuth {camera.azimuth:g}°"
    return f"seen from {side}, {camera.elevation:g}° above the floor"


# --------------------------------------------------------------------------- the floor

NICE_CELLS = (0.05, 0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 2.5, 5.0, 10.0)  # m: a floor square's side
CELLS_PER_SIZE = 5  # at most this many squares across the figure's size
FLOOR_CELLS = 30  # at most this many squares along the floor's longer side
FLOOR_MARGIN = 0.3  # of the largest pose's size: floor beyond the farthest rod end
FLOOR_LIGHT, FLOOR_DARK, FLOOR_EDGE = "0.95", "0.84", "0.55"
SHADOW_COLOR, SHADOW_ALPHA = "0.25", 0.22  # the figure's shadow, straight down on the floor


def pose_size(endpoints: np.ndarray, most: int = 200) -> float:
    """The figure's size, m: the largest distance between two rod ends of one pose, over
    ``most`` poses spread evenly through ``endpoints`` (N, rods, 2, 3) m (at least 0.1 m)."""
    picks = np.unique(np.linspace(0, len(endpoints) - 1, min(len(endpoints), most)).astype(int))
    points = np.asarray(endpoints, dtype=np.float64)[picks].reshape(len(picks), -1, 3)
    gaps = np.linalg.norm(points[:, :, None] - points[:, None], axis=-1)
    return max(float(gaps.max()), 0.1)


def floor_cells(
    points: np.ndarray, margin: float, size: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """The floor under ``points`` (..., 3) m with ``margin`` m round them, for a figure of
    ``size`` m (``pose_size``): its squares' side, m (the smallest of NICE_CELLS giving at most
    CELLS_PER_SIZE across the figure and FLOOR_CELLS along the floor's longer side), and the
    squares' edges along x and along z, m, multiples of the side (so that the squares of one
    world are the same whatever part of it is drawn)."""
    flat = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    low = flat[:, [0, 2]].min(axis=0) - margin
    high = flat[:, [0, 2]].max(axis=0) + margin
    least = max(size / CELLS_PER_SIZE, float((high - low).max()) / FLOOR_CELLS)
    cell = next((c for c in NICE_CELLS if c >= least - 1e-12), NICE_CELLS[-1])
    first = np.floor(low / cell + 1e-9)
    last = np.ceil(high / cell - 1e-9)
    x_edges = cell * np.arange(first[0], last[0] + 1)
    z_edges = cell * np.arange(first[1], last[1] + 1)
    return cell, x_edges, z_edges


def floor_corners(x_edges: np.ndarray, z_edges: np.ndarray) -> np.ndarray:
    """(4, 3) m: the floor's corners."""
    return np.array([[x, 0.0, z] for x in x_edges[[0, -1]] for z in z_edges[[0, -1]]])


def draw_floor(
    ax: Axes, x_edges: np.ndarray, z_edges: np.ndarray, camera: Camera = VIEW
) -> PolyCollection:
    """The floor y = 0 as a checker of squares between the edges (m) along x and z, seen by
    ``camera``; returns its collection (one polygon per square)."""
    cell = float(x_edges[1] - x_edges[0]) if len(x_edges) > 1 else 1.0
    squares, colors = [], []
    for x0, x1 in zip(x_edges[:-1], x_edges[1:], strict=True):
        for z0, z1 in zip(z_edges[:-1], z_edges[1:], strict=True):
            corners = np.array([[x0, 0, z0], [x1, 0, z0], [x1, 0, z1], [x0, 0, z1]])
            squares.append(project(corners, camera)[:, :2])
            parity = (round(x0 / cell) + round(z0 / cell)) % 2
            colors.append(FLOOR_DARK if parity else FLOOR_LIGHT)
    floor = PolyCollection(squares, facecolors=colors, edgecolors="none", zorder=0.5)
    ax.add_collection(floor, autolim=False)
    rim = project(floor_corners(x_edges, z_edges)[[0, 1, 3, 2, 0]], camera)
    ax.plot(rim[:, 0], rim[:, 1], color=FLOOR_EDGE, linewidth=0.8, zorder=0.6)
    return floor


def shadow_segments(poses: np.ndarray, camera: Camera) -> np.ndarray:
    """The poses' (..., rods, 2, 3) m shadows straight down on the floor, projected: (K·rods,
    2, 2)."""
    flat = np.array(poses, dtype=np.float64)
    flat[..., 1] = 0.0
    return project(flat, camera)[..., :2].reshape(-1, 2, 2)


def draw_shadows(ax: Axes, poses: np.ndarray, camera: Camera) -> None:
    """Draw the poses' (..., rods, 2, 3) m shadows on the floor, under everything else."""
    shadows = LineCollection(
        shadow_segments(poses, camera),
        colors=SHADOW_COLOR,
        alpha=SHADOW_ALPHA,
        linewidths=ROD_WIDTH + 0.5,
        capstyle="round",
        zorder=1,
    )
    ax.add_collection(shadows, autolim=False)


def drawn_pose(pose: np.ndarray, camera: Camera) -> np.ndarray:
    """A pose (rods, 2, 3) m as ``camera`` sees it, its rods farthest first: (rods, 2, 2) m."""
    seen = project(pose, camera)
    return seen[np.argsort(seen[..., 2].mean(axis=1), kind="stable"), :, :2]


def draw_axes_key(figure: Figure, box: tuple[float, float, float, float], camera: Camera) -> Axes:
    """A small key in ``box`` (figure fraction: left, bottom, width, height) of the world's x,
    y and z axes as ``camera`` sees them, each an arrow lettered at its tip."""
    key = figure.add_axes(box)
    key.set_axis_off()
    key.set_xlim(-1.35, 1.35)
    key.set_ylim(-1.35, 1.35)
    key.set_aspect("equal")
    for axis, letter in enumerate(("x", "y", "z")):
        tip = project(np.eye(3)[axis], camera)[:2]
        key.annotate(
            "",
            xy=tip,
            xytext=(0, 0),
            arrowprops={"arrowstyle": "-|>", "color": "0.2", "linewidth": 1.2},
        )
        key.text(*(tip * 1.22), letter, ha="center", va="center", fontsize=9, style="italic")
    return key


KEY_SIZE = 0.75  # inches: the axes key in the scene's corner
