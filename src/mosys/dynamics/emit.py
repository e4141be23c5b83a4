"""The text of a generated dynamics module: derived equations -> plain Python + numba source.

``emit_module`` only makes text (compile.py writes it). The emitted module imports math, numpy
and numba, never sympy or mosys, and defines the names listed in the README ("The generated
module", under "Figure spec"). Each function's expressions go through ``sympy.cse``; the mass
matrix is solved by an unrolled LDLᵀ factorization (no np.linalg: numba's needs SciPy).
"""

from __future__ import annotations

import json
import math
import textwrap
from collections.abc import Sequence

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from mosys.dynamics.derive import Equations
from mosys.parsing.figure import ContactPoint, Figure

INDENT = "    "
# The equations (``_qdd_fill``) are inlined (numba's IR inlining) into their callers,
# derivative_into among them, which LLVM then inlines into the DP's kernel specialised to the
# model (``kernels.specialise``): the grounded Luxo's exit transitions took a fifth less time,
# and a model's cold load about as long as before (4.4 s against 4.2 s, the full Luxo).
# Inlining more cost more than it gave: the contact helpers too (called once per contact
# point) took that load to 11.6 s; derivative_into too, the DP's kernel from 28 s to 87 s to
# compile cold.
INLINED = 'inline="always"'
_PRINTER = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})


def _literal(value: float) -> str:
    """A float as exact Python source: repr, or math.inf."""
    value = float(value)
    if math.isinf(value):
        return "math.inf" if value > 0 else "-math.inf"
    return repr(value)


def _string(text: str) -> str:
    """A str as Python source, double-quoted."""
    return json.dumps(text)


def _tuple(items: Sequence[str]) -> str:
    """Python tuple source from item sources: ``()``, ``(a,)``, ``(a, b)``."""
    if len(items) == 1:
        return f"({items[0]},)"
    return "(" + ", ".join(items) + ")"


def _code(expr: sp.Expr) -> str:
    if expr.is_Number:
        return _literal(float(expr))
    return _PRINTER.doprint(expr)


