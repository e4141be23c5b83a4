"""The .fig grammar: the shipped figures, defaults, whole-message errors, hypothesis fuzzing."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import pytest
from conftest import parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mosys.parsing.figure import (
    DEFAULT_GRAVITY,
    KEYWORDS,
    TERRAIN_HALF_WIDTH,
    ContactPoint,
    Coordinate,
    Figure,
    Joint,
    JointLimit,
    Rod,
    Terrain,
    parse_figure_spec,
    parse_figure_text,
    render_figure_spec,
)
from mosys.parsing.tokens import SpecError

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "specs" / "figures"

# --- the shipped figures ----------------------------------------------------------------------


def test_link1_is_the_1990_pendulum() -> None:
    figure = parse_figure_spec(FIGURES / "link1.fig")
    assert figure.gravity == 9.81
    assert figure.rods == (Rod("link", length=1.0, mass=1.0, com=0.5, inertia=1.0 / 12.0),)
    assert figure.joints == (
        Joint(
            "pin",
            "link",
            (Coordinate("angle", "omega", "angle", "link", "torque"),),
            pivot=(0.0, 0.0),
        ),
    )
    assert figure.limits == () and figure.contacts == () and figure.terrain.vertices == ()
    assert figure.q_names == ("angle",)
    assert figure.qd_names == ("omega",)
    assert figure.state_names == ("angle", "omega")
    assert figure.tau_names == ("torque",)
    assert figure.name == "link1"
    data = (FIGURES / "link1.fig").read_bytes()
    assert figure.spec_sha256 == hashlib.sha256(data).hexdigest()


def test_double_pendulum() -> None:
    figure = parse_figure_spec(FIGURES / "double_pendulum.fig")
    assert [rod.name for rod in figure.rods] == ["upper", "lower"]
    assert figure.q_names == ("shoulder", "elbow")
    assert figure.qd_names == ("shoulder_rate", "elbow_rate")
    assert figure.tau_names == ("shoulder_torque", "elbow_torque")
    lower = figure.joint("lower")
    assert (lower.kind, lower.parent, lower.position, lower.offset) == ("hinge", "upper", 1.0, 0.0)
    assert figure.parent_index() == (-1, 0)


def test_free3() -> None:
    figure = parse_figure_spec(FIGURES / "free3.fig")
    assert figure.gravity == 0.0
    assert figure.root.kind == "free"
    assert figure.q_names == ("x", "y", "heading", "arm", "leg")
    assert figure.qd_names == ("vx", "vy", "spin", "arm_rate", "leg_rate")
    assert [c.is_angle for c in figure.coordinates] == [False, False, True, True, True]
    assert figure.tau_names == ("", "", "", "arm_torque", "leg_torque")
    assert figure.rod("arm") == Rod("arm", 0.8, 1.0, 0.4, 0.07)
    arm, leg = figure.joint("arm"), figure.joint("leg")
    assert arm.position == 0.5 and arm.offset == pytest.approx(math.radians(60))
    assert leg.position == 1.2 and leg.offset == pytest.approx(math.radians(-30))


def test_defaults() -> None:
    figure = parse_figure_text(
        "rod a length=2 mass=3\nrod b length=1 mass=1\npin a\nhinge b on=a\n"
    )
    assert figure.gravity == DEFAULT_GRAVITY
    assert figure.rod("a") == Rod("a", 2.0, 3.0, 0.5, 3.0 * 4.0 / 12.0)
    assert figure.joint("a").pivot == (0.0, 0.0)
    assert figure.joint("b").position == 2.0  # the parent's distal end
    assert figure.q_names == ("a", "b")  # a coordinate is named after its rod
    assert figure.qd_names == ("a_rate", "b_rate")
    assert figure.tau_names == ("", "")  # unactuated
    free = parse_figure_text("rod body length=1 mass=1\nfree body\n")
    assert free.q_names == ("x", "y", "body")
    assert free.qd_names == ("x_rate", "y_rate", "body_rate")


def test_limits_contacts_terrain() -> None:
    figure = parse_figure_text(
        """\
