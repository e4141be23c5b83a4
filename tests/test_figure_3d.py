"""3-D figures: the .fig grammar's ball joints, their binding to the 3-D BSR kernel arrays, and
the shipped figures of the 1995 paper's §4 (Cujo, Rex, Bob) checked standing at rest with an
independent forward kinematics."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mosys.bsr.figure import bsr_figure
from mosys.bsr.figure3d import CONTACT_MODEL, BsrFigure3D, bsr_figure3d, load_bsr_figure3d
from mosys.dynamics.compile import compile_figure
from mosys.io.trajectory import read_figure_motion, write_figure_motion
from mosys.kernels.bsr3d_simulate import FigureArrays3D
from mosys.parsing.figure import (
    KEYWORDS,
    KEYWORDS_3D,
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
from mosys.parsing.tokens import SpecError, Token

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "specs" / "figures"
SHIPPED_3D = ("cujo", "rex", "bob")
# named, not globbed: a user's own 3-D figure in specs/figures/ (the README's way to add one) is
# no shipped planar figure
SHIPPED_PLANAR = ("beryl", "double_pendulum", "free3", "link1", "luxo", "luxo_grounded", "starman")


def load(name: str) -> BsrFigure3D:
    figure = parse_figure_spec(FIGURES / f"{name}.fig")
    assert isinstance(figure, Figure)
    return bsr_figure3d(figure)


# --- an independent forward kinematics, from the kernel contract's formula --------------------


def rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rest_pose(figure: BsrFigure3D, angles: np.ndarray | None = None) -> np.ndarray:
    """(N, 2, 3) m: every rod's proximal and distal end with the given joint angles (J,) rad
    (default all 0), root angle 0 and the root's proximal end at the origin. Parent frame @
    Rz(offset) @ Ry(splay) @ Rz(θ) @ Ry(ψ); a child hangs hinge[k] along its parent's x axis.
    Rest rotations are built here from the parsed joints' offset and splay, not from the
    binding's ``rest``."""
    if angles is None:
        angles = np.zeros(len(figure.joint_names))
    frames: list[np.ndarray] = []
    ends = np.zeros((len(figure.length), 2, 3))
    for k, rod in enumerate(figure.figure.rods):
        joint = figure.figure.joint(rod.name)
        rest = rz(joint.offset) @ ry(joint.splay)
        p = figure.parent[k]
        if p < 0:
            frames.append(rest)
        else:
            theta, psi = angles[figure.joint[k]], angles[figure.joint[k] + 1]
            frames.append(frames[p] @ rest @ rz(theta) @ ry(psi))
            ends[k, 0] = ends[p, 0] + figure.hinge[k] * frames[p][:, 0]
        ends[k, 1] = ends[k, 0] + figure.length[k] * frames[k][:, 0]
    return ends


def heading(figure: BsrFigure3D, ends: np.ndarray) -> float:
    """DESIGN.md's heading, deg: the heading rod's (x, z) direction, CCW from above (+x = 0,
    -z = +90), plus the heading offset."""
    dx, _, dz = ends[figure.heading_rod, 1] - ends[figure.heading_rod, 0]
    return math.degrees(math.atan2(-dz, dx) + figure.heading_offset)


def centre_of_mass(figure: BsrFigure3D, ends: np.ndarray) -> np.ndarray:
    points = ends[:, 0] + figure.com[:, None] * (ends[:, 1] - ends[:, 0])
    return (figure.mass[:, None] * points).sum(axis=0) / figure.total_mass


# --- the shipped figures ----------------------------------------------------------------------

# rods, angles, free angles, mean free range (deg), total mass (kg)
SHIPPED_NUMBERS = {
    "cujo": (7, 12, 10, 25.0, 25.5),
    "rex": (15, 28, 10, 40.0, 42.1),
    "bob": (9, 16, 11, 24.727, 62.0),
}


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_shipped_figure_numbers(name: str) -> None:
    figure = load(name)
    rods, angles, free, mean_range, mass = SHIPPED_NUMBERS[name]
    assert figure.figure.dimensions == 3
    assert len(figure.length) == rods
    assert len(figure.joint_names) == angles == 2 * (rods - 1)
    assert figure.free.sum() == free
    ranges = np.degrees(figure.joint_max - figure.joint_min)
    assert ranges[figure.free].mean() == pytest.approx(mean_range, abs=1e-3)
    assert figure.total_mass == pytest.approx(mass)
    # every angle's range holds the rest pose (all angles 0)
    assert np.all(figure.joint_min <= 0.0) and np.all(figure.joint_max >= 0.0)