class _Body:
    """The statements of one emitted function; ``compute`` adds a CSE'd block of scalars."""

    def __init__(self, equations: Equations):
        self.model = equations.model
        self.lines: list[str] = []
        self.used: set[sp.Symbol] = set()
        self.zero: set[str] = set()  # names whose value is exactly 0
        self.trig_count = 0  # sinK, cosK names made by _share_trig

    def compute(self, outputs: Sequence[tuple[str, sp.Expr]]) -> None:
        """Assign each (name, expr), sharing common subexpressions (temporaries t0, t1...)."""
        if not outputs:
            return
        names = [name for name, _ in outputs]
        exprs = [sp.sympify(expr) for _, expr in outputs]
        for expr in exprs:
            self.used |= expr.free_symbols
        exprs = self._share_trig(exprs)
        temporaries, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"))
        for symbol, expr in temporaries:
            self.lines.append(f"{symbol} = {_code(expr)}")
        for name, expr in zip(names, reduced, strict=True):
            if expr == 0 and name.isidentifier():
                self.zero.add(name)  # not assigned: users go through ref()
            else:
                self.lines.append(f"{name} = {_code(expr)}")

    def _share_trig(self, exprs: list[sp.Expr]) -> list[sp.Expr]:
        """``exprs`` with the sine and cosine of each angle that depends on the coordinates
        replaced by names (``sinK``, ``cosK``) assigned first, as lines of this body. An angle
        that differs from a smaller one by a constant, or by an angle whose sine and cosine are
        needed anyway, gets them from those by the angle-sum formulas rather than by two more
        calls: a chain's absolute rod angles are sums of its joint angles (the grounded Luxo's
        equations: 4 calls where they made 6, about 30 % of their time)."""
        coordinates = set(self.model.q)

        def depth(angle: sp.Expr) -> tuple:
            return (
                len(angle.free_symbols & coordinates),
                sp.count_ops(angle),
                sp.default_sort_key(angle),
            )

        angles = sorted(
            {
                f.args[0]
                for expr in exprs
                for f in expr.atoms(sp.sin, sp.cos)
                if f.args[0].free_symbols & coordinates
            },
            key=depth,
        )
        pairs: dict[sp.Expr, tuple[sp.Symbol, sp.Symbol]] = {}
        definitions: dict[sp.Symbol, sp.Expr] = {}

        def sine_cosine(angle: sp.Expr) -> tuple[sp.Expr, sp.Expr] | None:
            """(sin, cos) of ``angle`` without a call, or None."""
            if not angle.free_symbols & coordinates:
                return sp.sin(angle), sp.cos(angle)  # constants: numba folds them
            if angle in pairs:
                return pairs[angle]
            if -angle in pairs:
                sine, cosine = pairs[-angle]
                return -sine, cosine
            return None

        for angle in angles:
            sine, cosine = (sp.Symbol(f"{f}{self.trig_count}") for f in ("sin", "cos"))
            self.trig_count += 1
            definitions[sine], definitions[cosine] = sp.sin(angle), sp.cos(angle)
            for smaller, (sine_b, cosine_b) in pairs.items():
                rest = sine_cosine(sp.expand(angle - smaller))
                if rest is not None:
                    sine_r, cosine_r = rest
                    definitions[sine] = sine_b * cosine_r + cosine_b * sine_r
                    definitions[cosine] = cosine_b * cosine_r - sine_b * sine_r
                    break
            pairs[angle] = (sine, cosine)
        replaced = [
            expr.xreplace(
                {
                    f: pairs[f.args[0]][1 if f.func is sp.cos else 0]
                    for f in expr.atoms(sp.sin, sp.cos)
                    if f.args[0] in pairs
                }
            )
            for expr in exprs
        ]
        needed = set().union(*(expr.free_symbols for expr in replaced))
        for name in reversed(definitions):  # a definition uses only earlier ones
            if name in needed:
                needed |= definitions[name].free_symbols
        self.lines.extend(
            f"{name} = {_code(definition)}"
            for name, definition in definitions.items()
            if name in needed
        )
        return replaced

    def ref(self, name: str) -> str:
        """``name``, or ``0.0`` if ``compute`` found it to be exactly 0 (and left it out)."""
        return "0.0" if name in self.zero else name

    def add(self, *lines: str) -> None:
        self.lines.extend(lines)

    def need(self, *symbols: sp.Symbol) -> None:
        self.used |= set(symbols)

    def text(self, header: Sequence[str]) -> str:
        """``header`` (decorator, def line, docstring), then the unpacking of q/qd/tau entries
        that the body uses, then the body."""
        unpack = []
        for vector, symbols in (
            ("q", self.model.q),
            ("qd", self.model.qd),
            ("tau", self.model.tau),
        ):
            for k, symbol in enumerate(symbols):
                if symbol in self.used:
                    unpack.append(f"{symbol} = {vector}[{k}]")
        body = [INDENT + line if line else "" for line in unpack + self.lines]
        return "\n".join([*header, *body]) + "\n"


def _def(
    name: str, arguments: str, doc: str, signature: str | None = None, inline: bool = False
) -> list[str]:
    """Decorator, def line and docstring (wrapped at 96 columns) of an emitted function;
    ``inline``: numba inlines its body where it is called (``INLINED``)."""
    options = [signature] if signature else []
    options.append("cache=True")
    if inline:
        options.append(INLINED)
    decorator = f"@njit({', '.join(options)})"
    wrapped = textwrap.wrap(doc, width=96, initial_indent=INDENT + '"""', subsequent_indent=INDENT)
    if len(wrapped) == 1:
        wrapped[0] += '"""'
    else:
        wrapped.append(INDENT + '"""')
    return [decorator, f"def {name}({arguments}):", *wrapped]


