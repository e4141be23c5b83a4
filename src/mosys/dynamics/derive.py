"""Equations of motion of a planar tree of rods, derived symbolically with sympy.

Lagrange's equations with generalized coordinates q (model.py):

    M(q) qdd = tau - h(q, qd) + g(q)  (+ joint-limit and contact forces, added by emit.py)

    M = sum over rods of  m Jvᵀ Jv + I Jωᵀ Jω          (Jv: the rod's centre-of-mass Jacobian)
    h = Ṁ qd - ∂T/∂q = sum of m Jvᵀ (J̇v qd)          (velocity-product terms)
    g = -∂V/∂q = -sum of m * gravity * ∂y_com/∂q

The equality ``Ṁ qd - ∂T/∂q = sum m Jvᵀ J̇v qd`` holds because each rod's angular Jacobian Jω
is constant (0/1 entries) in the plane. With points written as sums of phasors c·e(φ)
(model.py), Jv_a·Jv_b, Jv_aᵀ J̇v qd and ∂y/∂q come out in closed form:

    e(φ_r)·e(φ_s) = cos(φ_r - φ_s),  (R90 e(φ_r))·e(φ_s) = sin(φ_s - φ_r),
    J̇v qd = -sum over phasors of c_s ω_s² e(φ_s)   (ω_s: the rate of φ_s).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from mosys.dynamics.model import JacobianColumn, KinematicModel, PlanarPoint


@dataclass
class Equations:
    """The symbolic equations and quantities of one figure (SI units).

    ``mass_matrix``: n × n, symmetric. ``forcing``: n, the smooth generalized forces
    tau - h + g (joint limits and contacts are added by the emitted code).
    ``kinetic_energy``, ``potential_energy`` (gravity only), J. ``momentum``: (p_x, p_y,
    angular momentum about the origin). ``center_of_mass``: (x, y). ``endpoints``: per rod
    ((x, y) proximal, (x, y) distal). ``contact_points``: (x, y) per contact point;
    ``contact_velocities``: (vx, vy); ``contact_jacobians``: per contact, per coordinate
    (d x/d q_k, d y/d q_k).
    """

    model: KinematicModel
    mass_matrix: sp.Matrix
    forcing: tuple[sp.Expr, ...]
    kinetic_energy: sp.Expr
    potential_energy: sp.Expr
    momentum: tuple[sp.Expr, sp.Expr, sp.Expr]
    center_of_mass: tuple[sp.Expr, sp.Expr]
    endpoints: tuple[tuple[tuple[sp.Expr, sp.Expr], tuple[sp.Expr, sp.Expr]], ...]
    contact_points: tuple[tuple[sp.Expr, sp.Expr], ...]
    contact_velocities: tuple[tuple[sp.Expr, sp.Expr], ...]
    contact_jacobians: tuple[tuple[tuple[sp.Expr, sp.Expr], ...], ...]


def dot(a: JacobianColumn, b: JacobianColumn) -> sp.Expr:
    """a · b for two Jacobian columns, in closed form."""
    (ax, ay), (bx, by) = a.translation, b.translation
    total = ax * bx + ay * by
    for s in b.phasors:  # a.translation · R90 e(φ_s) = -ax sin φ_s + ay cos φ_s
        total += s.coefficient * (-ax * sp.sin(s.angle) + ay * sp.cos(s.angle))
    for r in a.phasors:
        total += r.coefficient * (-bx * sp.sin(r.angle) + by * sp.cos(r.angle))
        for s in b.phasors:  # R90 e(φ_r) · R90 e(φ_s) = cos(φ_r - φ_s)
            total += r.coefficient * s.coefficient * sp.cos(r.angle - s.angle)
    return total


def dot_bias(a: JacobianColumn, point: PlanarPoint, rates: dict[int, sp.Expr]) -> sp.Expr:
    """a · (J̇v qd) for ``point``: J̇v qd = -sum_s c_s ω_s² e(φ_s)."""
    ax, ay = a.translation
    total = sp.Integer(0)
    for s in point.phasors:
        weight = -s.coefficient * rates[s.rod] ** 2
        total += weight * (ax * sp.cos(s.angle) + ay * sp.sin(s.angle))
        for r in a.phasors:  # R90 e(φ_r) · e(φ_s) = sin(φ_s - φ_r)
            total += weight * r.coefficient * sp.sin(s.angle - r.angle)
    return total


def derive_equations(model: KinematicModel) -> Equations:
    """The equations of motion and the derived quantities of ``model``'s figure."""
    n = model.n
    rods = range(len(model.figure.rods))
    rates = dict(enumerate(model.rates))
    columns = [[model.column(model.com[i], k) for k in range(n)] for i in rods]
    mass = sp.zeros(n, n)
    for a in range(n):
        for b in range(a + 1):
            entry = sp.Integer(0)
            for i in rods:
                entry += model.masses[i] * dot(columns[i][a], columns[i][b])
                angular = model.angular_column(i, a) * model.angular_column(i, b)
                entry += model.inertias[i] * angular
            mass[a, b] = mass[b, a] = sp.expand(entry)
    forcing = []
    for a in range(n):
        bias = sum(
            (model.masses[i] * dot_bias(columns[i][a], model.com[i], rates) for i in rods),
            sp.Integer(0),
        )
        weight = sum(
            (model.masses[i] * columns[i][a].xy()[1] for i in rods),
            sp.Integer(0),
        )
        forcing.append(sp.expand(model.tau[a] - bias - model.gravity * weight))
    qd = sp.Matrix(model.qd)
    kinetic = sp.Rational(1, 2) * (qd.T * mass * qd)[0, 0]
    potential = model.gravity * sum(
        (model.masses[i] * model.com[i].xy()[1] for i in rods), sp.Integer(0)
    )
    total_mass = sum(model.masses, sp.Integer(0))
    com_xy = [point.xy() for point in model.com]
    center = tuple(
        sum((model.masses[i] * com_xy[i][axis] for i in rods), sp.Integer(0)) / total_mass
        for axis in (0, 1)
    )
    velocities = [_velocity(point, model) for point in model.com]
    linear = tuple(
        sp.expand(sum((model.masses[i] * velocities[i][axis] for i in rods), sp.Integer(0)))
        for axis in (0, 1)
    )
    angular = sum(
        (
            model.masses[i] * _moment_of_velocity(model.com[i], model)
            + model.inertias[i] * model.rates[i]
            for i in rods
        ),
        sp.Integer(0),
    )
    contact_jacobians = tuple(
        tuple(model.column(point, k).xy() for k in range(n)) for point in model.contacts
    )
    return Equations(
        model=model,
        mass_matrix=mass,
        forcing=tuple(forcing),
        kinetic_energy=sp.expand(kinetic),
        potential_energy=potential,
        momentum=(linear[0], linear[1], sp.expand(angular)),
        center_of_mass=(center[0], center[1]),
        endpoints=tuple((model.proximal[i].xy(), model.distal[i].xy()) for i in rods),
        contact_points=tuple(point.xy() for point in model.contacts),
        contact_velocities=tuple(_velocity(point, model) for point in model.contacts),
        contact_jacobians=contact_jacobians,
    )


