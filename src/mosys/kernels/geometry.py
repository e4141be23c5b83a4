"""Planar polygon tests for obstacles: does a body outline, placed at a pose, overlap any obstacle,
and is a reference point inside a domain polygon. Metres and radians; polygons are (V, 2) float64
vertex arrays, several obstacles packed into one array with start offsets."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _side(ax, ay, bx, by, px, py):
    """> 0 when p lies left of the line a→b, < 0 right, 0 on it."""
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax)


@njit(cache=True)
def _opposite(a, b):
    """True when a and b have opposite signs or either is 0."""
    return (a <= 0.0 and b >= 0.0) or (a >= 0.0 and b <= 0.0)


@njit(cache=True)
def segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """True when segment ab crosses segment cd (touching counts as crossing)."""
    d1 = _side(cx, cy, dx, dy, ax, ay)
    d2 = _side(cx, cy, dx, dy, bx, by)
    d3 = _side(ax, ay, bx, by, cx, cy)
    d4 = _side(ax, ay, bx, by, dx, dy)
    if d1 == 0.0 and d2 == 0.0:  # collinear: do their extents overlap?
        return max(min(ax, bx), min(cx, dx)) <= min(max(ax, bx), max(cx, dx)) and max(
            min(ay, by), min(cy, dy)
        ) <= min(max(ay, by), max(cy, dy))
    # signs, not products: a product of two tiny sides can underflow to 0
    return _opposite(d1, d2) and _opposite(d3, d4)


@njit(cache=True)
def point_in_polygon(px, py, polygon):
    """True when (px, py) lies inside the simple polygon (V, 2) (even-odd rule)."""
    inside = False
    n = polygon.shape[0]
    j = n - 1
    for i in range(n):
        xi = polygon[i, 0]
        yi = polygon[i, 1]
        xj = polygon[j, 0]
        yj = polygon[j, 1]
        if (yi > py) != (yj > py) and px < xi + (py - yi) * (xj - xi) / (yj - yi):
            inside = not inside
        j = i
    return inside


@njit(cache=True)
def box_in_polygon(low_x, high_x, low_y, high_y, polygon):
    """True when the box [low_x, high_x] × [low_y, high_y] (m) lies inside the simple polygon
    (V, 2): a corner of it inside (``point_in_polygon``) and no edge of the polygon crossing
    or touching an edge of the box (``segments_cross``), so that the polygon's boundary, which
    is connected, lies wholly outside the box. True for an empty box (low > high: no point to
    test). Conservative: a box whose edge touches the polygon's boundary is not inside."""
    if low_x > high_x or low_y > high_y:
        return True
    if not point_in_polygon(low_x, low_y, polygon):
        return False
    n = polygon.shape[0]
    j = n - 1
    for i in range(n):
        ax, ay = polygon[j, 0], polygon[j, 1]
        bx, by = polygon[i, 0], polygon[i, 1]
        if (
            segments_cross(ax, ay, bx, by, low_x, low_y, high_x, low_y)
            or segments_cross(ax, ay, bx, by, high_x, low_y, high_x, high_y)
            or segments_cross(ax, ay, bx, by, high_x, high_y, low_x, high_y)
            or segments_cross(ax, ay, bx, by, low_x, high_y, low_x, low_y)
        ):
            return False
        j = i
    return True


@njit(cache=True)
def polygons_overlap(a, b):
    """True when the simple polygons a (Va, 2) and b (Vb, 2) share any point: an edge of one
    crosses an edge of the other, or one lies inside the other."""
    na = a.shape[0]
    nb = b.shape[0]
    for i in range(na):
        i2 = (i + 1) % na
        for j in range(nb):
            j2 = (j + 1) % nb
            if segments_cross(
                a[i, 0], a[i, 1], a[i2, 0], a[i2, 1], b[j, 0], b[j, 1], b[j2, 0], b[j2, 1]
            ):
                return True
    return point_in_polygon(a[0, 0], a[0, 1], b) or point_in_polygon(b[0, 0], b[0, 1], a)


@njit(cache=True)
def place_outline(outline, x, y, heading, out):
    """The outline (V, 2), given in the body's frame, moved to pose (x, y, heading) into out."""
    c = math.cos(heading)
    s = math.sin(heading)
    for i in range(outline.shape[0]):
        out[i, 0] = x + c * outline[i, 0] - s * outline[i, 1]
        out[i, 1] = y + s * outline[i, 0] + c * outline[i, 1]


@njit(cache=True, inline="always")
def _apart(polygon, low_x, high_x, low_y, high_y):
    """True when every vertex of polygon (V, 2) lies on one side of the box (m): the bounding
    boxes are apart, so the shapes cannot overlap."""
    right = left = above = below = True  # of the box, every vertex
    for i in range(polygon.shape[0]):
        right = right and polygon[i, 0] > high_x
        left = left and polygon[i, 0] < low_x
        above = above and polygon[i, 1] > high_y
        below = below and polygon[i, 1] < low_y
    return right or left or above or below


