"""The motions of a script with motor programs (Luxo's show), cut from its trajectory and
measured: distance, peak height, net rotation, touch-down, settling, penetration.

A motion begins where a motor program starts driving and ends where the next one starts (or at
the end of the trajectory): the program's airborne part, then whatever lands the figure.
Figures with a free root only: the root is rod 0 and its state variables are the first three
coordinates (x, y, angle).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from mosys.io.trajectory import Trajectory
from mosys.kernels.libm import arctan2_each

# settled: the base flat (within BASE_FLAT_DEG of a whole number of turns), the joints within
# JOINT_DEG of the standing pose, and at rest (speeds below these)
BASE_FLAT_DEG = 5.0
JOINT_DEG = 5.0
REST_SPEED = 0.05  # m/s, the root's x and y rates
REST_RATE = 10.0  # deg/s, every angular rate
SETTLE_WITHIN = 2.0  # s after touch-down: the target for a landing
ROD_SAMPLES = 21  # points along each rod where its depth in the ground is measured


@dataclass(frozen=True)
class Motion:
    """One motion: the motor program ``name`` and its samples [start, end) of the trajectory."""

    name: str
    start: int
    end: int


def motions(trajectory: Trajectory) -> list[Motion]:
    """The trajectory's motions, in time order (none if it ran no motor program)."""
    kinds = [str(kind) for kind in trajectory.attrs.get("controller_kinds", [])]
    driver = trajectory.controller
    starts = [
        i
        for i in range(len(driver))
        if kinds and kinds[driver[i]] == "motor" and (i == 0 or driver[i - 1] != driver[i])
    ]
    bounds = [*starts, len(driver)]
    return [Motion(trajectory.controllers[driver[a]], a, b) for a, b in pairwise(bounds)]


def ground_height(terrain: list[list[float]], x: np.ndarray) -> np.ndarray:
    """The terrain polyline's height at each x (m); at a vertical riser, the higher side. No
    terrain: the plane y = -inf (nothing to touch)."""
    x = np.asarray(x, dtype=np.float64)
    if not terrain:
        return np.full(x.shape, -np.inf)
    height = np.full(x.shape, -np.inf)
    for (x0, y0), (x1, y1) in pairwise(terrain):
        if x1 > x0:
            on = (x >= x0) & (x <= x1)
            height = np.where(on, np.maximum(height, y0 + (y1 - y0) * (x - x0) / (x1 - x0)), height)
    return height


def ground_depth(terrain: list[list[float]], points: np.ndarray) -> np.ndarray:
    """How far each point (..., 2) m lies inside the ground, m (0 outside): below the terrain
    polyline within its x range, its distance to the nearest point of the polyline, as the
    contact model measures it (README, the figure spec's 'contact'). Measured straight down
    from the surface above, a head touching a ditch's wall read 9.8 cm deep for 0.14 mm."""
    points = np.asarray(points, dtype=np.float64)
    inside = points[..., 1] < ground_height(terrain, points[..., 0])
    nearest = np.full(points.shape[:-1], np.inf)
    for start, end in pairwise(np.asarray(terrain, dtype=np.float64)):
        along = end - start
        fraction = np.clip(((points - start) @ along) / max(float(along @ along), 1e-300), 0, 1)
        gap = points - (start + fraction[..., None] * along)
        nearest = np.minimum(nearest, np.hypot(gap[..., 0], gap[..., 1]))
    return np.where(inside, nearest, 0.0)


def rod_points(endpoints: np.ndarray, per_rod: int = ROD_SAMPLES) -> np.ndarray:
    """(N, rods * per_rod, 2) points evenly along each rod (ends included) of ``endpoints``
    (N, rods, 2, 2) m."""
    fractions = np.linspace(0.0, 1.0, per_rod)[None, None, :, None]
    near, far = endpoints[:, :, None, 0], endpoints[:, :, None, 1]
    points = near + fractions * (far - near)
    return points.reshape(endpoints.shape[0], -1, 2)