def emit_module(equations: Equations, spec_path: str, spec_sha256: str, version: str) -> str:
    """The source text of the dynamics module of ``equations`` (see module docstring)."""
    model = equations.model
    figure = model.figure
    has_contact_forces = bool(figure.contacts) and bool(figure.terrain.vertices)
    parts = [
        _header(figure, spec_path, spec_sha256, version),
        _metadata(figure, spec_path, spec_sha256, has_contact_forces),
        _constants(model.constants),
    ]
    if has_contact_forces:
        parts.append(_terrain_helpers(figure))
    parts += [
        _mass_matrix(equations),
        _forcing(equations, has_contact_forces),
        _qdd(equations, has_contact_forces),
        _derivative(equations),
        _endpoints(equations),
        _center_of_mass(equations),
        _energy(equations, has_contact_forces),
        _momentum(equations),
        _contact_points(equations),
        _contact_forces(equations, has_contact_forces),
    ]
    return "\n\n\n".join(part.rstrip("\n") for part in parts) + "\n"


# --- module head ------------------------------------------------------------------------------


def _header(figure: Figure, spec_path: str, spec_sha256: str, version: str) -> str:
    stamp = (
        f"# Generated by mosys {version} from {spec_path} (spec_sha256 {spec_sha256}). "
        "Edit the spec, not this file."
    )
    return f'''{stamp}
"""Equations of motion of the planar figure '{figure.name}':
mass_matrix(q) @ qdd == forcing(q, qd, tau).

q: the coordinates (Q_NAMES; radians for angles, metres for x/y); qd: their rates (QD_NAMES);
tau: one generalized force per coordinate (N·m for angles, N for x/y; TAU_NAMES names the
actuated ones, the others are normally 0). Arrays are float64, SI units. Joint limits and
contact forces against the terrain are part of forcing() and qdd().
"""

import math

import numpy as np
from numba import njit, types

_VECTOR = types.float64[::1]  # C-contiguous float64 1-D array
_RODS_ARRAY = types.float64[:, :, ::1]  # (n_rods, 2, 2)'''