def test_paper_proportions() -> None:
    """Rex: 10 free angles (the paper's 47 variables at R = 4), about two thirds fixed, free
    ranges about 40 deg; Bob: about a third fixed, free ranges a little under 25 deg; Cujo's
    about 25 deg."""
    rex, bob, cujo = load("rex"), load("bob"), load("cujo")
    assert rex.free.sum() * 4 + 4 + 3 == 47
    assert 0.6 < 1 - rex.free.mean() < 0.7
    assert 0.25 < 1 - bob.free.mean() < 0.4
    bob_ranges = np.degrees(bob.joint_max - bob.joint_min)[bob.free]
    assert 22 < bob_ranges.mean() < 25
    cujo_ranges = np.degrees(cujo.joint_max - cujo.joint_min)[cujo.free]
    assert 22 < cujo_ranges.mean() < 28


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_shipped_figure_stands_at_rest(name: str) -> None:
    """All angles 0, root angle 0: the feet are the lowest endpoints, level within 1 mm, the
    figure faces +x (heading 0) and its centre of mass is over the points it stands on."""
    figure = load(name)
    ends = rest_pose(figure)
    feet = np.array([ends[rod, end] for rod, end in figure.feet])
    lowest = ends[:, :, 1].min()
    assert len(feet) >= 2
    assert np.ptp(feet[:, 1]) < 1e-3
    assert feet[:, 1].max() < lowest + 1e-3
    assert heading(figure, ends) == pytest.approx(0.0, abs=1e-9)
    com = centre_of_mass(figure, ends)
    support = ends.reshape(-1, 3)[ends.reshape(-1, 3)[:, 1] < lowest + 1e-3]
    for axis in (0, 2):  # x and z within the bounding box of the points on the floor
        assert support[:, axis].min() - 1e-9 <= com[axis] <= support[:, axis].max() + 1e-9
    assert com[1] - lowest > 0.3  # standing up


def test_standing_heights() -> None:
    """The centre of mass above the feet at rest, m (the README quotes these)."""
    heights = {}
    for name in SHIPPED_3D:
        figure = load(name)
        ends = rest_pose(figure)
        heights[name] = centre_of_mass(figure, ends)[1] - ends[:, :, 1].min()
    assert heights == pytest.approx({"cujo": 0.366, "rex": 0.661, "bob": 0.924}, abs=1e-3)


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_binding_matches_the_contract(name: str) -> None:
    figure = load(name)
    parsed = figure.figure
    n = len(parsed.rods)
    for k, rod in enumerate(parsed.rods):
        joint = parsed.joint(rod.name)
        assert figure.rest[k] == pytest.approx(rz(joint.offset) @ ry(joint.splay), abs=1e-15)
        if k == 0:
            assert (figure.parent[k], figure.joint[k]) == (-1, -1)
            continue
        assert parsed.rods[figure.parent[k]].name == joint.parent
        assert figure.parent[k] < k
        assert figure.joint[k] == 2 * (k - 1)
        assert figure.joint_names[figure.joint[k]] == joint.angle.name
        swing = joint.swing.name if joint.kind == "ball" else f"{rod.name}_swing"
        assert figure.joint_names[figure.joint[k] + 1] == swing
        if joint.kind == "hinge":
            assert figure.joint_min[figure.joint[k] + 1] == figure.joint_max[figure.joint[k] + 1]
    assert figure.rest.shape == (n, 3, 3)
    for rotation in figure.rest:
        assert rotation @ rotation.T == pytest.approx(np.eye(3), abs=1e-12)
    arrays = figure.arrays
    assert isinstance(arrays, FigureArrays3D)
    assert arrays.reach == pytest.approx(figure.length.sum())
    assert arrays.floor == 0.0 and arrays.gravity == 9.81
    assert arrays.parent.dtype == np.int64 and arrays.joint.dtype == np.int64
    assert arrays.endpoints.dtype == np.int64 and arrays.endpoints.shape[1] == 2
    assert figure.root_x == "x" and figure.root_angle == parsed.root.angle.name
    assert parsed.heading_rod == parsed.rods[figure.heading_rod].name


