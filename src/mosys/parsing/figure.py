"""The figure spec (``.fig``): a tree of rigid rods joined by hinges, planar or (with ``ball``
joints) 3-D.

::

    gravity 9.81                                       # m/s², pointing down (-y); default 9.81
    rod link length=1 mass=1                           # uniform rod: com=0.5, inertia=m*l²/12
    pin link at=0,0 angle=angle rate=omega actuator=torque

Keywords: ``gravity``, ``rod``, ``pin`` or ``free`` (the root), ``hinge``, ``limit``,
``contact``, ``terrain``; or a single ``vehicle`` line for the built-in car (``parsing.vehicle``).
Lengths in metres, masses in kg, angles in degrees (radians in the parsed ``Figure``).
The full grammar, with every default and convention, is in the README ("Figure spec").

A figure with any ``ball`` line is 3-D (the 3-D BSR figures of the 1995 paper's §4; frames as in
``kernels.bsr3d_simulate``: a child's frame is ``R_parent @ Rz(offset) @ Ry(splay) @ Rz(θ) @
Ry(ψ)``) and may use three more keywords and two more ``free`` options::

    free spine offset=0 splay=0        # the root rod's rest turn in the body frame (degrees)
    ball leg on=spine at=0.6 offset=-90 splay=10 angle=leg rate=leg_rate swing=leg_swing
    limit leg lower=-15 upper=15 swing_lower=-5 swing_upper=5   # lower == upper: a fixed angle
    heading spine offset=0             # required: the rod whose (x, z) direction is the heading
    feet leg.distal arm.distal         # the endpoints the figure walks on (optional)

A ball joint sits where a hinge would (``at=`` defaults to the parent's length) and has two
angles, θ (``angle=``, default name the rod's) and ψ (``swing=``, default ``ROD_swing``), their
rates (``rate=``, ``swing_rate=``) named ``NAME_rate`` by default, ``offset``/``splay`` 0 by
default, no actuator. A ``hinge`` in a 3-D figure is a joint whose ψ is fixed at 0 (named
``ROD_swing``, a name no other coordinate may take). Every limit of a 3-D figure (a ball's or
a hinge's) is a bare range: it may fix an angle (lower == upper) and needs no ``stiffness``
(the 3-D BSR simulator's joints are kinematic; one given is kept and not used).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

from mosys.parsing.tokens import (
    END_OF_FILE,
    Line,
    LineReader,
    SpecError,
    Token,
    format_number,
    missing_line,
    parse_endpoint,
    parse_name,
    parse_number,
    read_spec_text,
    record_once,
    tokenize,
    unknown_keyword,
    value_token,
)
from mosys.parsing.vehicle import Vehicle, is_vehicle_spec, parse_vehicle, render_vehicle_spec

KEYWORDS = ("gravity", "rod", "pin", "free", "hinge", "limit", "contact", "terrain", "vehicle")
KEYWORDS_3D = ("ball", "heading", "feet")  # only in a 3-D figure: one with a 'ball' line
ROOT_KINDS = ("pin", "free")
CHILD_KINDS = ("hinge", "ball")
DEFAULT_GRAVITY = 9.81  # m/s²
DEFAULT_COM = 0.5  # fraction of the rod from its proximal end
DEFAULT_SLIP = 0.01  # m/s: tangential speed at which contact friction reaches friction * normal
TERRAIN_HALF_WIDTH = 1000.0  # m: 'floor' and 'steps' run from x = -1000 to x = +1000
TERRAIN_KINDS = ("floor", "steps", "polyline")
# Physical ranges (issue 27): beyond them the equations' products and inverses (m·l², 1/M, the
# impulse solvers' determinants) overflow or underflow to 0 and the kernels divide by zero.
ROD_LENGTH_RANGE = (1e-6, 1e6)  # m
ROD_MASS_RANGE = (1e-6, 1e6)  # kg
ROD_INERTIA_RANGE = (1e-20, 1e20)  # kg·m², about the com; m·l²/12 of any rod above lies in it
MAX_GRAVITY = 1e6  # m/s²
MAX_PIVOT = 1e6  # m: a pin's pivot, a terrain vertex or height lies within this of the origin

_NO_TOKEN = Token("", 0, 0)
# the options of a hinge or ball line
_PLACEMENT_KEYS = {
    "on": "the parent rod's name",
    "at": "the hinge's distance along the parent in metres",
    "offset": "the fixed angle offset in degrees",
}
_ANGLE_KEYS = {"angle": "a name for the angle coordinate", "rate": "a name for the angle's rate"}
_ACTUATOR_KEY = "a name for the hinge's actuator"


@dataclass(frozen=True)
class Rod:
    """One ``rod`` line: a rigid rod. ``length`` m, ``mass`` kg, ``com`` the fraction of the way
    from the proximal to the distal end where its centre of mass sits, ``inertia`` kg·m² about
    its own centre of mass."""

    name: str
    length: float
    mass: float
    com: float
    inertia: float
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate: ``kind`` is ``x`` or ``y`` (metres, the free root's proximal
    end), ``angle`` (radians: absolute, CCW from +x, for the root; relative to the parent for a
    hinge; θ of a ball joint) or ``swing`` (radians: ψ of a ball joint). ``rate`` names its time
    derivative; ``actuator`` names the control that drives it (``""``: unactuated)."""

    name: str
    rate: str
    kind: str
    rod: str
    actuator: str = ""

    @property
    def is_angle(self) -> bool:
        return self.kind in ("angle", "swing")