def _metadata(figure: Figure, spec_path: str, spec_sha256: str, has_contact_forces: bool) -> str:
    coordinates = figure.coordinates
    rods = figure.rods

    def names(values: Sequence[str]) -> str:
        return _tuple([_string(value) for value in values])

    def floats(values: Sequence[float]) -> str:
        return _tuple([_literal(value) for value in values])

    def ints(values: Sequence[int]) -> str:
        return _tuple([str(value) for value in values])

    if has_contact_forces:
        contact_model = (
            "penalty: spring-damper normal force at each contact point inside the ground "
            "(below the terrain polyline), regularized Coulomb friction"
        )
    else:
        contact_model = "none"
    terrain = json.dumps([[x, y] for x, y in figure.terrain.vertices])
    limits = figure.limits
    contacts = figure.contacts
    return "\n".join(
        [
            'MODEL_KIND = "figure"  # an articulated figure (a built-in vehicle says "vehicle")',
            f"SPEC_PATH = {_string(spec_path)}  # as given to mosys compile",
            f"SPEC_SHA256 = {_string(spec_sha256)}",
            f"Q_NAMES = {names(figure.q_names)}",
            f"QD_NAMES = {names(figure.qd_names)}",
            f"Q_IS_ANGLE = {_tuple([str(c.is_angle) for c in coordinates])}",
            f"TAU_NAMES = {names(figure.tau_names)}",
            "",
            "# The first-order view the controllers use: state = q‖qd, inputs = tau.",
            "STATE_NAMES = Q_NAMES + QD_NAMES",
            "STATE_UNITS = "
            + _tuple(
                [_string("deg" if c.is_angle else "m") for c in coordinates]
                + [_string("deg/s" if c.is_angle else "m/s") for c in coordinates]
            )
            + "  # spec units",
            f"COORDINATE_COUNT = {len(coordinates)}  # state[:COORDINATE_COUNT] is q",
            "INPUT_NAMES = TAU_NAMES",
            "INPUT_UNITS = "
            + _tuple([_string("N*m" if c.is_angle else "N") for c in coordinates])
            + "  # spec units of the controls (SI)",
            "",
            "# The figure, for figure_motion (DESIGN.md): rods in file order, SI units.",
            f"ROD_NAMES = {names([rod.name for rod in rods])}",
            f"ROD_PARENT = {ints(figure.parent_index())}  # index of the parent rod, -1: root",
            f"ROD_MASS = {floats([rod.mass for rod in rods])}  # kg",
            f"ROD_LENGTH = {floats([rod.length for rod in rods])}  # m",
            f"ROD_COM = {floats([rod.com for rod in rods])}  # fraction, proximal -> distal",
            f"ROD_INERTIA = {floats([rod.inertia for rod in rods])}  # kg m² about the COM",
            f"ROOT_KIND = {_string(figure.root.kind)}  # 'pin' (fixed pivot) or 'free'",
            f"GRAVITY = {_literal(figure.gravity)}  # m/s², pointing down (-y)",
            f"TERRAIN_JSON = {_string(terrain)}  # ground polyline [[x, y], ...], m",
            f"CONTACT_MODEL = {_string(contact_model)}",
            "",
            "# Joint limits (applied in forcing): one-sided spring-dampers on coordinates.",
            f"LIMIT_COORDINATE = {ints([figure.coordinate_index(c.coordinate) for c in limits])}",
            f"LIMIT_LOWER = {floats([lim.lower for lim in limits])}  # rad",
            f"LIMIT_UPPER = {floats([lim.upper for lim in limits])}  # rad",
            f"LIMIT_STIFFNESS = {floats([lim.stiffness for lim in limits])}  # N m/rad",
            f"LIMIT_DAMPING = {floats([lim.damping for lim in limits])}  # N m s/rad",
            "",
            "# Contact points (applied in forcing when there is terrain).",
            f"CONTACT_ROD = {ints([figure.rod_index(c.rod) for c in contacts])}",
            f"CONTACT_FRACTION = {floats([c.fraction for c in contacts])}  # along the rod",
            f"CONTACT_STIFFNESS = {floats([c.stiffness for c in contacts])}  # N/m",
            f"CONTACT_DAMPING = {floats([c.damping for c in contacts])}  # N s/m",
            f"CONTACT_FRICTION = {floats([c.friction for c in contacts])}  # Coulomb coefficient",
            f"CONTACT_SLIP = {floats([c.slip for c in contacts])}  # m/s",
        ]
    )


def _constants(constants: dict[str, float]) -> str:
    lines = ["# Physical constants in the equations below (SI; zero ones are folded away)."]
    lines += [
        f"{name} = {_literal(value)}" for name, value in constants.items() if name != "GRAVITY"
    ]
    return "\n".join(lines)