def test_cujo_endpoints_and_angles() -> None:
    cujo = load("cujo")
    assert cujo.endpoint_names == (
        "spine.proximal",
        "spine.distal",
        "head.distal",
        "tail.distal",
        "front_left.distal",
        "front_right.distal",
        "hind_left.distal",
        "hind_right.distal",
    )
    assert cujo.feet == ((3, 1), (4, 1), (5, 1), (6, 1))
    assert cujo.joint_names[:6] == (
        "head",
        "head_turn",
        "tail",
        "tail_swing",
        "front_left",
        "front_left_swing",
    )
    assert cujo.free.tolist() == [True, False, True, False] + [True] * 8
    assert np.degrees(cujo.joint_min[:4]) == pytest.approx([-15, 0, -20, 0])
    assert (cujo.heading_rod, cujo.heading_offset) == (0, 0.0)


def test_bob_swing_turns_a_leg_forward() -> None:
    """Bob's hips swing forwards (+x) for positive swing and out to his right (+z) for a
    positive side angle, as bob.fig's header says."""
    bob = load("bob")
    thigh = bob.figure.rod_index("thigh_left")
    for name, axis in (("hip_left", 0), ("hip_left_side", 2)):
        angles = np.zeros(len(bob.joint_names))
        angles[bob.joint_names.index(name)] = math.radians(10)
        step = rest_pose(bob, angles)[thigh, 1] - rest_pose(bob)[thigh, 1]
        assert step[axis] > 0.05 and abs(step[2 - axis]) < 1e-12


def test_motion_is_the_3d_contract(tmp_path: Path) -> None:
    bob = load("bob")
    ends = rest_pose(bob)[None].repeat(3, axis=0)
    com = np.array([centre_of_mass(bob, ends[0])] * 3)
    motion = bob.motion(ends, com, 0.01)
    assert motion.t == pytest.approx([0.0, 0.01, 0.02])
    assert motion.dimensions == 3 and motion.contact == CONTACT_MODEL
    assert motion.heading_rod == "pelvis" and motion.heading_offset == pytest.approx(90.0)
    assert motion.feet == ((6, 1), (8, 1))
    assert motion.terrain == [[-1000.0, 0.0], [1000.0, 0.0]]
    assert motion.rod_names[0] == "pelvis" and motion.rod_mass.sum() == pytest.approx(62.0)
    with h5py.File(tmp_path / "motion.h5", "w") as h5:
        write_figure_motion(h5.create_group("figure_motion"), motion)
    with h5py.File(tmp_path / "motion.h5") as h5:
        back = read_figure_motion(h5["figure_motion"])
    assert back.endpoints.shape == (3, 9, 2, 3) and back.feet == motion.feet
    assert (back.dimensions, back.heading_rod) == (3, "pelvis")


def test_load_bsr_figure3d(tmp_path: Path) -> None:
    token = Token("rex", 1, 8)
    assert load_bsr_figure3d(FIGURES, "walk.bsr", token).figure.name == "rex"
    with pytest.raises(SpecError) as error:
        load_bsr_figure3d(tmp_path, "walk.bsr", token)
    assert str(error.value) == (
        f"walk.bsr:1:8: expected a figure in {tmp_path}, found 'rex' (no {tmp_path / 'rex.fig'})"
    )
    with pytest.raises(SpecError) as error:
        load_bsr_figure3d(FIGURES, "walk.bsr", Token("car", 1, 8))
    assert str(error.value) == "walk.bsr:1:8: expected a figure of rods, not a vehicle, found 'car'"


# --- the grammar ------------------------------------------------------------------------------

SMALL = """\
rod body length=1 mass=4
rod leg length=0.5 mass=1 com=0.4
rod arm length=0.4 mass=1
free body offset=30 splay=-90
ball leg on=body at=0.2 offset=-90 splay=10 angle=hip rate=hip_speed swing=hip_out
hinge arm on=body offset=45
limit leg lower=-20 upper=20 swing_lower=0 swing_upper=0
limit arm lower=-10 upper=10 stiffness=5
heading body offset=90
feet leg.distal body.proximal
terrain floor
"""