def longest_flight(touching: np.ndarray) -> tuple[int | None, int | None]:
    """(take-off, touch-down) sample indices of the longest stretch without contact in
    ``touching`` (N,) bool: its first airborne sample and the first touching one after it
    (None when it never leaves the ground, or never comes back)."""
    flying = np.concatenate([[False], ~touching, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(flying))
    if edges.size == 0:
        return None, None
    starts, ends = edges[::2], edges[1::2]
    longest = int(np.argmax(ends - starts))
    touchdown = int(ends[longest])
    return int(starts[longest]), touchdown if touchdown < len(touching) else None


@dataclass(frozen=True)
class MotionMeasures:
    """What the motions table reports for one motion (SI, angles in degrees)."""

    motion: str
    start_s: float
    distance_m: float  # the base's x displacement, end - start
    peak_height_m: float  # the base centre's highest point above its start
    rotation_deg: float  # the base's net rotation, end - start (a backflip: about -360)
    airborne_s: float  # its longest flight: from take-off (no contact force) to touch-down
    touchdown_s: float  # end of its longest flight, since the motion began (nan: no flight)
    settle_s: float  # from touch-down until it stayed settled to the end (nan: never)
    landed: bool  # touched down and settled within SETTLE_WITHIN s
    start_ground_m: float  # the ground's height under the base's centre, at the start
    end_ground_m: float  # and at the end
    lowest_ground_touched_m: float  # the lowest ground a contact point touched
    max_penetration_m: float  # the deepest any contact point went into the ground
    rod_in_ground_m: float  # the deepest any point of a rod went into it (the rods between
    # the contact points meet no ground: an arm can pass through a ditch's floor)
    limb_touched: bool  # a contact point off the root rod (Luxo: the head) touched the ground


def _column(trajectory: Trajectory, name: str) -> np.ndarray:
    return trajectory.state[:, trajectory.state_order.index(name)]


def settled(trajectory: Trajectory, standing: dict[str, float]) -> np.ndarray:
    """(N,) bool per sample: the base flat, each joint ``standing`` names (name -> deg) within
    JOINT_DEG of it, and at rest: the root's x and y rates below REST_SPEED, every angular rate
    below REST_RATE (about ``standing``'s value where it names the rate)."""
    motion = trajectory.motion
    assert motion is not None
    base = motion.endpoints[:, 0, 1] - motion.endpoints[:, 0, 0]
    ok = np.abs(np.degrees(arctan2_each(base[:, 1], base[:, 0]))) <= BASE_FLAT_DEG
    order = trajectory.state_order
    coordinates = len(order) // 2
    for k, name in enumerate(order):
        error = np.abs(_column(trajectory, name) - standing.get(name, 0.0))
        if k < coordinates:
            if name in standing:
                ok &= error <= JOINT_DEG
        else:
            ok &= error <= (REST_SPEED if k < coordinates + 2 else REST_RATE)
    return ok


def measure(trajectory: Trajectory, motion: Motion, standing: dict[str, float]) -> MotionMeasures:
    """Measure one motion of a trajectory with ``figure_motion`` and ``contacts``. ``standing``
    is the standing pose's joint angles and rates (the landing controller's destination)."""
    figure = trajectory.motion
    contacts = trajectory.contacts
    assert figure is not None and contacts is not None
    span = slice(motion.start, motion.end)
    t = trajectory.t[span] - trajectory.t[motion.start]
    base = figure.endpoints[span, 0]
    centre = base.mean(axis=1)
    rotation = _column(trajectory, trajectory.state_order[2])[span]
    terrain = figure.terrain
    points = contacts.position[span]
    surface = ground_height(terrain, points[..., 0])
    in_contact = np.linalg.norm(contacts.force[span], axis=2) > 0.0
    # a point resting on the surface with no force yet (a script's start state) is not flying:
    # a motion that never left the ground had one sample of flight
    touching = (in_contact | (points[..., 1] <= surface)).any(axis=1)
    takeoff, touchdown = longest_flight(touching)
    good = settled(trajectory, standing)[span]
    settle = np.nan
    landed = False
    if touchdown is not None and good[-1]:
        first_good = len(good) - int(np.argmin(good[::-1])) if not good.all() else 0
        settle = max(0.0, float(t[first_good] - t[touchdown]))
        landed = settle <= SETTLE_WITHIN
    depth = ground_depth(terrain, points)
    rods = ground_depth(terrain, rod_points(figure.endpoints[span]))
    touched = surface[in_contact]
    off_root = np.array([rod != figure.rod_names[0] for rod in contacts.rods], dtype=bool)
    return MotionMeasures(
        motion=motion.name,
        start_s=float(trajectory.t[motion.start]),
        distance_m=float(centre[-1, 0] - centre[0, 0]),
        peak_height_m=float(centre[:, 1].max() - centre[0, 1]),
        rotation_deg=float(rotation[-1] - rotation[0]),
        airborne_s=float(t[touchdown] - t[takeoff]) if touchdown is not None else np.nan,
        touchdown_s=float(t[touchdown]) if touchdown is not None else np.nan,
        settle_s=settle,
        landed=landed,
        start_ground_m=float(ground_height(terrain, centre[:1, 0])[0]),
        end_ground_m=float(ground_height(terrain, centre[-1:, 0])[0]),
        lowest_ground_touched_m=float(touched.min()) if touched.size else np.nan,
        max_penetration_m=float(max(0.0, depth.max())),
        rod_in_ground_m=float(max(0.0, rods.max())),
        limb_touched=bool(in_contact[:, off_root].any()),
    )