def _terrain_helpers(figure: Figure) -> str:
    xs = ", ".join(_literal(x) for x, _ in figure.terrain.vertices)
    ys = ", ".join(_literal(y) for _, y in figure.terrain.vertices)
    return f'''_TERRAIN_X = np.array([{xs}])
_TERRAIN_Y = np.array([{ys}])


@njit(cache=True)
def _ground_penetration(px, py):
    """How deep (m) the point (px, py) lies inside the ground (solid below the terrain polyline,
    between its first and last x), and the unit normal (nx, ny) from it towards the nearest
    point of the terrain. (0.0, 0.0, 1.0) when the point is not inside."""
    count = _TERRAIN_X.shape[0]
    if px < _TERRAIN_X[0] or px > _TERRAIN_X[count - 1]:
        return 0.0, 0.0, 1.0
    inside = False
    for k in range(count - 1):
        x0 = _TERRAIN_X[k]
        x1 = _TERRAIN_X[k + 1]
        if x0 < x1 and x0 <= px <= x1:
            y0 = _TERRAIN_Y[k]
            inside = py < y0 + (_TERRAIN_Y[k + 1] - y0) * (px - x0) / (x1 - x0)
            break
    if not inside:
        return 0.0, 0.0, 1.0
    best = math.inf
    nearest_x = px
    nearest_y = py
    for k in range(count - 1):
        x0 = _TERRAIN_X[k]
        y0 = _TERRAIN_Y[k]
        dx = _TERRAIN_X[k + 1] - x0
        dy = _TERRAIN_Y[k + 1] - y0
        t = ((px - x0) * dx + (py - y0) * dy) / (dx * dx + dy * dy)
        t = min(max(t, 0.0), 1.0)
        cx = x0 + t * dx
        cy = y0 + t * dy
        distance2 = (cx - px) * (cx - px) + (cy - py) * (cy - py)
        if distance2 < best:
            best = distance2
            nearest_x = cx
            nearest_y = cy
    depth = math.sqrt(best)
    if depth == 0.0:
        return 0.0, 0.0, 1.0
    return depth, (nearest_x - px) / depth, (nearest_y - py) / depth


@njit(cache=True)
def _contact_force(px, py, vx, vy, stiffness, damping, friction, slip):
    """The ground's force (fx, fy), N, on a contact point at (px, py) moving at (vx, vy):
    normal = stiffness * depth - damping * (normal speed), never pulling; friction opposes the
    tangential velocity with friction * normal * min(1, speed / slip)."""
    depth, nx, ny = _ground_penetration(px, py)
    if depth <= 0.0:
        return 0.0, 0.0
    normal_speed = vx * nx + vy * ny
    normal = stiffness * depth - damping * normal_speed
    if normal <= 0.0:
        return 0.0, 0.0
    fx = normal * nx
    fy = normal * ny
    tx = vx - normal_speed * nx
    ty = vy - normal_speed * ny
    speed = math.sqrt(tx * tx + ty * ty)
    if speed > 0.0 and friction > 0.0:
        scale = friction * normal / max(speed, slip)
        fx -= scale * tx
        fy -= scale * ty
    return fx, fy'''


# --- the functions ----------------------------------------------------------------------------


def _mass_outputs(equations: Equations) -> list[tuple[str, sp.Expr]]:
    n = equations.model.n
    return [(f"M_{i}_{j}", equations.mass_matrix[i, j]) for i in range(n) for j in range(i + 1)]


def _contact_outputs(equations: Equations, jacobians: bool) -> list[tuple[str, sp.Expr]]:
    outputs = []
    for c, (point, velocity) in enumerate(
        zip(equations.contact_points, equations.contact_velocities, strict=True)
    ):
        outputs += [(f"cx_{c}", point[0]), (f"cy_{c}", point[1])]
        outputs += [(f"cvx_{c}", velocity[0]), (f"cvy_{c}", velocity[1])]
        if jacobians:
            for k, (jx, jy) in enumerate(equations.contact_jacobians[c]):
                outputs += [(f"cjx_{c}_{k}", jx), (f"cjy_{c}_{k}", jy)]
    return outputs


def _minus(value: float) -> str:
    """Source for ``- value``: ``- 1.5`` or ``+ 1.5``."""
    return f"- {_literal(value)}" if value >= 0 else f"+ {_literal(-value)}"


def _limit_lines(equations: Equations, body: _Body, target: str) -> None:
    """Add each joint limit's one-sided spring-damper torque to ``{target}_{k}``."""
    model = equations.model
    figure = model.figure
    for limit in figure.limits:
        k = figure.coordinate_index(limit.coordinate)
        q, qd = model.q[k], model.qd[k]
        body.need(q, qd)
        bounds = [
            f"{side} {math.degrees(value):g}"
            for side, value in (("lower", limit.lower), ("upper", limit.upper))
            if math.isfinite(value)
        ]
        body.add(f"# limit of '{limit.coordinate}': {', '.join(bounds)} degrees")
        damper = f" - {_literal(limit.damping)} * {qd}" if limit.damping else ""
        branch = "if"
        for bound, sign, push in ((limit.upper, ">", "<"), (limit.lower, "<", ">")):
            if not math.isfinite(bound):
                continue
            body.add(
                f"{branch} {q} {sign} {_literal(bound)}:",
                f"{INDENT}push = -{_literal(limit.stiffness)} * ({q} {_minus(bound)}){damper}",
                f"{INDENT}if push {push} 0.0:",
                f"{INDENT}{INDENT}{target}_{k} += push",
            )
            branch = "elif"