def test_ball_joint_and_3d_lines() -> None:
    figure = parse_figure_text(SMALL, "small.fig")
    assert figure.dimensions == 3
    assert figure.q_names == ("x", "y", "body", "hip", "hip_out", "arm")
    assert figure.qd_names == (
        "x_rate",
        "y_rate",
        "body_rate",
        "hip_speed",
        "hip_out_rate",
        "arm_rate",
    )
    root, leg, arm = figure.joints
    assert (root.offset, root.splay) == pytest.approx((math.radians(30), math.radians(-90)))
    assert leg == Joint(
        "ball",
        "leg",
        (
            Coordinate("hip", "hip_speed", "angle", "leg"),
            Coordinate("hip_out", "hip_out_rate", "swing", "leg"),
        ),
        parent="body",
        position=0.2,
        offset=math.radians(-90),
        splay=math.radians(10),
    )
    assert leg.angle.name == "hip" and leg.swing is not None and leg.swing.is_angle
    assert arm.kind == "hinge" and arm.swing is None and arm.position == 1.0
    assert figure.limits == (
        JointLimit("leg", "hip", math.radians(-20), math.radians(20), 0.0, 0.0, 0.0, 0.0),
        JointLimit("arm", "arm", math.radians(-10), math.radians(10), 5.0, 0.0),
    )
    assert figure.heading_rod == "body" and figure.heading_offset == pytest.approx(math.pi / 2)
    assert figure.feet == (("leg", "distal"), ("body", "proximal"))
    bound = bsr_figure3d(figure)
    assert bound.joint_names == ("hip", "hip_out", "arm", "arm_swing")
    assert bound.free.tolist() == [True, False, True, False]
    assert bound.endpoint_names == (
        "body.proximal",
        "body.distal",
        "leg.proximal",
        "leg.distal",
        "arm.distal",
    )
    assert bound.feet == ((1, 1), (0, 0))


def test_ball_defaults() -> None:
    figure = parse_figure_text(
        "rod a length=2 mass=1\nrod b length=1 mass=1\nfree a\nball b on=a\nheading a\n"
    )
    ball = figure.joint("b")
    assert ball.coordinates == (
        Coordinate("b", "b_rate", "angle", "b"),
        Coordinate("b_swing", "b_swing_rate", "swing", "b"),
    )
    assert (ball.position, ball.offset, ball.splay) == (2.0, 0.0, 0.0)
    assert (figure.root.offset, figure.root.splay) == (0.0, 0.0)
    assert (figure.heading_offset, figure.feet) == (0.0, ())


def test_planar_figures_are_unchanged() -> None:
    """Every shipped planar figure is 2-D, with no 3-D part, and renders without 3-D words."""
    for name in SHIPPED_PLANAR:
        path = FIGURES / f"{name}.fig"
        figure = parse_figure_spec(path)
        assert isinstance(figure, Figure), path
        assert figure.dimensions == 2, path
        assert (figure.heading_rod, figure.heading_offset, figure.feet) == ("", 0.0, ())
        assert all(joint.splay == 0.0 and joint.swing is None for joint in figure.joints)
        keywords = {line.split()[0] for line in render_figure_spec(figure).splitlines()}
        assert keywords <= set(KEYWORDS), path