def default_swing_name(rod: str) -> str:
    """The name of the swing ψ of rod ``rod``'s joint when the spec gives none (a ball line
    without ``swing=``, any hinge of a 3-D figure)."""
    return f"{rod}_swing"


@dataclass(frozen=True)
class Joint:
    """How one rod hangs in the tree: a ``pin`` (root hinged to a fixed ``pivot`` (x, y), m;
    absolute angle = ``offset`` + coordinate), a ``free`` root (floating base: coordinates x,
    y, angle; in a 3-D figure its rod's rest frame in the body frame is Rz(``offset``) @
    Ry(``splay``)), a ``hinge`` on ``parent`` at ``position`` metres along the parent from its
    proximal end, with a fixed ``offset`` (rad): child absolute angle = parent absolute angle +
    offset + coordinate; or a ``ball`` (3-D) placed as a hinge, with coordinates θ and ψ: child
    frame = parent frame @ Rz(offset) @ Ry(``splay``) @ Rz(θ) @ Ry(ψ) (``splay`` rad)."""

    kind: str
    rod: str
    coordinates: tuple[Coordinate, ...]
    parent: str | None = None
    position: float = 0.0
    offset: float = 0.0
    pivot: tuple[float, float] = (0.0, 0.0)
    splay: float = 0.0
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)

    @property
    def angle(self) -> Coordinate:
        """The joint's angle coordinate (θ of a ball joint, the free root's angle)."""
        return next(coordinate for coordinate in self.coordinates if coordinate.kind == "angle")

    @property
    def swing(self) -> Coordinate | None:
        """A ball joint's swing coordinate ψ; None for other joints."""
        return next((c for c in self.coordinates if c.kind == "swing"), None)


@dataclass(frozen=True)
class JointLimit:
    """One ``limit`` line: a one-sided spring-damper on the angle coordinate ``coordinate`` of
    rod ``rod``'s joint, active below ``lower`` or above ``upper`` (radians, ±inf: no limit).
    ``stiffness`` N·m/rad (0: none, only for a ball joint, whose limit may be a bare range for
    the kinematic BSR simulator), ``damping`` N·m·s/rad. A ball joint's limit also bounds its
    swing ψ by ``swing_lower``, ``swing_upper`` (radians, ±inf: no limit); its bounds may be
    equal (a fixed angle)."""

    rod: str
    coordinate: str
    lower: float
    upper: float
    stiffness: float
    damping: float
    swing_lower: float = -math.inf
    swing_upper: float = math.inf
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class ContactPoint:
    """One ``contact`` line: a point ``fraction`` of the way along rod ``rod`` (0 proximal, 1
    distal) that the terrain pushes with a penalty spring (``stiffness`` N/m) and damper
    (``damping`` N·s/m), and drags with Coulomb ``friction`` (coefficient) regularized below the
    tangential speed ``slip`` (m/s)."""

    rod: str
    fraction: float
    stiffness: float
    damping: float
    friction: float
    slip: float
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class Terrain:
    """The ground: solid below a polyline of (x, y) vertices (metres, x non-decreasing).

    ``kind`` is ``none``, ``floor`` (flat at ``height``), ``steps`` (``height`` left of the first
    step; each step (x, y): from x on the ground is at height y) or ``polyline`` (``points`` are
    the vertices)."""

    kind: str = "none"
    height: float = 0.0
    points: tuple[tuple[float, float], ...] = ()
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)  # the kind's word
    height_token: Token = field(default=_NO_TOKEN, compare=False, repr=False)  # height='s value

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """The ground polyline, metres; ``()`` for no ground."""
        if self.kind == "floor":
            return ((-TERRAIN_HALF_WIDTH, self.height), (TERRAIN_HALF_WIDTH, self.height))
        if self.kind == "steps":
            vertices = [(-TERRAIN_HALF_WIDTH, self.height)]
            level = self.height
            for x, y in self.points:
                vertices.append((x, level))
                if y != level:
                    vertices.append((x, y))
                level = y
            vertices.append((TERRAIN_HALF_WIDTH, level))
            return tuple(vertices)
        return self.points