def _contact_call(body: _Body, c: int, contact: ContactPoint) -> str:
    """Source of the call giving contact point ``c``'s force (fx, fy)."""
    point = ", ".join(body.ref(f"{name}_{c}") for name in ("cx", "cy", "cvx", "cvy"))
    parameters = (contact.stiffness, contact.damping, contact.friction, contact.slip)
    return f"_contact_force({point}, {', '.join(_literal(value) for value in parameters)})"


def _contact_lines(equations: Equations, body: _Body, target: str) -> None:
    """Add each contact point's generalized force Jᵀ F to ``{target}_{k}``."""
    model = equations.model
    for c, contact in enumerate(model.figure.contacts):
        body.add(f"fx, fy = {_contact_call(body, c, contact)}")
        for k in range(model.n):
            terms = [
                f"{name} * {force}"
                for name, force in ((f"cjx_{c}_{k}", "fx"), (f"cjy_{c}_{k}", "fy"))
                if name not in body.zero
            ]
            if terms:
                body.add(f"{target}_{k} += " + " + ".join(terms))


def _mass_matrix(equations: Equations) -> str:
    n = equations.model.n
    body = _Body(equations)
    body.compute(_mass_outputs(equations))
    body.add(f"out = np.empty(({n}, {n}))")
    for i in range(n):
        for j in range(i + 1):
            body.add(f"out[{i}, {j}] = {body.ref(f'M_{i}_{j}')}")
            if i != j:
                body.add(f"out[{j}, {i}] = {body.ref(f'M_{i}_{j}')}")
    body.add("return out")
    doc = f"M(q): ({n}, {n}) float64, symmetric positive definite (kg, kg m, kg m²)."
    return body.text(_def("mass_matrix", "q", doc))


def _forcing_body(equations: Equations, has_contact_forces: bool, mass: bool) -> _Body:
    n = equations.model.n
    body = _Body(equations)
    outputs = _mass_outputs(equations) if mass else []
    outputs += [(f"f_{k}", equations.forcing[k]) for k in range(n)]
    if has_contact_forces:
        outputs += _contact_outputs(equations, jacobians=True)
    body.compute(outputs)
    body.need(*equations.model.tau)  # keep every tau entry in the signature's use
    _limit_lines(equations, body, "f")
    if has_contact_forces:
        _contact_lines(equations, body, "f")
    return body


def _forcing(equations: Equations, has_contact_forces: bool) -> str:
    n = equations.model.n
    body = _forcing_body(equations, has_contact_forces, mass=False)
    body.add(f"out = np.empty({n})")
    body.add(*(f"out[{k}] = {body.ref(f'f_{k}')}" for k in range(n)))
    body.add("return out")
    doc = (
        f"The right-hand side: tau - Coriolis/centrifugal + gravity + joint limits + contacts; "
        f"({n},) float64 (N·m for angles, N for x/y)."
    )
    return body.text(_def("forcing", "q, qd, tau", doc))


def _solve_lines(n: int, zero: set[str]) -> list[str]:
    """Unrolled LDLᵀ of M (scalars M_i_j, i >= j) and the solution of M x = f (scalars f_i),
    written to out[i]. Terms with a factor known to be 0 are left out."""
    lines: list[str] = []
    zero = set(zero)

    def assign(name: str, base: str, products: list[tuple[str, str]]) -> None:
        terms = [f" - {a} * {b}" for a, b in products if a not in zero and b not in zero]
        if base in zero and not terms:
            zero.add(name)
            return
        start = base if base not in zero else "0.0"
        lines.append(f"{name} = {start}{''.join(terms)}")

    for j in range(n):
        assign(f"D_{j}", f"M_{j}_{j}", [(f"L_{j}_{k}", f"LD_{j}_{k}") for k in range(j)])
        lines.append(f"inverse_D_{j} = 1.0 / D_{j}")
        for i in range(j + 1, n):
            assign(f"LD_{i}_{j}", f"M_{i}_{j}", [(f"L_{i}_{k}", f"LD_{j}_{k}") for k in range(j)])
            if f"LD_{i}_{j}" in zero:
                zero.add(f"L_{i}_{j}")
            else:
                lines.append(f"L_{i}_{j} = LD_{i}_{j} * inverse_D_{j}")
    for i in range(n):
        assign(f"z_{i}", f"f_{i}", [(f"L_{i}_{k}", f"z_{k}") for k in range(i)])
    for i in reversed(range(n)):
        z = f"z_{i} * inverse_D_{i}" if f"z_{i}" not in zero else "0.0"
        terms = "".join(
            f" - L_{k}_{i} * x_{k}" for k in range(i + 1, n) if f"L_{k}_{i}" not in zero
        )
        lines.append(f"x_{i} = {z}{terms}")
    lines += [f"out[{i}] = x_{i}" for i in range(n)]
    return lines