PLANAR = "rod a length=1 mass=1\nrod b length=1 mass=1\n"
SPATIAL = PLANAR + "free a\nball b on=a\n"
ERRORS_3D = {
    PLANAR + "free a offset=10\n": "bad.fig:3:8: expected a planar root's option ('offset=' "
    "needs a 3-D figure: one with 'ball' joints), found 'offset=10'",
    PLANAR + "free a\nhinge b on=a\nheading a\n": "bad.fig:5:1: expected a planar figure's "
    "keyword ('heading' needs a 3-D figure: one with 'ball' joints), found 'heading'",
    SPATIAL: "bad.fig:5:1: expected a 'heading' line, found end of file",
    SPATIAL + "heading a\nheading b\n": "bad.fig:6:1: expected one 'heading' line only (the "
    "first is line 5), found 'heading'",
    SPATIAL + "heading c\n": "bad.fig:5:9: expected a heading rod named by a 'rod' line (one of "
    "'a', 'b'), found 'c'",
    SPATIAL + "wheel a\n": "bad.fig:5:1: expected one of 'gravity', 'rod', 'pin', 'free', "
    "'hinge', 'limit', 'contact', 'terrain', 'vehicle', 'ball', 'heading', 'feet', found 'wheel'",
    SPATIAL + "heading a\nfeet\n": "bad.fig:6:5: expected an endpoint 'rod.proximal' or "
    "'rod.distal', found end of line",
    SPATIAL + "heading a\nfeet b.toe\n": "bad.fig:6:8: expected 'proximal' or 'distal' after "
    "'b.', found 'toe'",
    SPATIAL + "heading a\nfeet b.distal b.distal\n": "bad.fig:6:15: expected each endpoint once "
    "('b.distal' is at column 6), found 'b.distal'",
    SPATIAL + "heading a\nfeet c.distal\n": "bad.fig:6:6: expected a rod named by a 'rod' line "
    "(one of 'a', 'b'), found 'c'",
    SPATIAL + "heading a\nlimit b stiffness=5\n": "bad.fig:6:20: expected 'lower=', 'upper=', "
    "'swing_lower=' or 'swing_upper=' (degrees), found end of line",
    SPATIAL + "heading a\nlimit b lower=10 upper=5\n": "bad.fig:6:24: expected a number >= "
    "lower (10) for upper (degrees), found '5'",
    SPATIAL + "heading a\nlimit b swing_lower=3 swing_upper=-3\n": "bad.fig:6:35: expected a "
    "number >= swing_lower (3) for swing_upper (degrees), found '-3'",
    PLANAR + "rod c length=1 mass=1\nfree a\nball b on=a\nhinge c on=a\nheading a\n"
    "limit c lower=5 upper=0\n": "bad.fig:8:23: expected a number >= lower (5) for upper "
    "(degrees), found '0'",
    PLANAR + "rod c length=1 mass=1\nfree a\nball b on=a\nhinge c on=a\nheading a\n"
    "limit c lower=-5 upper=5 swing_lower=0 stiffness=5\n": "bad.fig:8:26: expected one of "
    "'lower=', 'upper=', 'stiffness=', 'damping=', found 'swing_lower=0'",
    PLANAR + "rod c length=1 mass=1\nfree a\nball b on=a swing=c_swing\nhinge c on=a\n"
    "heading a\n": "bad.fig:6:7: expected a coordinate name not used by another coordinate, "
    "rate or actuator (line 5), found 'c_swing'",
    SPATIAL + "heading a\nball a on=b actuator=m\n": "bad.fig:6:13: expected one of 'on=', 'at=', "
    "'offset=', 'splay=', 'angle=', 'rate=', 'swing=', 'swing_rate=', found 'actuator=m'",
    SPATIAL + "heading a\nhinge a on=b splay=5\n": "bad.fig:6:14: expected one of 'on=', 'at=', "
    "'offset=', 'angle=', 'rate=', 'actuator=', found 'splay=5'",
}


def test_a_hinge_limit_in_a_3d_figure_is_a_bare_range_that_may_fix_its_angle() -> None:
    """As a ball's: it needed a stiffness, which the kinematic 3-D joints never use, and could
    not fix the angle (lower == upper), so a rigid hinge had to be written as a ball."""
    hinged = PLANAR + "rod c length=1 mass=1\nfree a\nball b on=a\nhinge c on=a\nheading a\n"
    fixed = parse_figure_text(hinged + "limit c lower=20 upper=20\n", "fixed.fig")
    (limit,) = fixed.limits
    assert (limit.lower, limit.upper, limit.stiffness) == (math.radians(20), math.radians(20), 0)
    assert parse_figure_text(render_figure_spec(fixed), "fixed.fig") == fixed
    ranged = parse_figure_text(hinged + "limit c lower=-5 upper=5 stiffness=5\n", "ranged.fig")
    assert ranged.limits[0].stiffness == 5.0  # kept, not used


