"""A ``.fig`` figure laid out for the BSR simulator (``kernels.bsr_simulate``).

A BSR figure is a tree of rods with a ``free`` root and ``hinge`` joints, every hinge with a
``limit`` line giving its range (the target poses of Table 2 are drawn in it; the simulator's joints
are kinematic, so the limit's stiffness and damping are not used), on a flat ``terrain floor`` (or
no terrain). Its contact points are its rod endpoints: where a child hangs on an end of its parent
the two ends are one endpoint, so a tree of N rods hinged end to end has N + 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from mosys.io.trajectory import FigureMotion
from mosys.kernels.bsr_simulate import FigureArrays
from mosys.parsing.figure import Figure, Joint, parse_figure_spec
from mosys.parsing.tokens import ENDPOINT_ENDS, SpecError, Token

# the figure_motion contract's contact attribute of every BSR motion
CONTACT_MODEL = "bsr-impulse: rigid-body impulses at <= 2 rod endpoints, paper's friction"

_SAME_POINT = 1e-12  # m: a hinge this close to an end of its parent sits on that endpoint


@dataclass(frozen=True)
class BsrFigure:
    """Arrays of ``kernels.bsr_simulate`` (rods in file order, which the binding checks puts
    every parent first). ``joint_names``: the hinges' angle coordinates (J), in θ order;
    ``joint_min``/``joint_max``: (J,) rad; ``endpoints``: (E, 2) int64 rod and end (0 proximal,
    1 distal) of each distinct endpoint; ``endpoint_names``: ``ROD.proximal``/``ROD.distal``;
    ``floor``: the floor's height, m (nan: none); ``root_angle``, ``root_x``: the free root's
    angle and x coordinate names."""

    figure: Figure
    parent: np.ndarray
    hinge: np.ndarray
    offset: np.ndarray
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

    @property
    def total_mass(self) -> float:
        return float(self.mass.sum())

    @property
    def reach(self) -> float:
        """The sum of the rods' lengths, m: the scale of the height sense variable."""
        return float(self.length.sum())

    @property
    def sense_names(self) -> tuple[str, ...]:
        """Table 1's sense variables: joint angles, endpoint contact forces, y_cm, y_cm rate."""
        return (
            self.joint_names
            + tuple(f"force_{name}" for name in self.endpoint_names)
            + ("y_cm", "vy_cm")
        )

    def motion(self, rod_ends: np.ndarray, com: np.ndarray, dt: float) -> FigureMotion:
        """A run of the figure as the ``figure_motion`` contract: rod_ends (N, rods, 2, 2) m and
        com (N, 2) m, one sample every simulator step of dt s from t = 0."""
        return rod_figure_motion(self, rod_ends, com, dt, CONTACT_MODEL)

    @property
    def arrays(self) -> FigureArrays:
        """The figure as the kernels take it (each field this figure's attribute of its name)."""
        return FigureArrays(**{name: getattr(self, name) for name in FigureArrays._fields})


def bsr_figure(figure: Figure) -> BsrFigure:
    """Lay out ``figure`` for the BSR simulator; a figure it cannot simulate raises SpecError
    at the offending line (a 3-D figure, a pinned root, a hinge out of order or without a
    limit, terrain that is not a flat floor)."""
    ball = next((joint for joint in figure.joints if joint.kind == "ball"), None)
    if ball is not None:
        raise SpecError.at(
            figure.path,
            ball.token,
            "a planar figure (ball joints are for the 3-D BSR search: bsr.figure3d)",
        )
    root = check_bsr_figure(figure)
    names = [rod.name for rod in figure.rods]
    index = {name: i for i, name in enumerate(names)}
    limits = {limit.rod: limit for limit in figure.limits}
    n = len(names)
    parent = np.full(n, -1, np.int64)
    hinge = np.zeros(n)
    offset = np.zeros(n)
    joint = np.full(n, -1, np.int64)
    joint_names: list[str] = []
    joint_min: list[float] = []
    joint_max: list[float] = []
    for i, rod in enumerate(figure.rods):
        spec = figure.joint(rod.name)
        if spec.kind != "hinge":
            continue
        assert spec.parent is not None
        if index[spec.parent] >= i:
            raise SpecError.at(figure.path, rod.token, f"rod '{spec.parent}' before its child")
        limit = limits.get(rod.name)
        if limit is None or not (math.isfinite(limit.lower) and math.isfinite(limit.upper)):
            raise SpecError.at(
                figure.path, spec.token, f"a 'limit {rod.name} lower=... upper=...' line"
            )
        parent[i] = index[spec.parent]
        hinge[i] = spec.position
        offset[i] = spec.offset
        joint[i] = len(joint_names)
        joint_names.append(spec.coordinates[-1].name)
        joint_min.append(limit.lower)
        joint_max.append(limit.upper)
    terrain = figure.terrain
    length = np.array([rod.length for rod in figure.rods])
    endpoints = distinct_endpoints(parent, hinge, length)
    return BsrFigure(
        figure=figure,
        parent=parent,
        hinge=hinge,
        offset=offset,
        length=length,
        mass=np.array([rod.mass for rod in figure.rods]),
        com=np.array([rod.com for rod in figure.rods]),
        inertia=np.array([rod.inertia for rod in figure.rods]),
        joint=joint,
        joint_names=tuple(joint_names),
        joint_min=np.array(joint_min) + 0.0,  # + 0.0: a limit written -0 is 0 (numpy's uniform
        joint_max=np.array(joint_max) + 0.0,  # takes max -0 below min 0 and refuses the range)
        endpoints=endpoints,
        endpoint_names=tuple(f"{names[rod]}.{ENDPOINT_ENDS[end]}" for rod, end in endpoints),
        floor=terrain.height if terrain.kind == "floor" else math.nan,
        gravity=figure.gravity,
        root_angle=root.coordinates[2].name,
        root_x=root.coordinates[0].name,
    )


