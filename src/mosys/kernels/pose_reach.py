"""Which start poses of a car-like vehicle can reach a destination pose by a collision-free path
among polygon obstacles, and roughly how long the shortest such path is.

The vehicle (``dynamics.vehicle``): reference point (x, y) midway between the front wheels,
heading θ, steer φ, front wheels' speed v: x' = v cos(θ + φ), y' = v sin(θ + φ),
θ' = v sin(φ) / wheelbase. At rest it turns its wheels in place, so it moves as a Reeds–Shepp-like
car: any steer in [-steer_max, steer_max], forward or backward. A pose is free as in
``geometry.pose_is_free``: the reference point lies inside the domain polygon and the body
outline overlaps no obstacle.

The search is hybrid-A*-style breadth first, from the destination: a lattice of cells over
(x, y, heading) (``cell`` m squares over the domain's bounding box, ``heading_cells`` bins over
360°, the first centred on heading 0), each holding the continuous pose that first reached it.
A cell's pose is expanded by motion primitives of arc length ``step`` (m, travelled by the
reference point) at each steer of ``steer_values``, forward then backward, integrated in closed
form and tested for freedom every ``SUBSTEP`` m at most; a primitive with any non-free sample is
dropped, else the cell of its end pose, if unclaimed, is claimed with that pose and queued
(FIFO). Its path length is its BFS level × ``step``. Every path can be driven backward, so the
cells reached are those from which the destination can be reached.

A query pose reaches the destination if its cell was reached (its path length: the cell's);
else, since a cell's single pose leaves scattered cells of free space unreached, the primitives
from the query pose itself are tried too (``probe_levels`` deep): landing in a reached cell
counts. This is a discrete search, its answer only as good as its resolution (``cell``,
``heading_cells``, ``step``, ``steer_values``): "reachable" stands for a path from a pose a few
cm and ≤ half a heading bin from the query; "cannot reach" means that none was found at that
resolution, not a proof that none exists. Metres and radians throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from mosys.kernels.borrowed import borrowed, keep_alive
from mosys.kernels.geometry import pose_is_free

SUBSTEP = 0.05  # m, the longest travel of the reference point between two freedom tests
MIN_SUBSTEPS = 4  # freedom tests along a primitive, at least (the last at its end)
BYTES_PER_CELL = 40  # pose (3 float64) + path length (float64) + queue slot (int64)
_POSE_SLOT = np.arange(3, dtype=np.int64)  # pose_is_free's slots of x, y, heading in a pose


class PoseSearchError(ValueError):
    """A scene the pose search cannot take: its lattice too big for memory, or the destination
    itself not free (the other ValueErrors of ``pose_reach`` are a caller's mistakes)."""


@dataclass(frozen=True)
class PoseReach:
    """The answer for n query poses. path_length: (n,) float64 m, the length of the path found
    to the destination (BFS level × step; inf: cannot reach at the search's resolution; nan: the
    pose is not free); free: (n,) bool, the pose itself is free (reference point in the domain,
    body clear of every obstacle); reachable: (n,) bool, free and a path found (its cell
    reached, or a probe from it landed in a reached cell); cells_reached: the number of lattice
    cells the search reached."""

    path_length: np.ndarray
    free: np.ndarray
    reachable: np.ndarray
    cells_reached: int


@njit(cache=True)
def _cell_of(x, y, heading, origin, cell, shape):
    """The flat index of the lattice cell holding pose (x, y, heading): origin (2,) m, the
    lattice's low corner; cell m; shape (3,) int64 cells along x, y and heading."""
    ix = min(max(int(math.floor((x - origin[0]) / cell)), 0), shape[0] - 1)
    iy = min(max(int(math.floor((y - origin[1]) / cell)), 0), shape[1] - 1)
    ih = int(math.floor(heading * shape[2] / (2.0 * math.pi) + 0.5)) % shape[2]
    if ih < 0:
        ih += shape[2]
    return (ix * shape[1] + iy) * shape[2] + ih


@njit(cache=True)
def _arc(pose, curvature, s, out):
    """The pose (3,) after the reference point travels s m (negative: backward) with constant
    steer, heading turning at ``curvature`` = sin(steer) / wheelbase rad/m; into out (3,). The
    travel direction θ + φ turns with θ, so the point runs on a circle (chord form, exact)."""
    half = 0.5 * curvature * s
    chord = s if half == 0.0 else s * math.sin(half) / half
    direction = pose[2] + pose[3] + half
    out[0] = pose[0] + chord * math.cos(direction)
    out[1] = pose[1] + chord * math.sin(direction)
    heading = pose[2] + 2.0 * half
    out[2] = heading - 2.0 * math.pi * math.floor((heading + math.pi) / (2.0 * math.pi))


@njit(cache=True)
def _free_primitive(
    pose, curvature, s, substeps, outline, vertices, start, domain, body, end, sample
):
    """True when the primitive from pose (4,) (x, y, heading, steer) over s m (negative:
    backward) is free at its end and at substeps - 1 samples between; its end (3,) into end.
    sample: (3,) work array."""
    _arc(pose, curvature, s, end)
    free = pose_is_free(end, _POSE_SLOT, outline, vertices, start, domain, body)
    for k in range(1, substeps):
        if not free:
            break
        _arc(pose, curvature, s * k / substeps, sample)
        free = pose_is_free(sample, _POSE_SLOT, outline, vertices, start, domain, body)
    return free


@njit(cache=True)
def search(
    destination, outline, vertices, start, domain, wheelbase, steer_values, origin, cell, shape,
    step, substeps, poses, path_length, queue,
):  # fmt: skip
    """Breadth-first search of the lattice from destination (3,); returns the cells reached.
    poses (N, 3), path_length (N,) and queue (N,) int64 are work arrays of N = prod(shape)
    cells: on return path_length[c] is cell c's path length, m (inf: not reached) and poses[c]
    its pose. The other arguments as ``pose_reach`` takes them, steer_values (S,) rad."""
    own_body = np.empty_like(outline)
    own_points = np.empty((3, 4))
    # borrowed views (``kernels.borrowed``): the loop takes no references (it took 52 M a
    # search); the arguments and keep_alive keep the arrays alive
    body, points = borrowed((own_body, own_points))
    destination, outline, vertices, start, domain = borrowed(
        (destination, outline, vertices, start, domain)
    )
    steer_values, origin, cell, shape, poses, path_length, queue = borrowed(
        (steer_values, origin, cell, shape, poses, path_length, queue)
    )
    here = points[0]  # x, y, heading, steer
    there = points[1, :3]  # a primitive's end
    sample = points[2, :3]  # a pose along it
    path_length[:] = np.inf
    first = _cell_of(destination[0], destination[1], destination[2], origin, cell, shape)
    poses[first] = destination
    path_length[first] = 0.0
    queue[0] = first
    head, tail, level, level_end = 0, 1, 0, 1
    while head < tail:
        if head == level_end:
            level += 1
            level_end = tail
        c = queue[head]
        head += 1
        here[:3] = poses[c]
        for direction in (1.0, -1.0):
            for steer in steer_values:
                here[3] = steer
                curvature = math.sin(steer) / wheelbase
                _arc(here, curvature, direction * step, there)  # its end, to look up first
                end = _cell_of(there[0], there[1], there[2], origin, cell, shape)
                if path_length[end] != np.inf:  # claimed already: the samples cannot matter
                    continue
                if _free_primitive(
                    here, curvature, direction * step, substeps, outline, vertices, start,
                    domain, body, there, sample,
                ):  # fmt: skip
                    poses[end] = there
                    path_length[end] = (level + 1) * step
                    queue[tail] = end
                    tail += 1
    keep_alive((own_body, own_points))
    return tail


@njit(cache=True)
def lookup(
    queries, outline, vertices, start, domain, wheelbase, steer_values, origin, cell, shape,
    step, substeps, path_length, probe_levels, out,
):  # fmt: skip
    """Each query pose's (n, 3) path length into out (n,) m (nan: not free; inf: not reached);
    returns (n,) bool, the pose is free. path_length (N,) from ``search``. A free query whose
    cell was not reached is probed: the primitives from it, up to probe_levels deep, tested as
    in ``search``; at the first level some end lands in a reached cell, the shortest
    level × step + that cell's path length."""
    body = np.empty_like(outline)
    sample = np.empty(3)  # a pose along a primitive
    free = np.zeros(queries.shape[0], dtype=np.bool_)
    branches = 2 * steer_values.shape[0]
    frontier = np.empty((branches**probe_levels, 4))
    after = np.empty_like(frontier)
    for i in range(queries.shape[0]):
        q = queries[i]
        free[i] = pose_is_free(q, _POSE_SLOT, outline, vertices, start, domain, body)
        out[i] = np.nan
        if not free[i]:
            continue
        out[i] = path_length[_cell_of(q[0], q[1], q[2], origin, cell, shape)]
        frontier[0, :3] = q
        size = 1
        for level in range(1, probe_levels + 1):
            if out[i] < np.inf:
                break
            grown = 0
            for f in range(size):
                for b in range(branches):
                    steer = steer_values[b % steer_values.shape[0]]
                    frontier[f, 3] = steer
                    s = step if b < steer_values.shape[0] else -step
                    curvature = math.sin(steer) / wheelbase
                    end = after[grown, :3]
                    if _free_primitive(
                        frontier[f], curvature, s, substeps, outline, vertices, start, domain,
                        body, end, sample,
                    ):  # fmt: skip
                        c = _cell_of(end[0], end[1], end[2], origin, cell, shape)
                        out[i] = min(out[i], level * step + path_length[c])
                        grown += 1
            frontier, after, size = after, frontier, grown
    return free


def pose_reach(
    destination: np.ndarray,
    queries: np.ndarray,
    outline: np.ndarray,
    obstacle_vertices: np.ndarray,
    obstacle_start: np.ndarray,
    domain: np.ndarray,
    wheelbase: float,
    steer_max: float,
    cell: float = 0.05,
    heading_cells: int = 144,
    step: float = 0.15,
    max_bytes: int = 2 * 1024**3,
    steer_values: np.ndarray | None = None,
    probe_levels: int = 1,
) -> PoseReach:
    """Which query poses (n, 3) (x m, y m, heading rad) can reach destination (3,) (same units)
    by a collision-free path (see the module docstring). outline (V, 2): the body in the vehicle
    frame, m (reference point at the origin, heading +x); obstacle_vertices (M, 2) and
    obstacle_start (K+1,) int64 from ``geometry.pack_polygons``; domain (P, 2), P >= 3: the
    polygon the reference point stays in, its bounding box the lattice's x and y extent;
    wheelbase m; steer_max rad; cell m; step m (> the cell's diagonal); steer_values (S,) rad,
    default -steer_max, -steer_max/2, 0, steer_max/2, steer_max; probe_levels 0..3: how deep
    to probe from a free query whose cell was not reached (``lookup``; 0: not at all).
    PoseSearchError when the lattice would take more than max_bytes, or the destination is
    not free; ValueError for arguments out of their ranges."""
    destination = np.ascontiguousarray(destination, dtype=np.float64).reshape(3)
    queries = np.ascontiguousarray(queries, dtype=np.float64).reshape(-1, 3)
    domain = np.ascontiguousarray(domain, dtype=np.float64)
    if steer_values is None:
        steer_values = steer_max * np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
    steer_values = np.ascontiguousarray(steer_values, dtype=np.float64)
    if not 0 <= probe_levels <= 3:
        raise ValueError(f"probe_levels must be 0..3, got {probe_levels}")
    if domain.ndim != 2 or domain.shape[0] < 3 or domain.shape[1] != 2:
        raise ValueError(f"domain must be a (P, 2) polygon with P >= 3, got {domain.shape}")
    if not (cell > 0 and step > cell * math.sqrt(2.0) and heading_cells >= 1):
        raise ValueError(
            f"need cell > 0, heading_cells >= 1 and step > the cell's diagonal "
            f"(cell {cell} m, heading_cells {heading_cells}, step {step} m)"
        )
    origin = domain.min(axis=0)
    extent = domain.max(axis=0) - origin
    counts = [max(1, math.ceil(float(e) / cell)) for e in extent] + [int(heading_cells)]
    cells = counts[0] * counts[1] * counts[2]  # Python int: no overflow
    if cells * BYTES_PER_CELL > max_bytes:
        raise PoseSearchError(
            f"the lattice would take {cells * BYTES_PER_CELL} bytes ({cells} cells requested: "
            f"{counts[0]} x {counts[1]} x {counts[2]}, {BYTES_PER_CELL} bytes each), "
            f"more than max_bytes {max_bytes}; use a larger cell or fewer heading_cells"
        )
    shape = np.array(counts, dtype=np.int64)
    scene = (
        np.ascontiguousarray(outline, dtype=np.float64),
        np.ascontiguousarray(obstacle_vertices, dtype=np.float64).reshape(-1, 2),
        np.ascontiguousarray(obstacle_start, dtype=np.int64),
        domain,
    )
    body = np.empty_like(scene[0])
    if not pose_is_free(destination, _POSE_SLOT, *scene, body):
        raise PoseSearchError(f"the destination {destination.tolist()} is not free")
    substeps = max(MIN_SUBSTEPS, math.ceil(step / SUBSTEP))
    path_length = np.empty(cells)
    reached = search(
        destination, *scene, float(wheelbase), steer_values, origin, float(cell), shape,
        float(step), substeps, np.empty((cells, 3)), path_length, np.empty(cells, np.int64),
    )  # fmt: skip
    lengths = np.empty(queries.shape[0])
    free = lookup(
        queries, *scene, float(wheelbase), steer_values, origin, float(cell), shape, float(step),
        substeps, path_length, int(probe_levels), lengths,
    )  # fmt: skip
    return PoseReach(
        path_length=lengths, free=free, reachable=np.isfinite(lengths), cells_reached=int(reached)
    )