@pytest.mark.parametrize("text", list(ERRORS_3D))
def test_error_messages(text: str) -> None:
    with pytest.raises(SpecError) as error:
        parse_figure_text(text, "bad.fig")
    assert str(error.value) == ERRORS_3D[text]


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_shipped_figures_round_trip(name: str) -> None:
    figure = parse_figure_spec(FIGURES / f"{name}.fig")
    assert parse_figure_text(render_figure_spec(figure), figure.path) == figure


ANGLES = st.one_of(st.floats(-180, 180), st.just(0.0))  # degrees; 0 often: equal bounds


@st.composite
def figures_3d(draw: st.DrawFn) -> Figure:
    """A random valid 3-D figure: a free root with a rest turn, 1-4 ball or hinge children,
    limits (ball bounds possibly equal), a heading and feet."""
    count = draw(st.integers(2, 5))
    rods = tuple(Rod(f"r{i}", draw(st.floats(0.1, 2.0)), 1.0, 0.5, 0.1) for i in range(count))
    root_angle = Coordinate("a0", "w0", "angle", "r0")
    joints = [
        Joint(
            "free",
            "r0",
            (Coordinate("px", "vx", "x", "r0"), Coordinate("py", "vy", "y", "r0"), root_angle),
            offset=math.radians(draw(ANGLES)),
            splay=math.radians(draw(ANGLES)),
        )
    ]
    limits = []
    for i in range(1, count):
        parent = rods[draw(st.integers(0, i - 1))]
        angle = Coordinate(f"a{i}", f"w{i}", "angle", f"r{i}")
        kind = "ball" if i == 1 else draw(st.sampled_from(["ball", "hinge"]))
        lower, upper = sorted(math.radians(draw(ANGLES)) for _ in range(2))
        placement = {
            "parent": parent.name,
            "position": draw(st.sampled_from([0.0, 0.5, 1.0])) * parent.length,
            "offset": math.radians(draw(ANGLES)),
        }
        if kind == "ball":
            swing = Coordinate(f"s{i}", f"v{i}", "swing", f"r{i}")
            joints.append(
                Joint(
                    "ball", f"r{i}", (angle, swing), splay=math.radians(draw(ANGLES)), **placement
                )
            )
            swing_lower, swing_upper = sorted(math.radians(draw(ANGLES)) for _ in range(2))
            stiffness = draw(st.sampled_from([0.0, 10.0]))
            limits.append(
                JointLimit(
                    f"r{i}", angle.name, lower, upper, stiffness, 0.5, swing_lower, swing_upper
                )
            )
        else:
            joints.append(Joint("hinge", f"r{i}", (angle,), **placement))
            if upper > lower:
                limits.append(JointLimit(f"r{i}", angle.name, lower, upper, 10.0, 0.0))
    ends = [(rod.name, end) for rod in rods for end in ("proximal", "distal")]
    feet = draw(st.lists(st.sampled_from(ends), unique=True, max_size=4))
    return Figure(
        "<random>",
        9.81,
        rods,
        tuple(draw(st.permutations(joints))),
        tuple(limits),
        (),
        draw(st.sampled_from([Terrain(), Terrain("floor", 0.0)])),
        heading_rod=draw(st.sampled_from(rods)).name,
        heading_offset=math.radians(draw(ANGLES)),
        feet=tuple(feet),
    )


def angles(figure: Figure) -> list[float]:
    """Every angle of a figure, rad (what goes through degrees in its text)."""
    values = [figure.heading_offset]
    for joint in figure.joints:
        values += [joint.offset, joint.splay]
    for limit in figure.limits:
        values += [limit.lower, limit.upper, limit.swing_lower, limit.swing_upper]
    return values


def without_angles(figure: Figure) -> Figure:
    return replace(
        figure,
        heading_offset=0.0,
        joints=tuple(replace(joint, offset=0.0, splay=0.0) for joint in figure.joints),
        limits=tuple(
            replace(limit, lower=0.0, upper=0.0, swing_lower=0.0, swing_upper=0.0)
            for limit in figure.limits
        ),
    )


@settings(max_examples=150, deadline=None)
@given(figures_3d())
def test_render_then_parse_round_trips(figure: Figure) -> None:
    """Equal, except angles that went through degrees (within 1e-12 rad)."""
    back = parse_figure_text(render_figure_spec(figure), "<random>")
    assert without_angles(back) == without_angles(figure)
    assert angles(back) == pytest.approx(angles(figure), abs=1e-12)