@dataclass(frozen=True)
class Figure:
    """A parsed ``.fig`` file (SI units: metres, kg, radians).

    ``rods`` are in file order (the order of ``endpoints``); ``joints`` in file order, one per rod,
    exactly one of them the root (``pin`` or ``free``); ``coordinates`` follow the joints' order
    (a free root gives x, y, angle; a ball joint θ, ψ). ``spec_sha256`` is the hex SHA-256 of the
    file's bytes. A 3-D figure (one with a ball joint) names ``heading_rod``, the rod whose
    horizontal direction plus ``heading_offset`` (rad) is its heading, and its ``feet``: (rod,
    ``proximal``|``distal``) endpoints, in file order.
    """

    path: str = field(compare=False)
    gravity: float
    rods: tuple[Rod, ...]
    joints: tuple[Joint, ...]
    limits: tuple[JointLimit, ...] = ()
    contacts: tuple[ContactPoint, ...] = ()
    terrain: Terrain = Terrain()
    heading_rod: str = ""
    heading_offset: float = 0.0
    feet: tuple[tuple[str, str], ...] = ()
    spec_sha256: str = field(default="", compare=False)

    @property
    def name(self) -> str:
        """The figure's name: the spec file's stem (``link1`` for ``link1.fig``)."""
        return Path(self.path).stem

    @property
    def dimensions(self) -> int:
        """3 for a figure with a ball joint, else 2 (planar)."""
        return 3 if any(joint.kind == "ball" for joint in self.joints) else 2

    @property
    def root(self) -> Joint:
        return next(joint for joint in self.joints if joint.kind in ROOT_KINDS)

    @property
    def coordinates(self) -> tuple[Coordinate, ...]:
        return tuple(coordinate for joint in self.joints for coordinate in joint.coordinates)

    @property
    def q_names(self) -> tuple[str, ...]:
        return tuple(coordinate.name for coordinate in self.coordinates)

    @property
    def qd_names(self) -> tuple[str, ...]:
        return tuple(coordinate.rate for coordinate in self.coordinates)

    @property
    def state_names(self) -> tuple[str, ...]:
        """The figure's state order: coordinate names, then rate names."""
        return self.q_names + self.qd_names

    @property
    def tau_names(self) -> tuple[str, ...]:
        """The actuator of each coordinate, ``""`` where unactuated."""
        return tuple(coordinate.actuator for coordinate in self.coordinates)

    def rod(self, name: str) -> Rod:
        return next(rod for rod in self.rods if rod.name == name)

    def rod_index(self, name: str) -> int:
        return next(index for index, rod in enumerate(self.rods) if rod.name == name)

    def joint(self, rod: str) -> Joint:
        """The joint that attaches rod ``rod`` (its hinge, or the root's pin/free line)."""
        return next(joint for joint in self.joints if joint.rod == rod)

    def parent_index(self) -> tuple[int, ...]:
        """Per rod (file order): the index of its parent rod, -1 for the root."""
        return tuple(
            -1 if (parent := self.joint(rod.name).parent) is None else self.rod_index(parent)
            for rod in self.rods
        )

    def coordinate_index(self, name: str) -> int:
        return self.q_names.index(name)


def parse_figure_spec(path: str | Path) -> Figure | Vehicle:
    """Parse a ``.fig`` file; any problem raises SpecError naming file, line and column."""
    text, digest = read_spec_text(path)  # SpecError at 1:1 for a file it cannot read
    return parse_figure_text(text, str(path), digest)