gravity 9.81
rod base length=0.3 mass=1
rod leg length=0.5 mass=0.5       # declared before its joint: order does not matter
hinge leg on=base at=0.15 offset=90 actuator=leg_torque
free base x=px y=py angle=tilt rate=tilt_rate
limit leg lower=-80 upper=80 stiffness=200 damping=2
contact base fraction=0 stiffness=20000 damping=200 friction=0.8
contact base fraction=1 stiffness=20000
terrain steps 1,-0.2 3,-0.4 height=0.1
""",
        "luxo.fig",
    )
    assert figure.q_names == ("leg", "px", "py", "tilt")  # joint lines in file order
    assert figure.limits == (
        JointLimit("leg", "leg", math.radians(-80), math.radians(80), 200.0, 2.0),
    )
    assert figure.contacts == (
        ContactPoint("base", 0.0, 20000.0, 200.0, 0.8, 0.01),
        ContactPoint("base", 1.0, 20000.0, 0.0, 0.0, 0.01),
    )
    w = TERRAIN_HALF_WIDTH
    assert figure.terrain.vertices == (
        (-w, 0.1),
        (1.0, 0.1),
        (1.0, -0.2),
        (3.0, -0.2),
        (3.0, -0.4),
        (w, -0.4),
    )
    floor = parse_figure_text("rod a length=1 mass=1\npin a\nterrain floor\n").terrain
    assert floor.vertices == ((-w, 0.0), (w, 0.0))
    line = parse_figure_text("rod a length=1 mass=1\npin a\nterrain polyline 0,0 1,0 1,-1\n")
    assert line.terrain.vertices == ((0.0, 0.0), (1.0, 0.0), (1.0, -1.0))
    one_sided = parse_figure_text("rod a length=1 mass=1\npin a\nlimit a upper=10 stiffness=1\n")
    assert one_sided.limits[0].lower == -math.inf


# --- whole-message errors ---------------------------------------------------------------------

ROD = "rod a length=1 mass=1\n"
ROD_B = "rod b length=1 mass=1\n"
ERRORS = {
    "rods link length=1 mass=1\n": "bad.fig:1:1: expected one of 'gravity', 'rod', 'pin', "
    "'free', 'hinge', 'limit', 'contact', 'terrain', 'vehicle', found 'rods'",
    "rod link length=one mass=1\npin link\n": "bad.fig:1:17: expected a number for length (m), "
    "found 'one'",
    "rod link length=0 mass=1\npin link\n": "bad.fig:1:17: expected a number > 0 for length "
    "(m), found '0'",
    "rod link length=1\npin link\n": "bad.fig:1:18: expected 'mass=' (the rod's mass in kg), "
    "found end of line",
    "rod link length=1 mass=1 com=1.5\npin link\n": "bad.fig:1:30: expected a number from 0 to "
    "1 for com (fraction of the length), found '1.5'",
    "rod link length=1 mass=1 colour=red\n": "bad.fig:1:26: expected one of 'length=', "
    "'mass=', 'com=', 'inertia=', found 'colour=red'",
    "rod a length=1 mass=1\nrod a length=2 mass=1\npin a\n": "bad.fig:2:5: expected a rod "
    "name not used before (line 1), found 'a'",
    ROD + ROD_B + "pin a\nhinge b on=c\n": "bad.fig:4:12: expected a parent rod named by a "
    "'rod' line (one of 'a', 'b'), found 'c'",
    ROD + ROD_B + "rod c length=1 mass=1\npin a\nhinge b on=c\nhinge c on=b\n": "bad.fig:6:12: "
    "expected a parent that does not close a cycle (b -> c -> b), found 'b'",
    ROD + ROD_B + "pin a\nfree b\n": "bad.fig:4:1: expected one root ('pin' or 'free') only "
    "(the first is line 3), found 'free'",
    ROD + ROD_B + "hinge b on=a\n": "bad.fig:4:1: expected a root line ('pin' or 'free'), "
    "found end of file",
    ROD + ROD_B + "pin a\n": "bad.fig:4:1: expected a joint line ('hinge', 'pin' or 'free') "
    "for rod 'b' (line 2), found end of file",
    ROD + ROD_B + "pin a angle=theta\nhinge b on=a angle=theta\n": "bad.fig:4:20: expected a "
    "coordinate name not used by another coordinate, rate or actuator (line 3), found 'theta'",
    ROD + ROD_B + "pin a\nhinge b on=a angle=e rate=e_rate actuator=e_rate\n": "bad.fig:4:43: "
    "expected an actuator name not used by another coordinate, rate or actuator (line 4), "
    "found 'e_rate'",
    ROD + "pin a actuator=\n": "bad.fig:2:16: expected a name for the pin's actuator, found "
    "end of line",
    ROD + ROD_B + "pin a\nhinge b on=a at=1.5\n": "bad.fig:4:17: expected a number from 0 to "
    "1 (the length of 'a') for at (m along the parent), found '1.5'",
    ROD + "free a\nlimit a lower=-10 stiffness=5\n": "bad.fig:3:7: expected a rod with a 'pin' "
    "or 'hinge' joint (a free root has no limit), found 'a'",
    # the free root's message, not "expected 'stiffness='" first (adding one only led to it)
    ROD + "free a\nlimit a lower=-10 upper=10\n": "bad.fig:3:7: expected a rod with a 'pin' "
    "or 'hinge' joint (a free root has no limit), found 'a'",
    ROD + "pin a\nlimit a lower=-10 upper=10\n": "bad.fig:3:27: expected 'stiffness=' "
    "(N·m/rad), found end of line",
    ROD + "pin a\nlimit a lower=10 upper=-10 stiffness=5\n": "bad.fig:3:24: expected a number "
    "> lower (10) for upper (degrees), found '-10'",
    "gravity 9.81\ngravity 1.6\n" + ROD + "pin a\n": "bad.fig:2:1: expected one 'gravity' line "
    "only (the first is line 1), found 'gravity'",
    "gravity -9.81\n": "bad.fig:1:9: expected a number >= 0 for gravity (m/s², pointing down), "
    "found '-9.81'",
    ROD + "pin a at=0,zero\n": "bad.fig:2:12: expected a number for at y, found 'zero'",
    ROD + "pin a\nterrain polyline 0,0 1,0 0.5,-1\n": "bad.fig:3:26: expected a vertex with "
    "x >= 1 (vertices run left to right), found '0.5,-1'",
    ROD + "pin a\ncontact a fraction=1\n": "bad.fig:3:21: expected 'stiffness=' (N/m), found "
    "end of line",
    "# only a comment\n\n": "bad.fig:1:1: expected a 'rod' line, found end of file",
}


@pytest.mark.parametrize("text", list(ERRORS))
def test_error_messages(text: str) -> None:
    with pytest.raises(SpecError) as error:
        parse_figure_text(text, "bad.fig")
    assert str(error.value) == ERRORS[text]


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nothing.fig"
    with pytest.raises(SpecError) as error:
        parse_figure_spec(path)
    assert str(error.value) == f"{path}:1:1: expected an existing spec file, found no such file"


# --- hypothesis -------------------------------------------------------------------------------

NAMES = st.sampled_from(["a", "b", "c", "link", "x", "y", "angle", "omega", "torque", "1bad"])
NUMBERS = st.sampled_from(
    ["0", "1", "-1", "0.5", "2.5e-1", "1e200", "1e400", "nan", "90", "-180", "x"]
)
VALUES = st.one_of(NAMES, NUMBERS, st.just("0,0"), st.just("1,-2"), st.just(""))
KEYS = st.sampled_from(
    [
        "length",
        "mass",
        "com",
        "inertia",
        "at",
        "on",
        "offset",
        "angle",
        "rate",
        "actuator",
        "x",
        "y",
        "x_rate",
        "y_rate",
        "lower",
        "upper",
        "stiffness",
        "damping",
        "fraction",
        "friction",
        "slip",
        "height",
    ]
)
WORDS = st.one_of(
    st.sampled_from([*KEYWORDS, "floor", "steps", "polyline", "#", "=", ","]),
    NAMES,
    NUMBERS,
    st.builds(lambda key, value: f"{key}={value}", KEYS, VALUES),
    st.text(alphabet=st.characters(codec="utf-8"), max_size=6),
)
LINES = st.lists(st.lists(WORDS, max_size=6).map(" ".join), max_size=10).map("\n".join)


def sound(figure: Figure) -> None:
    """What a figure the parser accepts satisfies."""
    assert isinstance(figure, Figure)
    assert len(figure.joints) == len(figure.rods)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(LINES)
def test_random_text_parses_or_raises_spec_error(text: str) -> None:
    parses_or_spec_error(parse_figure_text, text, "fuzz.fig", sound)


SHIPPED = [(FIGURES / f"{name}.fig").read_text() for name in ("link1", "double_pendulum", "free3")]
FEATURES = """\
gravity 9.81
rod base length=0.3 mass=1
rod leg length=0.5 mass=0.5 com=0.3 inertia=0.02
free base
hinge leg on=base at=0.15 offset=90 actuator=leg_torque
limit leg lower=-80 upper=80 stiffness=200 damping=2
contact base fraction=0 stiffness=20000 damping=200 friction=0.8
terrain steps 1,-0.2 height=0
"""


@st.composite
def mutated(draw: st.DrawFn) -> str:
    """A shipped or feature-rich spec with a few characters deleted, replaced or inserted."""
    text = draw(st.sampled_from([*SHIPPED, FEATURES]))
    for _ in range(draw(st.integers(1, 4))):
        position = draw(st.integers(0, len(text)))
        kind = draw(st.sampled_from(["delete", "replace", "insert"]))
        character = draw(st.sampled_from(list(" \n=,#-.0159aexz_")))
        if kind == "delete":
            text = text[:position] + text[position + 1 :]
        elif kind == "replace":
            text = text[:position] + character + text[position + 1 :]
        else:
            text = text[:position] + character + text[position:]
    return text


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def test_mutated_text_parses_or_raises_spec_error(text: str) -> None:
    parses_or_spec_error(parse_figure_text, text, "fuzz.fig", sound)


POSITIVE = st.floats(0.01, 100.0)


@st.composite
def figures(draw: st.DrawFn) -> Figure:
    """A random valid figure: a tree of 1-5 rods, pinned or free, with limits and contacts."""
    count = draw(st.integers(1, 5))
    rods = tuple(
        Rod(
            f"r{i}",
            draw(POSITIVE),
            draw(POSITIVE),
            draw(st.floats(0.0, 1.0)),
            draw(POSITIVE),
        )
        for i in range(count)
    )
    free = draw(st.booleans())
    joints = []
    for i, rod in enumerate(rods):
        actuator = draw(st.sampled_from(["", f"m{i}"]))
        if i == 0 and free:
            x = Coordinate("px", "vx", "x", rod.name)
            y = Coordinate("py", "vy", "y", rod.name)
            angle = Coordinate(f"q{i}", f"w{i}", "angle", rod.name)  # a free root is unactuated
            joints.append(Joint("free", rod.name, (x, y, angle)))
        elif i == 0:
            angle = Coordinate(f"q{i}", f"w{i}", "angle", rod.name, actuator)
            pivot = (draw(st.floats(-5, 5)), draw(st.floats(-5, 5)))
            joints.append(Joint("pin", rod.name, (angle,), pivot=pivot))
        else:
            angle = Coordinate(f"q{i}", f"w{i}", "angle", rod.name, actuator)
            parent = rods[draw(st.integers(0, i - 1))]
            position = draw(st.floats(0.0, 1.0)) * parent.length
            offset = math.radians(draw(st.floats(-180, 180)))
            joints.append(Joint("hinge", rod.name, (angle,), parent.name, position, offset))
    order = draw(st.permutations(joints))
    limits = []
    for joint in joints:
        if joint.kind != "free" and draw(st.booleans()):
            lower = math.radians(draw(st.floats(-170, -1)))
            upper = math.radians(draw(st.floats(1, 170)))
            limits.append(JointLimit(joint.rod, joint.coordinates[0].name, lower, upper, 10.0, 0.5))
    contacts = tuple(
        ContactPoint(rod.name, draw(st.floats(0, 1)), 1000.0, 10.0, 0.5, 0.01)
        for rod in rods
        if draw(st.booleans())
    )
    terrain = draw(
        st.sampled_from(
            [
                Terrain(),
                Terrain("floor", -0.5),
                Terrain("steps", 0.0, ((1.0, -0.2), (2.0, -0.4))),
                Terrain("polyline", 0.0, ((-3.0, 0.0), (0.0, 0.0), (0.0, -1.0), (3.0, -1.0))),
            ]
        )
    )
    return Figure(
        "<random>",
        draw(st.floats(0, 20)),
        rods,
        tuple(order),
        tuple(limits),
        contacts,
        terrain,
    )


def assert_same_figure(a: Figure, b: Figure) -> None:
    """Equal, except angles that went through degrees (within 1e-12 rad)."""
    assert a.gravity == b.gravity and a.rods == b.rods
    assert a.contacts == b.contacts and a.terrain == b.terrain
    assert len(a.joints) == len(b.joints)
    for x, y in zip(a.joints, b.joints, strict=True):
        assert (x.kind, x.rod, x.coordinates, x.parent, x.position, x.pivot) == (
            y.kind,
            y.rod,
            y.coordinates,
            y.parent,
            y.position,
            y.pivot,
        )
        assert x.offset == pytest.approx(y.offset, abs=1e-12)
    assert len(a.limits) == len(b.limits)
    for x, y in zip(a.limits, b.limits, strict=True):
        assert (x.rod, x.coordinate, x.stiffness, x.damping) == (
            y.rod,
            y.coordinate,
            y.stiffness,
            y.damping,
        )
        assert x.lower == pytest.approx(y.lower, abs=1e-12)
        assert x.upper == pytest.approx(y.upper, abs=1e-12)


@settings(max_examples=150, deadline=None)
@given(figures())
def test_render_then_parse_round_trips(figure: Figure) -> None:
    assert_same_figure(parse_figure_text(render_figure_spec(figure)), figure)


@pytest.mark.parametrize("name", ["link1", "double_pendulum", "free3"])
def test_shipped_figures_round_trip(name: str) -> None:
    figure = parse_figure_spec(FIGURES / f"{name}.fig")
    assert_same_figure(parse_figure_text(render_figure_spec(figure)), figure)