@st.composite
def mutated_3d(draw: st.DrawFn) -> str:
    """A shipped 3-D spec with a few characters deleted, replaced or inserted."""
    text = (FIGURES / f"{draw(st.sampled_from(SHIPPED_3D))}.fig").read_text()
    for _ in range(draw(st.integers(1, 4))):
        position = draw(st.integers(0, len(text)))
        kind = draw(st.sampled_from(["delete", "replace", "insert"]))
        character = draw(st.sampled_from(list(" \n=,.#-0159aelrwz_")))
        if kind == "delete":
            text = text[:position] + text[position + 1 :]
        elif kind == "replace":
            text = text[:position] + character + text[position + 1 :]
        else:
            text = text[:position] + character + text[position:]
    return text


WORDS_3D = st.one_of(
    st.sampled_from([*KEYWORDS, *KEYWORDS_3D, "a", "b", "a.distal", "b.top", "b.proximal"]),
    st.builds(
        lambda key, value: f"{key}={value}",
        st.sampled_from(
            ["on", "at", "offset", "splay", "swing", "swing_rate", "lower", "upper"]
            + ["swing_lower", "swing_upper", "stiffness", "length", "mass"]
        ),
        st.sampled_from(["a", "b", "0", "1", "-5", "x", ""]),
    ),
)
LINES_3D = st.lists(st.lists(WORDS_3D, min_size=1, max_size=6).map(" ".join), max_size=10).map(
    "\n".join
)


def sound(figure: Figure) -> None:
    assert isinstance(figure, Figure)
    assert len(figure.joints) == len(figure.rods)
    if figure.dimensions == 3:
        assert figure.heading_rod in {rod.name for rod in figure.rods}


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(mutated_3d(), LINES_3D))
def test_text_parses_or_raises_spec_error(text: str) -> None:
    parses_or_spec_error(parse_figure_text, text, "fuzz.fig", sound)


# --- what refuses a 3-D figure, and what the 3-D binding refuses ------------------------------


