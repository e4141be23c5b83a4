"""A 3-D ``.fig`` figure laid out for the 3-D BSR simulator (``kernels.bsr3d_simulate``).

A 3-D BSR figure is a tree of rods with a ``free`` root and ``ball`` or ``hinge`` joints (a hinge
is a ball joint whose swing ψ is fixed at 0), every angle with a finite range from a ``limit``
line (a ball joint's limit gives θ's and ψ's; equal bounds fix an angle), on a flat ``terrain
floor`` (or no terrain). As in 2-D, its contact points are its distinct rod endpoints, and the
joints are kinematic: limits' stiffness and damping are not used. Frames are the kernel's: the
root rod's rest frame in the body frame is Rz(offset) @ Ry(splay) of the ``free`` line, and the
body frame is the world's at t = 0 turned by the start's root angle about world z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mosys.bsr.figure import (
    check_bsr_figure,
    distinct_endpoints,
    load_rod_figure,
    rod_figure_motion,
)
from mosys.io.trajectory import FigureMotion
from mosys.kernels.bsr3d_simulate import FigureArrays3D
from mosys.parsing.figure import (
    Figure,
    Joint,
    JointLimit,
    default_swing_name,
)
from mosys.parsing.tokens import ENDPOINT_ENDS, SpecError, Token

# the figure_motion contract's contact attribute of every 3-D BSR motion
CONTACT_MODEL = "bsr3d-impulse: rigid-body impulses at rod endpoints, paper's friction"


@dataclass(frozen=True)
class BsrFigure3D:
    """Arrays of ``kernels.bsr3d_simulate`` (N rods in file order, which the binding checks
    puts every parent first; J = 2 (N - 1) angles, θ then ψ of each non-root rod in rod order).

    ``parent``: (N,) int64, -1 for the root; ``hinge``: (N,) m along the parent from its
    proximal end; ``rest``: (N, 3, 3) Rz(offset) @ Ry(splay) of each rod's joint (the root's from
    its ``free`` line); ``length`` (N,) m; ``mass`` (N,) kg; ``com`` (N,) fraction from proximal
    to distal; ``inertia`` (N,) kg m² about a transverse axis through the rod's centre of mass;
    ``joint``: (N,) int64 index of each rod's θ (ψ follows), -1 for the root; ``joint_names``:
    (J,) coordinate names; ``joint_min``/``joint_max``: (J,) rad, equal for a fixed angle;
    ``endpoints``: (E, 2) int64 rod and end (0 proximal, 1 distal) of each distinct endpoint;
    ``endpoint_names``: ``ROD.proximal``/``ROD.distal``; ``floor``: the floor's height, m (nan:
    none); ``gravity`` m/s², positive; ``root_angle``, ``root_x``: the free root's angle and x
    coordinate names; ``heading_rod``: the index of the rod whose horizontal (x, z) direction,
    proximal to distal, plus ``heading_offset`` (rad) is the heading (0 along +x, positive
    counter-clockwise seen from above, i.e. towards -z); ``feet``: the rows of ``endpoints``
    (rod, end) the figure walks on, in the order of the ``feet`` line."""

    figure: Figure
    parent: np.ndarray
    hinge: np.ndarray
    rest: np.ndarray
    length: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    joint: np.ndarray
    joint_names: tuple[str, ...]
    joint_min: np.ndarray
    joint_max: np.ndarray
    endpoints: np.ndarray
    endpoint_names: tuple[str, ...]
    floor: float
    gravity: float
    root_angle: str
    root_x: str
    heading_rod: int
    heading_offset: float
    feet: tuple[tuple[int, int], ...]

    @property
    def free(self) -> np.ndarray:
        """(J,) bool: the angles that can move (range wider than a point)."""
        return self.joint_max > self.joint_min

    @property
    def sense_names(self) -> tuple[str, ...]:
        """§4.2's senses in the order of ``kernels.bsr3d_controller``: the centre of mass's
        height, its velocity, the angular velocity and the world's up vector in the body frame,
        each endpoint's contact force, each free angle."""
        physical = ("y_cm",) + tuple(
            f"{quantity}_{axis}" for quantity in ("v_cm", "spin", "up") for axis in "xyz"
        )
        forces = tuple(f"force_{name}" for name in self.endpoint_names)
        free = tuple(name for name, moves in zip(self.joint_names, self.free, strict=True) if moves)
        return physical + forces + free

    @property
    def total_mass(self) -> float:
        """kg."""
        return float(self.mass.sum())

    @property
    def reach(self) -> float:
        """The sum of the rods' lengths, m."""
        return float(self.length.sum())

    @property
    def arrays(self) -> FigureArrays3D:
        """The figure as the kernels take it (each field this figure's attribute of its name)."""
        return FigureArrays3D(**{name: getattr(self, name) for name in FigureArrays3D._fields})

    def motion(self, rod_ends: np.ndarray, com: np.ndarray, dt: float) -> FigureMotion:
        """A run of the figure as the 3-D ``figure_motion`` contract: rod_ends (S, N, 2, 3) m
        (per sample and rod, its proximal then distal end (x, y, z), y up) and com (S, 3) m, one
        sample every simulator step of dt s from t = 0."""
        return rod_figure_motion(
            self,
            rod_ends,
            com,
            dt,
            CONTACT_MODEL,
            dimensions=3,
            heading_rod=self.figure.rods[self.heading_rod].name,
            heading_offset=math.degrees(self.heading_offset),
            feet=self.feet,
        )