def _qdd(equations: Equations, has_contact_forces: bool) -> str:
    n = equations.model.n
    body = _forcing_body(equations, has_contact_forces, mass=True)
    body.add(*_solve_lines(n, body.zero))
    fill = body.text(
        _def(
            "_qdd_fill",
            "q, qd, tau, out",
            "Solve mass_matrix(q) @ out == forcing(q, qd, tau) (unrolled LDLᵀ).",
            inline=True,
        )
    )
    signature = "types.void(_VECTOR, _VECTOR, _VECTOR, _VECTOR)"
    into = "\n".join(
        _def(
            "qdd_into",
            "q, qd, tau, out",
            f"Accelerations into out: ({n},) float64 (rad/s², m/s²); all arrays C-contiguous "
            "float64. Explicitly typed, so cached kernels can take it as a first-class function.",
            signature,
        )
        + [f"{INDENT}_qdd_fill(q, qd, tau, out)"]
    )
    allocating = "\n".join(
        _def("qdd", "q, qd, tau", f"Accelerations: ({n},) float64 (rad/s², m/s²).")
        + [
            f"{INDENT}out = np.empty({n})",
            f"{INDENT}_qdd_fill(q, qd, tau, out)",
            f"{INDENT}return out",
        ]
    )
    return f"{fill}\n\n{into}\n\n\n{allocating}"


def _derivative(equations: Equations) -> str:
    n = equations.model.n
    return "\n".join(
        _def(
            "derivative_into",
            "state, inputs, out",
            f"The state's time derivative into out: state = q‖qd ({2 * n},) SI, inputs = tau "
            f"({n},); out ({2 * n},) = qd‖qdd. Explicitly typed: the controllers' cached kernels "
            "take it as a first-class function.",
            "types.void(_VECTOR, _VECTOR, _VECTOR)",
        )
        + [
            f"{INDENT}_qdd_fill(state[:{n}], state[{n}:], inputs, out[{n}:])",
            f"{INDENT}for i in range({n}):",
            f"{INDENT}{INDENT}out[i] = state[{n} + i]",
        ]
    )


def _endpoints(equations: Equations) -> str:
    body = _Body(equations)
    outputs = []
    for i, ends in enumerate(equations.endpoints):
        for end, (x, y) in enumerate(ends):
            outputs += [(f"out[{i}, {end}, 0]", x), (f"out[{i}, {end}, 1]", y)]
    body.compute(outputs)
    rods = len(equations.endpoints)
    fill = body.text(
        _def("_endpoints_fill", "q, out", "Each rod's proximal and distal end into out.")
    )
    signature = "types.void(_VECTOR, _RODS_ARRAY)"
    into = "\n".join(
        _def(
            "endpoints_into",
            "q, out",
            f"Rod ends into out: ({rods}, 2, 2) float64, m: per rod (file order) its proximal "
            "then distal end (x, y).",
            signature,
        )
        + [f"{INDENT}_endpoints_fill(q, out)"]
    )
    allocating = "\n".join(
        _def("endpoints", "q", f"Rod ends: ({rods}, 2, 2) float64, m (see endpoints_into).")
        + [
            f"{INDENT}out = np.empty(({rods}, 2, 2))",
            f"{INDENT}_endpoints_fill(q, out)",
            f"{INDENT}return out",
        ]
    )
    return f"{fill}\n\n{into}\n\n\n{allocating}"


