"""The kinematics of a parsed figure as sympy expressions: every point of the figure as a base
point plus a sum of rotating vectors ("phasors"), one per rod on its path from the root.

A rod's absolute angle ``phi`` is linear in the coordinates with unit coefficients (root: its
angle coordinate; child: parent's angle + offset + its own coordinate), so the point
``base + sum(c_r * (cos phi_r, sin phi_r))`` has, for an angle coordinate ``q_k``, the Jacobian
column ``R90 * sum(c_r * e(phi_r) for the rods r whose angle contains q_k)``. derive.py builds
the equations of motion from that structure, which keeps them in closed form
(``cos(phi_r - phi_s)`` instead of ``sin² + cos²`` sums that would need trigsimp).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from mosys.parsing.figure import (
    ROD_INERTIA_RANGE,
    ROD_LENGTH_RANGE,
    ROD_MASS_RANGE,
    Figure,
)
from mosys.parsing.tokens import SpecError


@dataclass(frozen=True)
class Phasor:
    """``coefficient * (cos angle, sin angle)``: ``coefficient`` in metres, ``angle`` the
    absolute angle of rod ``rod`` (index in file order)."""

    coefficient: sp.Expr
    angle: sp.Expr
    rod: int


@dataclass(frozen=True)
class PlanarPoint:
    """A point of the figure: ``base`` (x, y) (the pivot, or the free root's x, y coordinates)
    plus the sum of ``phasors``, at most one per rod."""

    base: tuple[sp.Expr, sp.Expr]
    phasors: tuple[Phasor, ...]

    def xy(self) -> tuple[sp.Expr, sp.Expr]:
        x = self.base[0] + sum(p.coefficient * sp.cos(p.angle) for p in self.phasors)
        y = self.base[1] + sum(p.coefficient * sp.sin(p.angle) for p in self.phasors)
        return x, y

    def plus(self, coefficient: sp.Expr, angle: sp.Expr, rod: int) -> PlanarPoint:
        """This point moved by ``coefficient`` metres along rod ``rod``'s direction ``angle``."""
        phasors = list(self.phasors)
        for index, phasor in enumerate(phasors):
            if phasor.rod == rod:
                phasors[index] = Phasor(phasor.coefficient + coefficient, angle, rod)
                break
        else:
            phasors.append(Phasor(coefficient, angle, rod))
        phasors = [phasor for phasor in phasors if phasor.coefficient != 0]
        return PlanarPoint(self.base, tuple(phasors))


@dataclass(frozen=True)
class JacobianColumn:
    """d(point)/d(q_k) = ``translation`` + R90 * sum(``phasors``) (R90: rotation by +90°)."""

    translation: tuple[sp.Expr, sp.Expr]
    phasors: tuple[Phasor, ...]

    def xy(self) -> tuple[sp.Expr, sp.Expr]:
        x = self.translation[0] - sum(p.coefficient * sp.sin(p.angle) for p in self.phasors)
        y = self.translation[1] + sum(p.coefficient * sp.cos(p.angle) for p in self.phasors)
        return x, y


@dataclass
class KinematicModel:
    """Symbols and point expressions of one figure.

    ``q``, ``qd``, ``tau``: one symbol per coordinate (``q_0``, ``qd_0``, ``tau_0`` ...).
    ``constants``: symbol name -> value (SI) of every physical constant left symbolic (the
    emitted module defines them as module-level constants); constants equal to 0 are substituted
    by 0 so their terms vanish. ``angles``: each rod's absolute angle (rad); ``proximal``,
    ``distal``, ``com``: each rod's points; ``contacts``: each contact point.
    """

    figure: Figure
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    tau: tuple[sp.Symbol, ...]
    constants: dict[str, float]
    masses: tuple[sp.Expr, ...]
    inertias: tuple[sp.Expr, ...]
    gravity: sp.Expr
    angles: tuple[sp.Expr, ...]
    rates: tuple[sp.Expr, ...]
    proximal: tuple[PlanarPoint, ...]
    distal: tuple[PlanarPoint, ...]
    com: tuple[PlanarPoint, ...]
    contacts: tuple[PlanarPoint, ...]

    @property
    def n(self) -> int:
        return len(self.q)

    def column(self, point: PlanarPoint, k: int) -> JacobianColumn:
        """The Jacobian column of ``point`` for coordinate ``k``."""
        coordinate = self.figure.coordinates[k]
        zero = sp.Integer(0)
        if coordinate.kind == "x":
            return JacobianColumn((sp.Integer(1), zero), ())
        if coordinate.kind == "y":
            return JacobianColumn((zero, sp.Integer(1)), ())
        moving = tuple(
            Phasor(p.coefficient * sp.diff(p.angle, self.q[k]), p.angle, p.rod)
            for p in point.phasors
            if sp.diff(p.angle, self.q[k]) != 0
        )
        return JacobianColumn((zero, zero), moving)

    def angular_column(self, rod: int, k: int) -> sp.Expr:
        """d(angle of rod)/d(q_k): 1 or 0."""
        return sp.diff(self.angles[rod], self.q[k])


def constant_name(kind: str, rod: str) -> str:
    """The emitted module's name for a physical constant of a rod: ``mass_link``."""
    return f"{kind}_{rod}"


def build_model(figure: Figure) -> KinematicModel:
    """The kinematics of ``figure``; rods are placed root first, each after its parent. A 3-D
    figure raises SpecError at its first ball line (only the 3-D BSR simulator moves those)."""
    ball = next((joint for joint in figure.joints if joint.kind == "ball"), None)
    if ball is not None:
        raise SpecError.at(
            figure.path, ball.token, "a planar figure (ball joints are for 3-D BSR figures)"
        )
    _check_rods(figure)
    n = len(figure.coordinates)
    q = tuple(sp.Symbol(f"q_{k}", real=True) for k in range(n))
    qd = tuple(sp.Symbol(f"qd_{k}", real=True) for k in range(n))
    tau = tuple(sp.Symbol(f"tau_{k}", real=True) for k in range(n))
    constants: dict[str, float] = {}

    def constant(name: str, value: float) -> sp.Expr:
        if value == 0:
            return sp.Integer(0)
        if not math.isfinite(value):
            raise ValueError(f"{figure.path}: constant {name} = {value!r} is not finite")
        constants[name] = float(value)
        return sp.Symbol(name, real=True)

    gravity = constant("GRAVITY", figure.gravity)
    index = {coordinate.name: k for k, coordinate in enumerate(figure.coordinates)}
    rods = figure.rods
    rod_index = {rod.name: i for i, rod in enumerate(rods)}
    lengths = [constant(constant_name("length", rod.name), rod.length) for rod in rods]
    masses = tuple(constant(constant_name("mass", rod.name), rod.mass) for rod in rods)
    coms = [constant(constant_name("com", rod.name), rod.com) for rod in rods]
    inertias = tuple(constant(constant_name("inertia", rod.name), rod.inertia) for rod in rods)

    angles: list[sp.Expr | None] = [None] * len(rods)
    proximal: list[PlanarPoint | None] = [None] * len(rods)
    order = _tree_order(figure)
    for name in order:
        i = rod_index[name]
        joint = figure.joint(name)
        angle_q = q[index[joint.coordinates[-1].name]]
        if joint.kind == "pin":
            base = (constant("pivot_x", joint.pivot[0]), constant("pivot_y", joint.pivot[1]))
            proximal[i] = PlanarPoint(base, ())
            angles[i] = constant(constant_name("offset", name), joint.offset) + angle_q
        elif joint.kind == "free":
            x, y = joint.coordinates[0].name, joint.coordinates[1].name
            proximal[i] = PlanarPoint((q[index[x]], q[index[y]]), ())
            angles[i] = angle_q
        else:
            assert joint.parent is not None
            p = rod_index[joint.parent]
            parent_point, parent_angle = proximal[p], angles[p]
            assert parent_point is not None and parent_angle is not None
            hinge = constant(constant_name("hinge", name), joint.position)
            offset = constant(constant_name("offset", name), joint.offset)
            proximal[i] = parent_point.plus(hinge, parent_angle, p)
            angles[i] = parent_angle + offset + angle_q
    placed_angles = tuple(a for a in angles if a is not None)
    placed = tuple(p for p in proximal if p is not None)
    assert len(placed_angles) == len(rods) and len(placed) == len(rods)
    distal = tuple(placed[i].plus(lengths[i], placed_angles[i], i) for i in range(len(rods)))
    com = tuple(placed[i].plus(coms[i] * lengths[i], placed_angles[i], i) for i in range(len(rods)))
    contacts = []
    for c, contact in enumerate(figure.contacts):
        i = rod_index[contact.rod]
        fraction = constant(f"contact_fraction_{c}", contact.fraction)
        contacts.append(placed[i].plus(fraction * lengths[i], placed_angles[i], i))
    rates = tuple(
        sum((sp.diff(angle, q[k]) * qd[k] for k in range(n)), sp.Integer(0))
        for angle in placed_angles
    )
    return KinematicModel(
        figure=figure,
        q=q,
        qd=qd,
        tau=tau,
        constants=constants,
        masses=masses,
        inertias=inertias,
        gravity=gravity,
        angles=placed_angles,
        rates=rates,
        proximal=placed,
        distal=distal,
        com=com,
        contacts=tuple(contacts),
    )


def _check_rods(figure: Figure) -> None:
    """Every rod's length, mass and inertia within the parser's ranges (a Figure built in code
    skips the parser): outside them the mass matrix over- or underflows and the kernels divide
    by zero. SpecError at the rod's line."""
    for rod in figure.rods:
        for what, value, (low, high) in (
            ("length (m)", rod.length, ROD_LENGTH_RANGE),
            ("mass (kg)", rod.mass, ROD_MASS_RANGE),
            ("inertia (kg·m²)", rod.inertia, ROD_INERTIA_RANGE),
        ):
            if not low <= value <= high:
                raise SpecError.at(
                    figure.path,
                    rod.token,
                    f"a rod whose {what} is from {low:g} to {high:g} (it is {value:g})",
                )


def _tree_order(figure: Figure) -> list[str]:
    """Rod names, each after its parent (the parser has ruled out cycles)."""
    children: dict[str, list[str]] = {}
    for joint in figure.joints:
        if joint.parent is not None:
            children.setdefault(joint.parent, []).append(joint.rod)
    order = [figure.root.rod]
    for name in order:
        order.extend(children.get(name, []))
    return order