def ball_token(path: Path) -> tuple[int, int, str]:
    """Line, column and rod name of the first ball line of a spec file."""
    for number, line in enumerate(path.read_text().split("\n"), start=1):
        words = line.split()
        if words and words[0] == "ball":
            return number, line.index(words[1]) + 1, words[1]
    raise AssertionError(f"no ball line in {path}")


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_dynamics_compiler_refuses_a_3d_figure(name: str, tmp_path: Path) -> None:
    path = FIGURES / f"{name}.fig"
    out = tmp_path / f"{name}.py"
    with pytest.raises(SpecError) as error:
        compile_figure(path, out)
    line, column, rod = ball_token(path)
    assert str(error.value) == (
        f"{path}:{line}:{column}: expected a planar figure (ball joints are for 3-D BSR "
        f"figures), found '{rod}'"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", SHIPPED_3D)
def test_planar_bsr_binding_refuses_a_3d_figure(name: str) -> None:
    path = FIGURES / f"{name}.fig"
    with pytest.raises(SpecError) as error:
        bsr_figure(parse_figure_spec(path))
    line, column, rod = ball_token(path)
    assert str(error.value) == (
        f"{path}:{line}:{column}: expected a planar figure (ball joints are for the 3-D BSR "
        f"search: bsr.figure3d), found '{rod}'"
    )


BINDING = """\
rod a length=1 mass=1
rod b length=1 mass=1
rod c length=1 mass=1
free a
ball b on=a
hinge c on=a at=0.5
limit b lower=-10 upper=10 swing_lower=-5 swing_upper=5
limit c lower=-10 upper=10 stiffness=1
heading a
terrain floor
"""
BINDING_ERRORS = {
    BINDING.replace("free a", "pin a"): "bad.fig:4:5: expected a 'free' root, as BSR figures fly "
    "and fall, found 'a'",
    BINDING.replace(
        "rod a length=1 mass=1\nrod b length=1 mass=1\n",
        "rod b length=1 mass=1\nrod a length=1 mass=1\n",
    ): "bad.fig:1:5: expected the root rod 'a' first, found 'b'",
    BINDING.replace("ball b on=a", "ball b on=c"): "bad.fig:2:5: expected rod 'c' before its "
    "child, found 'b'",
    BINDING.replace("limit b lower=-10 upper=10 swing_lower=-5 swing_upper=5\n", ""): "bad.fig:"
    "5:6: expected a 'limit b lower=... upper=... swing_lower=... swing_upper=...' line, found 'b'",
    BINDING.replace(" swing_lower=-5 swing_upper=5", " swing_upper=5"): "bad.fig:7:7: expected "
    "a limit with 'swing_lower=' (degrees): a 3-D BSR figure needs every angle's range, found 'b'",
    BINDING.replace("limit c lower=-10 upper=10", "limit c upper=10"): "bad.fig:8:7: expected a "
    "limit with 'lower=' (degrees): a 3-D BSR figure needs every angle's range, found 'c'",
    BINDING.replace("limit c lower=-10 upper=10 stiffness=1\n", ""): "bad.fig:6:7: expected a "
    "'limit c lower=... upper=...' line, found 'c'",
    # at the terrain line's kind (it was bad.fig:1:1, found end of line)
    BINDING.replace("terrain floor", "terrain steps 1,0.1"): "bad.fig:10:9: expected a flat "
    "'terrain floor' for a BSR figure, found 'steps'",
    # a raised floor: the fitness terms, falls and senses measure heights from y = 0, so it ran
    # and scored the figure as standing 0.3 m higher
    BINDING.replace("terrain floor", "terrain floor height=0.3"): "bad.fig:10:22: expected a "
    "floor at height 0 for a BSR figure (its heights, falls and senses are measured from y = 0), "
    "found '0.3'",
    # every angle fixed: the search ran, scoring a figure no rule could move
    BINDING.replace(
        "lower=-10 upper=10 swing_lower=-5 swing_upper=5",
        "lower=0 upper=0 swing_lower=0 swing_upper=0",
    ).replace(
        "limit c lower=-10 upper=10", "limit c lower=0 upper=0"
    ): "bad.fig:4:6: expected a figure with an angle free to move (every limit here "
    "fixes its angles: a search would have nothing to move), found 'a'",
}


@pytest.mark.parametrize("text", list(BINDING_ERRORS))
def test_binding_errors(text: str) -> None:
    with pytest.raises(SpecError) as error:
        bsr_figure3d(parse_figure_text(text, "bad.fig"))
    assert str(error.value) == BINDING_ERRORS[text]


def test_binding_refuses_a_planar_figure() -> None:
    with pytest.raises(SpecError) as error:
        bsr_figure3d(parse_figure_spec(FIGURES / "starman.fig"))
    path = FIGURES / "starman.fig"
    line = next(
        number
        for number, text in enumerate(path.read_text().split("\n"), start=1)
        if text.startswith("free ")
    )
    assert str(error.value) == (
        f"{path}:{line}:6: expected a 3-D figure (one with 'ball' joints), found 'torso'"
    )


def test_binding_shares_endpoints_and_floor() -> None:
    figure = bsr_figure3d(parse_figure_text(BINDING.replace("terrain floor\n", ""), "x.fig"))
    # b hangs on a's distal end (shared), c at a's middle (its own proximal end)
    assert figure.endpoint_names == ("a.proximal", "a.distal", "b.distal", "c.proximal", "c.distal")
    assert (
        math.isnan(figure.floor)
        and figure.motion(np.zeros((1, 3, 2, 3)), np.zeros((1, 3)), 0.01).terrain == []
    )
    assert figure.hinge.tolist() == [0.0, 1.0, 0.5]


def test_feet_are_distinct_endpoints() -> None:
    """A foot named as a child's proximal end on its parent's end is that endpoint, once."""
    text = BINDING.replace("heading a", "heading a\nfeet b.proximal c.proximal a.distal b.distal")
    figure = bsr_figure3d(parse_figure_text(text, "x.fig"))
    assert figure.feet == ((0, 1), (2, 0), (1, 1))
    rows = [tuple(row) for row in figure.endpoints.tolist()]
    assert all(foot in rows for foot in figure.feet)