def parse_figure_text(
    text: str, path: str = "<text>", spec_sha256: str | None = None
) -> Figure | Vehicle:
    """Parse ``.fig`` text: a tree of rods, or a built-in ``vehicle`` (``parsing.vehicle``);
    ``path`` names it in errors. ``spec_sha256`` defaults to the SHA-256 of the text's UTF-8
    encoding."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    lines = tokenize(text, path)
    if is_vehicle_spec(lines):
        return parse_vehicle(lines, path, spec_sha256)
    return _Parser(path).parse(lines, spec_sha256)


def render_figure_spec(figure: Figure | Vehicle) -> str:
    """Spec text that parses back to ``figure`` (angles round-trip through degrees), a vehicle
    too (``parsing.vehicle.render_vehicle_spec``)."""
    if isinstance(figure, Vehicle):
        return render_vehicle_spec(figure)
    out = [f"gravity {format_number(figure.gravity)}"]
    for rod in figure.rods:
        out.append(
            f"rod {rod.name} length={format_number(rod.length)} mass={format_number(rod.mass)} "
            f"com={format_number(rod.com)} inertia={format_number(rod.inertia)}"
        )
    for joint in figure.joints:
        angle = joint.angle
        names = f"angle={angle.name} rate={angle.rate}"
        actuator = f" actuator={angle.actuator}" if angle.actuator else ""
        if joint.kind == "pin":
            at = f"{format_number(joint.pivot[0])},{format_number(joint.pivot[1])}"
            offset = f" offset={format_number(math.degrees(joint.offset))}" if joint.offset else ""
            out.append(f"pin {joint.rod} at={at}{offset} {names}{actuator}")
        elif joint.kind == "free":
            x, y = joint.coordinates[0], joint.coordinates[1]
            rest = "".join(
                f" {key}={format_number(math.degrees(value))}"
                for key, value in (("offset", joint.offset), ("splay", joint.splay))
                if value
            )
            out.append(
                f"free {joint.rod} x={x.name} y={y.name} {names} x_rate={x.rate} y_rate={y.rate}"
                + rest
            )
        elif joint.kind == "hinge":
            out.append(
                f"hinge {joint.rod} on={joint.parent} at={format_number(joint.position)} "
                f"offset={format_number(math.degrees(joint.offset))} {names}{actuator}"
            )
        else:
            swing = joint.swing
            assert swing is not None
            out.append(
                f"ball {joint.rod} on={joint.parent} at={format_number(joint.position)} "
                f"offset={format_number(math.degrees(joint.offset))} "
                f"splay={format_number(math.degrees(joint.splay))} {names} "
                f"swing={swing.name} swing_rate={swing.rate}"
            )
    for limit in figure.limits:
        bounds = "".join(
            f" {key}={format_number(math.degrees(value))}"
            for key, value in (
                ("lower", limit.lower),
                ("upper", limit.upper),
                ("swing_lower", limit.swing_lower),
                ("swing_upper", limit.swing_upper),
            )
            if math.isfinite(value)
        )
        stiffness = f" stiffness={format_number(limit.stiffness)}" if limit.stiffness else ""
        out.append(f"limit {limit.rod}{bounds}{stiffness} damping={format_number(limit.damping)}")
    for contact in figure.contacts:
        out.append(
            f"contact {contact.rod} fraction={format_number(contact.fraction)} "
            f"stiffness={format_number(contact.stiffness)} "
            f"damping={format_number(contact.damping)} "
            f"friction={format_number(contact.friction)} slip={format_number(contact.slip)}"
        )
    terrain = figure.terrain
    points = " ".join(f"{format_number(x)},{format_number(y)}" for x, y in terrain.points)
    if terrain.kind == "floor":
        out.append(f"terrain floor height={format_number(terrain.height)}")
    elif terrain.kind == "steps":
        out.append(f"terrain steps {points} height={format_number(terrain.height)}")
    elif terrain.kind == "polyline":
        out.append(f"terrain polyline {points}")
    if figure.heading_rod:
        offset = format_number(math.degrees(figure.heading_offset))
        out.append(f"heading {figure.heading_rod} offset={offset}")
    if figure.feet:
        out.append("feet " + " ".join(f"{rod}.{end}" for rod, end in figure.feet))
    return "\n".join(out) + "\n"


# --- the parser -------------------------------------------------------------------------------


@dataclass
class _RawJoint:
    """A joint line as read, before its references are resolved."""

    kind: str
    keyword: Token
    rod: Token
    coordinates: list[Coordinate]
    names: list[tuple[str, str, Token]]  # (what, name, the token that named it)
    parent: Token | None = None
    position: tuple[float, Token] | None = None
    offset: float = 0.0
    pivot: tuple[float, float] = (0.0, 0.0)
    splay: float = 0.0


@dataclass
class _RawLimit:
    rod: Token
    lower: float
    upper: float
    stiffness: float
    damping: float
    swing_lower: float
    swing_upper: float
    # (line, column) where a planar figure's limit lacks its 'stiffness=' (reported once the
    # rod is known to have a joint that takes a limit at all)
    stiffness_missing_at: tuple[int, int] | None = None


@dataclass
class _RawContact:
    rod: Token
    fraction: float
    stiffness: float
    damping: float
    friction: float
    slip: float


class _Parser:
    def __init__(self, path: str):
        self.path = path
        self.gravity = DEFAULT_GRAVITY
        self.rods: list[Rod] = []
        self.joints: list[_RawJoint] = []
        self.limits: list[_RawLimit] = []
        self.contacts: list[_RawContact] = []
        self.terrain = Terrain()
        self.heading: tuple[Token, float] | None = None  # the heading rod, the offset (rad)
        self.feet: list[tuple[Token, str]] = []  # each foot's rod (its part of ROD.END), end
        self.first_line: dict[str, int] = {}  # once-only keyword -> its line number
        self.dimensions = 2
        self.ball_rods: set[str] = set()  # the rods the file's ball lines name

    def error(self, token: Token, expected: str) -> SpecError:
        return SpecError.at(self.path, token, expected)

    def parse(self, lines: list[Line], spec_sha256: str) -> Figure:
        # a 'ball' line anywhere makes the figure 3-D, which other lines' grammar depends on
        balls = [line for line in lines if line.keyword.text == "ball"]
        self.dimensions = 3 if balls else 2
        self.ball_rods = {line.tokens[1].text for line in balls if len(line.tokens) > 1}
        keywords = KEYWORDS + KEYWORDS_3D if balls else KEYWORDS
        once = ("gravity", "terrain", "heading", "feet")
        for line in lines:
            keyword = line.keyword.text
            if keyword in KEYWORDS_3D and not balls:
                raise self.error(
                    line.keyword,
                    f"a planar figure's keyword ('{keyword}' needs a 3-D figure: one with 'ball' "
                    "joints)",
                )
            if keyword not in keywords:
                raise unknown_keyword(line, keywords)
            if keyword in once:
                record_once(line, self.first_line)
            getattr(self, f"line_{keyword}")(line)
        end = Token(END_OF_FILE, lines[-1].number + 1 if lines else 1, 1)
        if not self.rods:
            raise SpecError(self.path, end.line, 1, "a 'rod' line", END_OF_FILE)
        rods = {rod.name: rod for rod in self.rods}
        joints = self.resolve_joints(rods, end)
        self.check_names()
        by_rod = {joint.rod: joint for joint in joints}
        heading_rod, heading_offset = "", 0.0
        if balls:
            if self.heading is None:
                raise missing_line(self.path, lines, "heading")
            heading_rod = self.rod_reference(self.heading[0], rods, "a heading rod").name
            heading_offset = self.heading[1]
        return Figure(
            path=self.path,
            gravity=self.gravity,
            rods=tuple(self.rods),
            joints=joints,
            limits=tuple(self.resolve_limit(limit, rods, by_rod) for limit in self.limits),
            contacts=tuple(self.resolve_contact(contact, rods) for contact in self.contacts),
            terrain=self.terrain,
            heading_rod=heading_rod,
            heading_offset=heading_offset,
            feet=tuple(
                (self.rod_reference(rod, rods, "a rod").name, end) for rod, end in self.feet
            ),
            spec_sha256=spec_sha256,
        )

    # --- helpers

    def name_token(self, reader: LineReader, what: str) -> Token:
        token = reader.peek()
        reader.name(what)
        assert token is not None
        return token

    def number(self, token: Token, key: str, what: str, check: str | None = None) -> float:
        """The number of a ``key=value`` token; ``check`` is one of ``>0``, ``>=0``, ``0..1``."""
        part = value_token(token, key)
        value = parse_number(part, self.path, what)
        bad = {
            ">0": (value <= 0, f"a number > 0 for {what}"),
            ">=0": (value < 0, f"a number >= 0 for {what}"),
            "0..1": (not 0 <= value <= 1, f"a number from 0 to 1 for {what}"),
            None: (False, ""),
        }[check]
        if bad[0]:
            raise self.error(part, bad[1])
        return value

    def point(self, token: Token, what: str, key: str | None = None) -> tuple[float, float]:
        """An ``x,y`` pair (metres), from a bare token or the value of ``key=x,y``."""
        part = value_token(token, key) if key is not None else token
        pieces = part.text.split(",")
        if len(pieces) != 2:
            raise self.error(part, f"a point 'x,y' in metres for {what}")
        x = parse_number(
            Token(pieces[0], part.line, part.column), self.path, f"{what} x", pieces[0]
        )
        y_token = Token(pieces[1], part.line, part.column + len(pieces[0]) + 1)
        y = parse_number(y_token, self.path, f"{what} y")
        return x, y

    def options(self, reader: LineReader, allowed: dict[str, str]) -> dict[str, Token]:
        return {key: token for key, (token, _) in reader.key_values(allowed).items()}

    def required(self, line: Line, found: dict[str, Token], key: str, what: str) -> Token:
        if key not in found:
            raise SpecError(self.path, line.number, line.end_column, f"'{key}=' ({what})", None)
        return found[key]

    def coordinate(
        self, found: dict[str, Token], key: str, default: str, rod: Token, what: str
    ) -> tuple[str, Token]:
        """A coordinate or rate name from ``key=name``, else ``default`` (blamed on ``rod``)."""
        if key not in found:
            return default, rod
        part = value_token(found[key], key)
        return parse_name(part, self.path, what), part

    # --- one method per keyword

    def line_vehicle(self, line: Line) -> None:
        raise self.error(line.keyword, "'vehicle' as the first line of a spec of its own")

    def line_gravity(self, line: Line) -> None:
        reader = line.reader()
        token = reader.peek()
        value = reader.number("gravity (m/s²)")
        assert token is not None
        if value < 0:
            raise self.error(token, "a number >= 0 for gravity (m/s², pointing down)")
        if value > MAX_GRAVITY:
            raise self.error(token, f"a number <= {MAX_GRAVITY:g} for gravity (m/s²)")
        reader.end()
        self.gravity = value

    def line_rod(self, line: Line) -> None:
        reader = line.reader()
        name = self.name_token(reader, "the rod")
        for rod in self.rods:
            if rod.name == name.text:
                raise self.error(name, f"a rod name not used before (line {rod.token.line})")
        found = self.options(
            reader,
            {
                "length": "the length in metres",
                "mass": "the mass in kg",
                "com": "the centre of mass as a fraction from the proximal end",
                "inertia": "the inertia about the centre of mass in kg·m²",
            },
        )
        length_token = self.required(line, found, "length", "the rod's length in metres")
        mass_token = self.required(line, found, "mass", "the rod's mass in kg")
        length = self.ranged(length_token, "length", "length (m)", ROD_LENGTH_RANGE)
        mass = self.ranged(mass_token, "mass", "mass (kg)", ROD_MASS_RANGE)
        com = DEFAULT_COM
        if "com" in found:
            com = self.number(found["com"], "com", "com (fraction of the length)", "0..1")
        if "inertia" in found:
            inertia = self.ranged(found["inertia"], "inertia", "inertia (kg·m²)", ROD_INERTIA_RANGE)
        else:  # derived: the ranges above keep it in ROD_INERTIA_RANGE; checked all the same
            inertia = mass * length * length / 12.0
            low, high = ROD_INERTIA_RANGE
            if not low <= inertia <= high:
                raise self.error(
                    value_token(length_token, "length"),
                    f"a length and mass whose inertia m·l²/12 is from {low:g} to {high:g} kg·m² "
                    f"(it is {inertia:g})",
                )
        self.rods.append(Rod(name.text, length, mass, com, inertia, name))

    def ranged(self, token: Token, key: str, what: str, bounds: tuple[float, float]) -> float:
        """The number > 0 of a ``key=value`` token, within ``bounds`` (inclusive)."""
        value = self.number(token, key, what, ">0")
        low, high = bounds
        if not low <= value <= high:
            raise self.error(
                value_token(token, key), f"a number from {low:g} to {high:g} for {what}"
            )
        return value

    def line_pin(self, line: Line) -> None:
        reader = line.reader()
        rod = self.name_token(reader, "the root rod")
        found = self.options(
            reader,
            {
                "at": "the pivot 'x,y' in metres",
                "offset": _PLACEMENT_KEYS["offset"],
                **_ANGLE_KEYS,
                "actuator": "a name for the pin's actuator",
            },
        )
        pivot = (0.0, 0.0)
        if "at" in found:
            pivot = self.point(found["at"], "at", "at")
            if max(abs(pivot[0]), abs(pivot[1])) > MAX_PIVOT:
                raise self.error(
                    value_token(found["at"], "at"), f"a pivot within {MAX_PIVOT:g} m of the origin"
                )
        offset = self.degrees(found, "offset")
        angle, names = self.angle_coordinate(found, rod)
        self.joints.append(
            _RawJoint("pin", line.keyword, rod, [angle], names, pivot=pivot, offset=offset)
        )

    def line_free(self, line: Line) -> None:
        reader = line.reader()
        rod = self.name_token(reader, "the root rod")
        found = self.options(
            reader,
            {
                "x": "a name for the x coordinate",
                "y": "a name for the y coordinate",
                "angle": "a name for the angle coordinate",
                "x_rate": "a name for x's rate",
                "y_rate": "a name for y's rate",
                "rate": "a name for the angle's rate",
                "offset": "the rest turn about z in degrees",
                "splay": "the rest turn about y in degrees",
            },
        )
        for key in ("offset", "splay"):
            if key in found and self.dimensions == 2:
                raise self.error(
                    found[key],
                    f"a planar root's option ('{key}=' needs a 3-D figure: one with 'ball' joints)",
                )
        coordinates = []
        names = []
        for axis in ("x", "y"):
            name, name_token = self.coordinate(found, axis, axis, rod, f"the {axis} coordinate")
            rate, rate_token = self.coordinate(
                found, f"{axis}_rate", f"{name}_rate", rod, f"{axis}'s rate"
            )
            coordinates.append(Coordinate(name, rate, axis, rod.text))
            names += [("coordinate", name, name_token), ("rate", rate, rate_token)]
        angle, angle_names = self.angle_coordinate(found, rod)
        coordinates.append(angle)
        self.joints.append(
            _RawJoint(
                "free",
                line.keyword,
                rod,
                coordinates,
                names + angle_names,
                offset=self.degrees(found, "offset"),
                splay=self.degrees(found, "splay"),
            )
        )

    def angle_coordinate(
        self, found: dict[str, Token], rod: Token, kind: str = "angle"
    ) -> tuple[Coordinate, list[tuple[str, str, Token]]]:
        """The ``angle`` coordinate of a joint line (keys ``angle=``, ``rate=``, ``actuator=``)
        or a ball line's ``swing`` ψ (keys ``swing=``, ``swing_rate=``), and its names with the
        tokens that gave them (the rod's token for a default name)."""
        if kind == "angle":
            rate_key, default = "rate", rod.text
        else:
            rate_key, default = "swing_rate", default_swing_name(rod.text)
        name, name_token = self.coordinate(found, kind, default, rod, f"the {kind} coordinate")
        rate, rate_token = self.coordinate(
            found, rate_key, f"{name}_rate", rod, f"the {kind}'s rate"
        )
        names = [("coordinate", name, name_token), ("rate", rate, rate_token)]
        actuator = ""
        if "actuator" in found:
            actuator, actuator_token = self.coordinate(found, "actuator", "", rod, "the actuator")
            names.append(("actuator", actuator, actuator_token))
        return Coordinate(name, rate, kind, rod.text, actuator), names

    def line_hinge(self, line: Line) -> None:
        self.child_joint(
            line, "hinge", {**_PLACEMENT_KEYS, **_ANGLE_KEYS, "actuator": _ACTUATOR_KEY}
        )

    def line_ball(self, line: Line) -> None:
        self.child_joint(
            line,
            "ball",
            {
                **_PLACEMENT_KEYS,
                "splay": "the fixed splay in degrees",
                **_ANGLE_KEYS,
                "swing": "a name for the swing coordinate",
                "swing_rate": "a name for the swing's rate",
            },
        )

    def child_joint(self, line: Line, kind: str, keys: dict[str, str]) -> None:
        """A ``hinge`` or ``ball`` line, whose options are ``keys`` (key -> what it gives)."""
        reader = line.reader()
        rod = self.name_token(reader, "the child rod")
        found = self.options(reader, keys)
        on = self.required(line, found, "on", "the parent rod")
        parent = value_token(on, "on")
        parse_name(parent, self.path, "the parent rod")
        position = None
        if "at" in found:
            at = found["at"]
            position = (self.number(at, "at", "at (m along the parent)"), value_token(at, "at"))
        offset = self.degrees(found, "offset")
        angle, names = self.angle_coordinate(found, rod)
        coordinates = [angle]
        if kind == "ball":
            swing, swing_names = self.angle_coordinate(found, rod, "swing")
            coordinates.append(swing)
            names += swing_names
        elif self.dimensions == 3:  # the hinge's ψ, fixed at 0, still has its name
            names.append(("coordinate", default_swing_name(rod.text), rod))
        self.joints.append(
            _RawJoint(
                kind,
                line.keyword,
                rod,
                coordinates,
                names,
                parent=parent,
                position=position,
                offset=offset,
                splay=self.degrees(found, "splay"),
            )
        )

    def degrees(self, found: dict[str, Token], key: str) -> float:
        """A line's angle option ``key=`` (degrees) in radians; 0 without one."""
        if key not in found:
            return 0.0
        return math.radians(self.number(found[key], key, f"{key} (degrees)"))

    def line_limit(self, line: Line) -> None:
        reader = line.reader()
        rod = self.name_token(reader, "the limited joint's rod")
        ball = rod.text in self.ball_rods
        keys = {"lower": "the lower limit in degrees", "upper": "the upper limit in degrees"}
        if ball:
            keys["swing_lower"] = "the swing's lower limit in degrees"
            keys["swing_upper"] = "the swing's upper limit in degrees"
        keys["stiffness"] = "the spring stiffness in N·m/rad"
        keys["damping"] = "the damping in N·m·s/rad"
        found = self.options(reader, keys)
        bound_keys = [key for key in keys if key.endswith(("lower", "upper"))]
        if not any(key in found for key in bound_keys):
            expected = " or ".join(
                [", ".join(f"'{key}='" for key in bound_keys[:-1]), f"'{bound_keys[-1]}='"]
            )
            raise SpecError(self.path, line.number, line.end_column, f"{expected} (degrees)", None)
        # a 3-D figure's limit (a ball's or a hinge's) is a bare range, which may fix its angle:
        # the 3-D BSR simulator's joints are kinematic, and no spring acts
        kinematic = self.dimensions == 3
        missing = None if kinematic or "stiffness" in found else (line.number, line.end_column)
        lower, upper = self.bounds(found, "lower", "upper", kinematic)
        swing_lower, swing_upper = self.bounds(found, "swing_lower", "swing_upper", kinematic)
        stiffness = 0.0
        if "stiffness" in found:
            stiffness = self.number(found["stiffness"], "stiffness", "stiffness (N·m/rad)", ">0")
        damping = 0.0
        if "damping" in found:
            damping = self.number(found["damping"], "damping", "damping (N·m·s/rad)", ">=0")
        self.limits.append(
            _RawLimit(rod, lower, upper, stiffness, damping, swing_lower, swing_upper, missing)
        )

    def bounds(
        self, found: dict[str, Token], lower_key: str, upper_key: str, closed: bool
    ) -> tuple[float, float]:
        """A limit's range from ``lower_key=``, ``upper_key=`` (degrees) in radians, ±inf where
        absent; upper > lower, or upper >= lower if ``closed`` (a ball joint may fix an angle)."""
        lower, upper = -math.inf, math.inf
        if lower_key in found:
            lower = math.radians(self.number(found[lower_key], lower_key, f"{lower_key} (degrees)"))
        if upper_key in found:
            upper_degrees = self.number(found[upper_key], upper_key, f"{upper_key} (degrees)")
            upper = math.radians(upper_degrees)
            if not (upper >= lower if closed else upper > lower):
                raise self.error(
                    value_token(found[upper_key], upper_key),
                    f"a number {'>=' if closed else '>'} {lower_key} ({math.degrees(lower):g}) "
                    f"for {upper_key} (degrees)",
                )
        return lower, upper

    def line_heading(self, line: Line) -> None:
        reader = line.reader()
        rod = self.name_token(reader, "the heading rod")
        found = self.options(reader, {"offset": "the heading's offset in degrees"})
        self.heading = (rod, self.degrees(found, "offset"))

    def line_feet(self, line: Line) -> None:
        expected = "an endpoint 'rod.proximal' or 'rod.distal'"
        if len(line.tokens) == 1:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        firsts: dict[str, Token] = {}
        for token in line.tokens[1:]:
            rod, end = parse_endpoint(token, self.path, expected)
            if token.text in firsts:
                raise self.error(
                    token,
                    f"each endpoint once ('{token.text}' is at column {firsts[token.text].column})",
                )
            firsts[token.text] = token
            self.feet.append((Token(rod, token.line, token.column), end))

    def line_contact(self, line: Line) -> None:
        reader = line.reader()
        rod = self.name_token(reader, "the contact point's rod")
        found = self.options(
            reader,
            {
                "fraction": "the point's fraction of the way along the rod",
                "stiffness": "the spring stiffness in N/m",
                "damping": "the damping in N·s/m",
                "friction": "the friction coefficient",
                "slip": "the slip speed in m/s",
            },
        )
        fraction_token = self.required(line, found, "fraction", "0 proximal end .. 1 distal end")
        stiffness_token = self.required(line, found, "stiffness", "N/m")
        fraction = self.number(fraction_token, "fraction", "fraction", "0..1")
        stiffness = self.number(stiffness_token, "stiffness", "stiffness (N/m)", ">0")
        values = {"damping": 0.0, "friction": 0.0, "slip": DEFAULT_SLIP}
        checks = {"damping": ("damping (N·s/m)", ">=0"), "friction": ("friction", ">=0")}
        checks["slip"] = ("slip (m/s)", ">0")
        for key in values:
            if key in found:
                values[key] = self.number(found[key], key, *checks[key])
        self.contacts.append(
            _RawContact(
                rod, fraction, stiffness, values["damping"], values["friction"], values["slip"]
            )
        )

    def line_terrain(self, line: Line) -> None:
        reader = line.reader()
        kind_token = reader.peek()
        kind = reader.word("'floor', 'steps' or 'polyline'").text
        assert kind_token is not None
        if kind not in TERRAIN_KINDS:
            raise self.error(kind_token, "'floor', 'steps' or 'polyline'")
        points: list[tuple[float, float]] = []
        point_tokens: list[Token] = []
        if kind != "floor":
            while (token := reader.peek()) is not None and "=" not in token.text:
                reader.word("a point")
                points.append(
                    self.point(token, "a terrain vertex" if kind == "polyline" else "a step")
                )
                point_tokens.append(token)
        height = 0.0
        height_token = _NO_TOKEN
        if kind != "polyline":
            found = self.options(reader, {"height": "the ground height in metres"})
            if "height" in found:
                height = self.number(found["height"], "height", "height (m)")
                height_token = value_token(found["height"], "height")
                if abs(height) > MAX_PIVOT:
                    raise self.error(
                        height_token,
                        f"a height within {MAX_PIVOT:g} m of 0, as terrain vertices are",
                    )
        reader.end()
        if kind == "polyline":
            self.check_polyline(line, points, point_tokens)
        elif kind == "steps":
            self.check_steps(line, points, point_tokens)
        self.terrain = Terrain(kind, height, tuple(points), kind_token, height_token)

    def check_polyline(
        self, line: Line, points: list[tuple[float, float]], tokens: list[Token]
    ) -> None:
        if len(points) < 2:
            raise SpecError(
                self.path, line.number, line.end_column, "at least two vertices 'x,y'", None
            )
        for (x0, y0), (x1, y1), token in zip(points, points[1:], tokens[1:], strict=False):
            if x1 < x0:
                raise self.error(token, f"a vertex with x >= {x0:g} (vertices run left to right)")
            if (x1, y1) == (x0, y0):
                raise self.error(token, f"a vertex different from the previous one ({x0:g},{y0:g})")
        for (x, y), token in zip(points, tokens, strict=True):
            if abs(x) > 1e6 or abs(y) > 1e6:
                raise self.error(token, "a vertex within 1e6 m of the origin")

    def check_steps(
        self, line: Line, points: list[tuple[float, float]], tokens: list[Token]
    ) -> None:
        if not points:
            raise SpecError(self.path, line.number, line.end_column, "a step 'x,y'", None)
        previous = -TERRAIN_HALF_WIDTH
        for (x, y), token in zip(points, tokens, strict=True):
            if not previous < x < TERRAIN_HALF_WIDTH or abs(y) > 1e6:
                raise self.error(
                    token,
                    f"a step with {previous:g} < x < {TERRAIN_HALF_WIDTH:g} and |y| <= 1e6",
                )
            previous = x

    # --- checks that need the whole file

    def rod_reference(self, token: Token, rods: dict[str, Rod], what: str) -> Rod:
        if token.text not in rods:
            choices = ", ".join(f"'{name}'" for name in rods)
            raise self.error(token, f"{what} named by a 'rod' line (one of {choices})")
        return rods[token.text]

    def resolve_joints(self, rods: dict[str, Rod], end: Token) -> tuple[Joint, ...]:
        joint_line: dict[str, int] = {}
        root: _RawJoint | None = None
        for raw in self.joints:
            self.rod_reference(raw.rod, rods, "a rod")
            if raw.rod.text in joint_line:
                raise self.error(
                    raw.rod,
                    f"a rod without a joint yet ('{raw.rod.text}' has one on line "
                    f"{joint_line[raw.rod.text]})",
                )
            joint_line[raw.rod.text] = raw.rod.line
            if raw.kind in ROOT_KINDS:
                if root is not None:
                    raise self.error(
                        raw.keyword,
                        f"one root ('pin' or 'free') only (the first is line {root.rod.line})",
                    )
                root = raw
            else:
                assert raw.parent is not None
                self.rod_reference(raw.parent, rods, "a parent rod")
        if root is None:
            raise SpecError(self.path, end.line, 1, "a root line ('pin' or 'free')", END_OF_FILE)
        for rod in self.rods:
            if rod.name not in joint_line:
                raise SpecError(
                    self.path,
                    end.line,
                    1,
                    f"a joint line ('hinge', 'pin' or 'free') for rod '{rod.name}' (line "
                    f"{rod.token.line})",
                    END_OF_FILE,
                )
        parents = {raw.rod.text: raw for raw in self.joints if raw.kind in CHILD_KINDS}
        for raw in self.joints:
            chain = [raw.rod.text]
            current = raw
            while current.kind in CHILD_KINDS:
                assert current.parent is not None
                parent = current.parent.text
                if parent in chain:
                    cycle = " -> ".join([*chain[chain.index(parent) :], parent])
                    raise self.error(
                        current.parent, f"a parent that does not close a cycle ({cycle})"
                    )
                chain.append(parent)
                if parent not in parents:
                    break
                current = parents[parent]
        joints = []
        for raw in self.joints:
            position = 0.0
            if raw.kind in CHILD_KINDS:
                assert raw.parent is not None
                parent_rod = rods[raw.parent.text]
                position = parent_rod.length
                if raw.position is not None:
                    position, token = raw.position
                    if not 0 <= position <= parent_rod.length:
                        raise self.error(
                            token,
                            f"a number from 0 to {parent_rod.length:g} (the length of "
                            f"'{parent_rod.name}') for at (m along the parent)",
                        )
            joints.append(
                Joint(
                    kind=raw.kind,
                    rod=raw.rod.text,
                    coordinates=tuple(raw.coordinates),
                    parent=None if raw.parent is None else raw.parent.text,
                    position=position,
                    offset=raw.offset,
                    pivot=raw.pivot,
                    splay=raw.splay,
                    token=raw.rod,
                )
            )
        return tuple(joints)

    def check_names(self) -> None:
        """Coordinate, rate and actuator names are all different."""
        seen: dict[str, int] = {}
        for raw in self.joints:
            for what, name, token in raw.names:
                if name in seen:
                    raise SpecError(
                        self.path,
                        token.line,
                        token.column,
                        f"{'an' if what[0] in 'aeiou' else 'a'} {what} name not used by another "
                        "coordinate, rate or actuator "
                        f"(line {seen[name]})",
                        name,
                    )
                seen[name] = token.line

    def resolve_limit(
        self, raw: _RawLimit, rods: dict[str, Rod], joints: dict[str, Joint]
    ) -> JointLimit:
        rod = self.rod_reference(raw.rod, rods, "a rod")
        joint = joints[rod.name]
        if joint.kind == "free":
            raise self.error(
                raw.rod, "a rod with a 'pin' or 'hinge' joint (a free root has no limit)"
            )
        if raw.stiffness_missing_at is not None:
            raise SpecError(self.path, *raw.stiffness_missing_at, "'stiffness=' (N·m/rad)", None)
        for other in self.limits:
            if other is raw:
                break
            if other.rod.text == raw.rod.text:
                raise self.error(
                    raw.rod, f"one limit per joint (the first is line {other.rod.line})"
                )
        return JointLimit(
            rod.name,
            joint.angle.name,
            raw.lower,
            raw.upper,
            raw.stiffness,
            raw.damping,
            raw.swing_lower,
            raw.swing_upper,
            raw.rod,
        )

    def resolve_contact(self, raw: _RawContact, rods: dict[str, Rod]) -> ContactPoint:
        rod = self.rod_reference(raw.rod, rods, "a rod")
        return ContactPoint(
            rod.name, raw.fraction, raw.stiffness, raw.damping, raw.friction, raw.slip, raw.rod
        )