def bsr_figure3d(figure: Figure) -> BsrFigure3D:
    """Lay out the 3-D ``figure`` for the 3-D BSR simulator; a figure it cannot simulate raises
    SpecError at the offending line (a planar figure, a pinned root, a joint before its parent's
    rod, an angle without a finite range, no angle free to move, terrain that is not a flat
    floor)."""
    if figure.dimensions != 3:
        raise SpecError.at(figure.path, figure.root.token, "a 3-D figure (one with 'ball' joints)")
    root = check_bsr_figure(figure)
    names = [rod.name for rod in figure.rods]
    terrain = figure.terrain
    index = {name: i for i, name in enumerate(names)}
    limits = {limit.rod: limit for limit in figure.limits}
    n = len(names)
    parent = np.full(n, -1, np.int64)
    hinge = np.zeros(n)
    rest = np.empty((n, 3, 3))
    joint = np.full(n, -1, np.int64)
    joint_names: list[str] = []
    ranges: list[tuple[float, float]] = []
    for i, rod in enumerate(figure.rods):
        spec = figure.joint(rod.name)
        rest[i] = _rz(spec.offset) @ _ry(spec.splay)
        if spec.kind == "free":
            continue
        assert spec.parent is not None
        if index[spec.parent] >= i:
            raise SpecError.at(figure.path, rod.token, f"rod '{spec.parent}' before its child")
        parent[i] = index[spec.parent]
        hinge[i] = spec.position
        joint[i] = len(joint_names)
        swing = spec.swing
        joint_names += [
            spec.angle.name,
            default_swing_name(rod.name) if swing is None else swing.name,
        ]
        ranges += _ranges(figure.path, spec, limits.get(rod.name))
    length = np.array([rod.length for rod in figure.rods])
    endpoints = distinct_endpoints(parent, hinge, length)
    bounds = np.array(ranges).reshape(-1, 2) + 0.0  # a limit written -0 is 0 (numpy's uniform
    # takes max -0 below min 0 and refuses the range)
    if not (bounds[:, 1] > bounds[:, 0]).any():
        raise SpecError.at(
            figure.path,
            root.token,
            "a figure with an angle free to move (every limit here fixes its angles: a search "
            "would have nothing to move)",
        )
    return BsrFigure3D(
        figure=figure,
        parent=parent,
        hinge=hinge,
        rest=rest,
        length=length,
        mass=np.array([rod.mass for rod in figure.rods]),
        com=np.array([rod.com for rod in figure.rods]),
        inertia=np.array([rod.inertia for rod in figure.rods]),
        joint=joint,
        joint_names=tuple(joint_names),
        joint_min=np.ascontiguousarray(bounds[:, 0]),
        joint_max=np.ascontiguousarray(bounds[:, 1]),
        endpoints=endpoints,
        endpoint_names=tuple(f"{names[rod]}.{ENDPOINT_ENDS[end]}" for rod, end in endpoints),
        floor=terrain.height if terrain.kind == "floor" else math.nan,
        gravity=figure.gravity,
        root_angle=root.angle.name,
        root_x=root.coordinates[0].name,
        heading_rod=index[figure.heading_rod],
        heading_offset=figure.heading_offset,
        feet=_distinct_feet(figure, index, endpoints),
    )


def load_bsr_figure3d(figures_dir: str | Path, spec_path: str, token: Token) -> BsrFigure3D:
    """The 3-D BSR figure a spec names (``load_rod_figure``, then ``bsr_figure3d``)."""
    return bsr_figure3d(load_rod_figure(figures_dir, spec_path, token))


def _ranges(path: str, joint: Joint, limit: JointLimit | None) -> list[tuple[float, float]]:
    """(min, max) rad of the joint's θ and ψ (a hinge's ψ: (0, 0)); a range that is missing or
    infinite raises SpecError at the limit line, or at the joint's line without one."""
    ball = joint.kind == "ball"
    keys = ("lower", "upper", "swing_lower", "swing_upper") if ball else ("lower", "upper")
    if limit is None:
        values = " ".join(f"{key}=..." for key in keys)
        raise SpecError.at(path, joint.token, f"a 'limit {joint.rod} {values}' line")
    bounds = (limit.lower, limit.upper, limit.swing_lower, limit.swing_upper)[: len(keys)]
    missing = [f"'{key}='" for key, value in zip(keys, bounds, strict=True) if math.isinf(value)]
    if missing:
        raise SpecError.at(
            path,
            limit.token,
            f"a limit with {', '.join(missing)} (degrees): a 3-D BSR figure needs every angle's "
            "range",
        )
    return [
        (limit.lower, limit.upper),
        (limit.swing_lower, limit.swing_upper) if ball else (0.0, 0.0),
    ]


def _distinct_feet(
    figure: Figure, index: dict[str, int], endpoints: np.ndarray
) -> tuple[tuple[int, int], ...]:
    """The figure's feet as rows of ``endpoints`` (rod, end), in file order, each once: a foot
    named as a child's proximal end that sits on an end of its parent is that end."""
    distinct = {(int(rod), int(end)) for rod, end in endpoints}
    feet: dict[tuple[int, int], None] = {}
    for name, end_name in figure.feet:
        rod, end = index[name], ENDPOINT_ENDS.index(end_name)
        while (rod, end) not in distinct:  # a shared proximal end: its parent's nearer end
            joint = figure.joint(figure.rods[rod].name)
            assert joint.parent is not None
            parent = index[joint.parent]
            rod, end = parent, int(joint.position > figure.rods[parent].length / 2)
        feet[(rod, end)] = None
    return tuple(feet)


def _rz(angle: float) -> np.ndarray:
    """(3, 3) the rotation by ``angle`` rad about z: [[c, -s, 0], [s, c, 0], [0, 0, 1]]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(angle: float) -> np.ndarray:
    """(3, 3) the rotation by ``angle`` rad about y: [[c, 0, s], [0, 1, 0], [-s, 0, c]]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