def _center_of_mass(equations: Equations) -> str:
    body = _Body(equations)
    x, y = equations.center_of_mass
    body.compute([("x", x), ("y", y)])
    body.add("out = np.empty(2)", f"out[0] = {body.ref('x')}", f"out[1] = {body.ref('y')}")
    body.add("return out")
    return body.text(
        _def("center_of_mass", "q", "The whole figure's centre of mass: (2,) float64, m.")
    )


def _energy(equations: Equations, has_contact_forces: bool) -> str:
    model = equations.model
    body = _Body(equations)
    outputs = [("total", equations.kinetic_energy + equations.potential_energy)]
    if has_contact_forces:
        outputs += _contact_outputs(equations, jacobians=False)
    body.compute(outputs)
    for limit in model.figure.limits:
        k = model.figure.coordinate_index(limit.coordinate)
        q = model.q[k]
        body.need(q)
        branch = "if"
        for bound, sign in ((limit.upper, ">"), (limit.lower, "<")):
            if math.isfinite(bound):
                stretch = f"({q} {_minus(bound)})"
                body.add(
                    f"{branch} {q} {sign} {_literal(bound)}:",
                    f"{INDENT}total += 0.5 * {_literal(limit.stiffness)} * {stretch} * {stretch}",
                )
                branch = "elif"
    if has_contact_forces:
        for c, contact in enumerate(model.figure.contacts):
            body.add(
                f"depth = _ground_penetration({body.ref(f'cx_{c}')}, {body.ref(f'cy_{c}')})[0]",
                f"total += 0.5 * {_literal(contact.stiffness)} * depth * depth",
            )
    body.add(f"return {body.ref('total')}")
    doc = (
        "Kinetic + potential energy, J: gravity, and the springs of joint limits and contacts "
        "(dampers and friction dissipate)."
    )
    return body.text(_def("energy", "q, qd", doc))


def _momentum(equations: Equations) -> str:
    body = _Body(equations)
    px, py, angular = equations.momentum
    body.compute([("px", px), ("py", py), ("angular", angular)])
    body.add("out = np.empty(3)")
    body.add(*(f"out[{k}] = {body.ref(name)}" for k, name in enumerate(("px", "py", "angular"))))
    body.add("return out")
    doc = (
        "(p_x, p_y, angular momentum about the origin): (3,) float64 (kg m/s, kg m²/s); "
        "conserved when nothing external acts (no gravity, pivot or contact)."
    )
    return body.text(_def("momentum", "q, qd", doc))


def _contact_points(equations: Equations) -> str:
    body = _Body(equations)
    count = len(equations.contact_points)
    outputs = []
    for c, (x, y) in enumerate(equations.contact_points):
        outputs += [(f"out[{c}, 0]", x), (f"out[{c}, 1]", y)]
    body.add(f"out = np.empty(({count}, 2))")
    body.compute(outputs)
    body.add("return out")
    doc = f"The contact points: ({count}, 2) float64, m (CONTACT_ROD, CONTACT_FRACTION)."
    return body.text(_def("contact_points", "q", doc))


def _contact_forces(equations: Equations, has_contact_forces: bool) -> str:
    body = _Body(equations)
    count = len(equations.contact_points)
    body.add(f"out = np.zeros(({count}, 2))")
    if has_contact_forces:
        body.compute(_contact_outputs(equations, jacobians=False))
        for c, contact in enumerate(equations.model.figure.contacts):
            body.add(f"out[{c}, 0], out[{c}, 1] = {_contact_call(body, c, contact)}")
    body.add("return out")
    doc = (
        f"The ground's force on each contact point: ({count}, 2) float64, N (zero without "
        "terrain or when not touching)."
    )
    return body.text(_def("contact_forces", "q, qd", doc))