class RodFigure(Protocol):
    """What ``rod_figure_motion`` reads of a BSR figure, 2-D (BsrFigure) or 3-D (BsrFigure3D):
    the parsed figure, its rods' masses (kg), lengths (m), centres of mass and inertias, and
    gravity (m/s²)."""

    figure: Figure
    mass: np.ndarray
    length: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    gravity: float


def rod_figure_motion(
    bsr_figure: RodFigure,
    rod_ends: np.ndarray,
    com: np.ndarray,
    dt: float,
    contact: str,
    **three_d: object,
) -> FigureMotion:
    """A BSR figure's run (``bsr_figure`` a BsrFigure or a BsrFigure3D: its parsed ``figure``
    and its rods' ``mass``, ``length``, ``com``, ``inertia``) as the ``figure_motion``
    contract: rod_ends (N, rods, 2, D) m and com (N, D) m, one sample every simulator step of dt
    s from t = 0; ``three_d``: the 3-D group attributes (``dimensions``, ``heading_rod``, ...)."""
    return FigureMotion(
        t=np.arange(com.shape[0]) * dt,
        endpoints=rod_ends,
        com=com,
        rod_names=tuple(rod.name for rod in bsr_figure.figure.rods),
        rod_mass=bsr_figure.mass,
        rod_length=bsr_figure.length,
        rod_com=bsr_figure.com,
        rod_inertia=bsr_figure.inertia,
        gravity=bsr_figure.gravity,
        terrain=[list(vertex) for vertex in bsr_figure.figure.terrain.vertices],
        contact=contact,
        **three_d,
    )


def check_bsr_figure(figure: Figure) -> Joint:
    """The checks every BSR figure (2-D or 3-D) passes: a ``free`` root listed first and a flat
    floor at height 0 (or no terrain); returns the root's joint, raises SpecError at the
    offending line."""
    root = figure.root
    if root.kind != "free":
        raise SpecError.at(figure.path, root.token, "a 'free' root, as BSR figures fly and fall")
    if figure.rods[0].name != root.rod:
        raise SpecError.at(figure.path, figure.rods[0].token, f"the root rod '{root.rod}' first")
    if figure.terrain.kind not in ("none", "floor"):
        raise SpecError.at(
            figure.path, figure.terrain.token, "a flat 'terrain floor' for a BSR figure"
        )
    if figure.terrain.height != 0.0:
        raise SpecError.at(
            figure.path,
            figure.terrain.height_token,
            "a floor at height 0 for a BSR figure (its heights, falls and senses are measured "
            "from y = 0)",
        )
    return root


def load_rod_figure(figures_dir: str | Path, spec_path: str, token: Token) -> Figure:
    """The figure a spec names (``token``, its word in ``spec_path``), parsed from
    ``figures_dir``/NAME.fig; one that is missing, is a vehicle or is not a BSR figure
    (``check_bsr_figure``: a pendulum named by a .bsr) raises SpecError at the word (it was
    raised at the sound .fig, as if that were wrong)."""
    figure_path = Path(figures_dir) / f"{token.text}.fig"
    if not figure_path.is_file():
        raise SpecError.at(spec_path, token, f"a figure in {figures_dir}", f"no {figure_path}")
    parsed = parse_figure_spec(figure_path)
    if not isinstance(parsed, Figure):
        raise SpecError.at(spec_path, token, "a figure of rods, not a vehicle")
    try:
        check_bsr_figure(parsed)
    except SpecError as error:  # a sound figure, but not one for BSR: the spec chose it
        raise SpecError.at(spec_path, token, "a BSR figure", str(error)) from None
    return parsed


def load_bsr_figure(figures_dir: str | Path, spec_path: str, token: Token) -> BsrFigure:
    """The 2-D BSR figure a spec names (``load_rod_figure``, then ``bsr_figure``); a 3-D one
    raises SpecError at the spec's word (a composite script naming one was refused at the
    sound .fig, naming an internal module)."""
    parsed = load_rod_figure(figures_dir, spec_path, token)
    if parsed.dimensions == 3:
        raise SpecError.at(
            spec_path, token, f"a planar figure (composite motion is 2-D; '{token.text}' is 3-D)"
        )
    return bsr_figure(parsed)


def distinct_endpoints(parent: np.ndarray, hinge: np.ndarray, length: np.ndarray) -> np.ndarray:
    """(E, 2) rod and end of every distinct endpoint: a child's proximal end that sits on an
    end of its parent is that end, not a new point."""
    owner: dict[tuple[int, int], tuple[int, int]] = {}
    for k in range(parent.shape[0]):
        owner[(k, 1)] = (k, 1)
        p = parent[k]
        if p >= 0 and abs(hinge[k]) <= _SAME_POINT:
            owner[(k, 0)] = owner[(p, 0)]
        elif p >= 0 and abs(hinge[k] - length[p]) <= _SAME_POINT:
            owner[(k, 0)] = owner[(p, 1)]
        else:
            owner[(k, 0)] = (k, 0)
    distinct = sorted(set(owner.values()))
    return np.array(distinct, np.int64).reshape(-1, 2)