@njit(cache=True)
def box_is_clear(low_x, high_x, low_y, high_y, obstacle_vertices, obstacle_start):
    """True when the box [low_x, high_x] × [low_y, high_y] (m) is apart from every obstacle's
    bounding box (obstacles packed as in ``first_collision``): no shape inside it can touch
    one."""
    for k in range(obstacle_start.shape[0] - 1):
        polygon = obstacle_vertices[obstacle_start[k] : obstacle_start[k + 1]]
        if not _apart(polygon, low_x, high_x, low_y, high_y):
            return False
    return True


@njit(cache=True)
def first_collision(outline, x, y, heading, obstacle_vertices, obstacle_start, body):
    """The index of the first obstacle the body overlaps at pose (x, y, heading), or -1.
    obstacle_vertices: (M, 2) every obstacle's vertices in turn; obstacle_start: (K+1,) int64,
    obstacle k is rows obstacle_start[k]:obstacle_start[k+1]; body: (V, 2) work array."""
    if obstacle_start.shape[0] <= 1:
        return -1
    place_outline(outline, x, y, heading, body)
    low_x = high_x = body[0, 0]
    low_y = high_y = body[0, 1]
    for i in range(1, body.shape[0]):
        low_x = min(low_x, body[i, 0])
        high_x = max(high_x, body[i, 0])
        low_y = min(low_y, body[i, 1])
        high_y = max(high_y, body[i, 1])
    for k in range(obstacle_start.shape[0] - 1):
        polygon = obstacle_vertices[obstacle_start[k] : obstacle_start[k + 1]]
        # bounding boxes apart: no overlap (the edge tests below cost far more)
        if _apart(polygon, low_x, high_x, low_y, high_y):
            continue
        if polygons_overlap(body, polygon):
            return k
    return -1


@njit(cache=True, inline="always")  # its callers' hot loops: no call (and no reference
# counts of its seven arrays) where there are no obstacles
def pose_is_free(state, pose_slot, outline, obstacle_vertices, obstacle_start, domain, body):
    """True when a model state (S,) is allowed (``pose_is_free_at`` its pose: x
    state[pose_slot[0]], y state[pose_slot[1]], heading state[pose_slot[2]]). pose_slot[0] < 0:
    always True."""
    if pose_slot[0] < 0:
        return True
    x = state[pose_slot[0]]
    y = state[pose_slot[1]]
    heading = state[pose_slot[2]]
    return pose_is_free_at(x, y, heading, outline, obstacle_vertices, obstacle_start, domain, body)


@njit(cache=True, inline="always")
def pose_is_free_at(x, y, heading, outline, obstacle_vertices, obstacle_start, domain, body):
    """True when the reference point (x, y) m lies inside ``domain`` (P, 2; P = 0: no domain
    polygon) and the body (``outline``), turned by ``heading`` rad, overlaps no obstacle."""
    if domain.shape[0] > 0 and not point_in_polygon(x, y, domain):
        return False
    return first_collision(outline, x, y, heading, obstacle_vertices, obstacle_start, body) < 0


def grown_polygon(vertices: np.ndarray, margin: float) -> np.ndarray:
    """A convex polygon (V, 2), m, with every edge moved ``margin`` m outward (V, 2): it holds
    every point within ``margin`` of the original (each corner moves along its bisector to where
    the two moved edges meet, so a rectangle grows by ``margin`` on each side)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    edges = np.roll(vertices, -1, axis=0) - vertices  # edge k runs from vertex k to k + 1
    following = np.roll(edges, -1, axis=0)
    turns = edges[:, 0] * following[:, 1] - edges[:, 1] * following[:, 0]
    if not (np.all(turns > 0.0) or np.all(turns < 0.0)):
        raise ValueError("grown_polygon: the polygon is not convex")
    sense = 1.0 if turns[0] > 0.0 else -1.0  # counter-clockwise: the outward normal is right
    normals = sense * np.column_stack([edges[:, 1], -edges[:, 0]])
    normals /= np.hypot(normals[:, 0], normals[:, 1])[:, None]
    before = np.roll(normals, 1, axis=0)  # the normal of the edge ending at each vertex
    bisector = (before + normals) / (1.0 + np.sum(before * normals, axis=1))[:, None]
    return np.ascontiguousarray(vertices + margin * bisector)


def pack_polygons(polygons: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Polygons (each (V_k, 2)) as one (M, 2) float64 vertex array and (K+1,) int64 offsets."""
    starts = np.zeros(len(polygons) + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(p) for p in polygons])
    if not polygons:
        return np.zeros((0, 2)), starts
    return np.ascontiguousarray(np.concatenate(polygons).astype(np.float64)), starts


@njit(cache=True)
def first_colliding_sample(poses, outline, obstacle_vertices, obstacle_start):
    """(sample, obstacle) of the first pose (N, 3) (x m, y m, heading rad) at which the body
    overlaps an obstacle, or (-1, -1)."""
    body = np.empty_like(outline)
    for i in range(poses.shape[0]):
        hit = first_collision(
            outline, poses[i, 0], poses[i, 1], poses[i, 2], obstacle_vertices, obstacle_start, body
        )
        if hit >= 0:
            return i, hit
    return -1, -1