def _base_velocity(point: PlanarPoint, model: KinematicModel) -> tuple[sp.Expr, sp.Expr]:
    """The rate of ``point.base``: the free root's (x, y) rates, or 0 for a pivot."""
    return tuple(  # type: ignore[return-value]
        sum((sp.diff(b, q) * qd for q, qd in zip(model.q, model.qd, strict=True)), sp.Integer(0))
        for b in point.base
    )


def _velocity(point: PlanarPoint, model: KinematicModel) -> tuple[sp.Expr, sp.Expr]:
    """d(point)/dt = base rate + sum_s c_s ω_s R90 e(φ_s)."""
    vx, vy = _base_velocity(point, model)
    for s in point.phasors:
        speed = s.coefficient * model.rates[s.rod]
        vx -= speed * sp.sin(s.angle)
        vy += speed * sp.cos(s.angle)
    return vx, vy


def _moment_of_velocity(point: PlanarPoint, model: KinematicModel) -> sp.Expr:
    """point × d(point)/dt (z component), in closed form:
    e(φ_r) × R90 e(φ_s) = cos(φ_s - φ_r); b × R90 e(φ) = bx cos φ + by sin φ;
    e(φ) × ḃ = cos φ ḃy - sin φ ḃx."""
    bx, by = point.base
    bvx, bvy = _base_velocity(point, model)
    total = bx * bvy - by * bvx
    for s in point.phasors:
        speed = s.coefficient * model.rates[s.rod]
        total += speed * (bx * sp.cos(s.angle) + by * sp.sin(s.angle))
        total += s.coefficient * (sp.cos(s.angle) * bvy - sp.sin(s.angle) * bvx)
        for r in point.phasors:
            total += r.coefficient * speed * sp.cos(s.angle - r.angle)
    return sp.expand(total)
