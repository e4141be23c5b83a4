"""The .ssc grammar: the six pendulum specs, whole-message errors, and hypothesis fuzzing."""

from __future__ import annotations

import codecs
import dataclasses
import hashlib
from pathlib import Path

import pytest
from conftest import SpecLines, parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations

from mosys.parsing.controller import (
    DEFAULT_DT,
    DEFAULT_MAX_ITERATIONS,
    DEFAULT_TOLERANCE,
    ControlDimension,
    ControllerSpec,
    Destination,
    StateDimension,
    parse_controller_spec,
    parse_controller_text,
    render_controller_spec,
)
from mosys.parsing.tokens import SpecError, Token

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ROOT / "specs" / "controllers" / "pendulum"
FIGURE_13 = {  # name: (angle deg, omega deg/s)
    "A": (0.0, 0.0),
    "B": (120.0, 0.0),
    "C": (-120.0, 0.0),
    "D": (0.0, 300.0),
    "E": (-120.0, -300.0),
    "F": (160.0, 250.0),
}
BASE = """\
dyn link1
ssd omega -500.0 500.0 21
ssd angle -180 170 36 wrap
torq torque -10.0 10.0 11 0.1
dest angle=0 omega=0
"""


def values(spec: ControllerSpec) -> tuple:
    """Everything a spec says, without tokens, path and hash."""
    return (
        spec.figure,
        tuple((d.name, d.minimum, d.maximum, d.samples, d.wrap) for d in spec.state),
        tuple((c.name, c.minimum, c.maximum, c.samples, c.effort_weight) for c in spec.controls),
        tuple(tuple((e.name, e.value, e.index) for e in line) for line in spec.destinations),
        spec.tolerance,
        spec.max_iterations,
        spec.dt,
        spec.known_weight,
        tuple((o.name, o.vertices) for o in spec.obstacles),
        None if spec.domain is None else spec.domain.vertices,
        spec.hold is not None,
        None
        if spec.policy is None
        else (spec.policy.kind, spec.policy.arrival, spec.policy.aim, spec.policy.arrival_value),
    )


# --- the real specs -------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(FIGURE_13))
def test_pendulum_specs(name):
    path = PENDULUM / f"{name}.ssc"
    spec = parse_controller_spec(path)
    angle, omega = FIGURE_13[name]
    assert spec.path == str(path)
    assert spec.name == name
    assert spec.figure == "link1"
    assert spec.figure_token == Token("link1", 6, 5)
    omega_axis, angle_axis = spec.state
    assert (omega_axis.name, omega_axis.minimum, omega_axis.maximum) == ("omega", -500.0, 500.0)
    assert (omega_axis.samples, omega_axis.wrap, omega_axis.step) == (21, False, 50.0)
    assert omega_axis.period is None
    assert (angle_axis.name, angle_axis.minimum, angle_axis.maximum) == ("angle", -180.0, 170.0)
    assert (angle_axis.samples, angle_axis.wrap, angle_axis.step) == (36, True, 10.0)
    assert angle_axis.period == 360.0
    assert angle_axis.token == Token("angle", 8, 5)
    (torque,) = spec.controls
    assert (torque.name, torque.minimum, torque.maximum) == ("torque", -10.0, 10.0)
    assert (torque.samples, torque.effort_weight) == (11, 0.1)
    assert torque.values() == tuple(float(v) for v in range(-10, 11, 2))
    assert spec.destination_values() == {"angle": angle, "omega": omega}
    assert [e.name for e in spec.destination] == ["angle", "omega"]
    for entry in spec.destination:
        axis = spec.dimension(entry.name)
        assert axis.node(entry.index) == entry.value  # the paper's destinations are nodes
        assert entry.token.line == 10
        assert entry.value_token.text == entry.token.text.split("=")[1]
    assert (spec.tolerance, spec.max_iterations, spec.dt) == (1e-6, 1000, 0.05)
    assert spec.spec_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert [d.name for d in spec.ordered_state(("angle", "omega"))] == ["angle", "omega"]


def test_figure_12_as_the_paper_prints_it_parses_as_a_does():
    """The paper's Figure 12 declares the angle's wrap on a line of its own, ``wrap angle``
    after ``ssd angle -180 170 36`` (its text runs 'ssd angle -180 170 36 wrap angle torq
    ...'); DESIGN.md's form puts ``wrap`` at the end of the ssd line. Both make the same spec."""
    paper = (
        (PENDULUM / "A.ssc")
        .read_text()
        .replace("ssd angle -180 170 36 wrap", "ssd angle -180 170 36\nwrap angle")
    )
    assert "wrap angle" in paper
    assert values(parse_controller_text(paper, "A.ssc")) == values(
        parse_controller_spec(PENDULUM / "A.ssc")
    )


def test_spec_a_is_figure_12_verbatim():
    assert (PENDULUM / "A.ssc").read_text() == (
        "# controller for a single link\n"
        "# controller description commands:\n"
        "# ssd <name> <min> <max> <steps>\n"
        "# torq <name> <tmin> <tmax> <tsteps> <Ktorq>\n"
        "# dest <state>\n"
        "dyn link1  # dynamics equations\n"
        "ssd omega -500.0 500.0 21\n"
        "ssd angle -180 170 36 wrap\n"
        "torq torque -10.0 10.0 11 0.1\n"
        "dest angle=0 omega=0\n"
    )


def test_the_six_specs_differ_only_in_dest():
    a_lines = (PENDULUM / "A.ssc").read_text().splitlines()
    for name in "BCDEF":
        lines = (PENDULUM / f"{name}.ssc").read_text().splitlines()
        assert lines[:-1] == a_lines[:-1]


def test_nodes_and_indices():
    spec = parse_controller_text(BASE)
    angle = spec.dimension("angle")
    assert angle.nodes() == tuple(float(v) for v in range(-180, 171, 10))
    assert spec.dimension("omega").nodes()[-1] == 500.0
    assert {e.name: e.index for e in spec.destination} == {"angle": 18, "omega": 10}
    with pytest.raises(KeyError) as error:
        spec.dimension("torque")
    assert error.value.args == ("torque",)


@pytest.mark.parametrize(
    ("written", "index"),
    [("180", 0), ("540", 0), ("-190", 35), ("170", 35), ("-180", 0), ("-900", 0), ("360", 18)],
)
def test_wrap_destinations_are_wrapped_onto_nodes(written, index):
    spec = parse_controller_text(BASE.replace("angle=0", f"angle={written}"))
    assert spec.destination[0].index == index
    assert spec.destination[0].value == float(written)


def test_several_destinations_in_file_order():
    """Several dest lines (a conditional goal): each parsed as the first is, in file order;
    ``destination`` stays the first; render writes every one."""
    spec = parse_controller_text(BASE + "tol 1e-5\ndest angle=-180 omega=500\ndest omega=0\n")
    assert spec.all_destination_values() == [
        {"angle": 0.0, "omega": 0.0},
        {"angle": -180.0, "omega": 500.0},
        {"omega": 0.0},
    ]
    assert spec.destination == spec.destinations[0]
    assert spec.destination_values() == {"angle": 0.0, "omega": 0.0}
    assert [[(e.name, e.index) for e in line] for line in spec.further_destinations] == [
        [("angle", 0), ("omega", 20)],
        [("omega", 10)],
    ]
    text = render_controller_spec(spec)
    assert [line for line in text.splitlines() if line.startswith("dest")] == [
        "dest angle=0.0 omega=0.0",
        "dest angle=-180.0 omega=500.0",
        "dest omega=0.0",
    ]
    assert values(parse_controller_text(text)) == values(spec)


def test_pendulum_g_has_two_destinations():
    spec = parse_controller_spec(PENDULUM / "G.ssc")
    assert spec.all_destination_values() == [
        {"angle": 90.0, "omega": 0.0},
        {"angle": -90.0, "omega": 0.0},
    ]


def test_options_and_order_free_lines():
    text = (
        "tol 1e-4 # s\nmaxiter 50\ndt 0.0005\nknown_weight 0.75\n"
        "dest omega=-500\ntorq a 0 0 1 0\ntorq b -1 1 2 2.5\n"
        "ssd omega -500 500 3\ndyn car\n"
    )
    spec = parse_controller_text(text)
    assert (spec.tolerance, spec.max_iterations, spec.dt) == (1e-4, 50, 0.0005)
    assert spec.known_weight == 0.75
    assert parse_controller_text(text.replace("known_weight 0.75\n", "")).known_weight == 0.0
    assert spec.destination_values() == {"omega": -500.0}
    assert spec.controls[0].values() == (0.0,)
    assert spec.controls[1].values() == (-1.0, 1.0)
    assert spec.figure == "car"


def test_dest_within_grid_tolerance():
    spec = parse_controller_text(BASE.replace("omega=0", "omega=500.00000001"))
    assert spec.destination[1].index == 20
    with pytest.raises(SpecError) as error:
        parse_controller_text(BASE.replace("omega=0", "omega=0.0000001"))
    assert str(error.value) == (
        "<text>:5:20: expected a grid node of ssd omega (-500 + k * 50) for dest omega, "
        "found '0.0000001'"
    )


def test_ordered_state_rejects_names_the_figure_lacks():
    spec = parse_controller_text(BASE, "x.ssc")
    with pytest.raises(SpecError) as error:
        spec.ordered_state(("theta", "omega"))
    assert str(error.value) == (
        "x.ssc:3:5: expected a state variable of figure 'link1' (one of 'theta', 'omega'), "
        "found 'angle'"
    )
    assert str(spec.error(spec.controls[0].token, "a control of figure 'link1'")) == (
        "x.ssc:4:6: expected a control of figure 'link1', found 'torque'"
    )


# --- errors: the whole message --------------------------------------------------------------


replace_line = SpecLines(BASE).replace
drop_line = SpecLines(BASE).drop


ERRORS = [
    (
        replace_line(2, "ssd omega -500.0 fivehundred 21"),
        "x.ssc:2:18: expected a number for max, found 'fivehundred'",
    ),
    (
        replace_line(2, "ssdd omega -500.0 500.0 21"),
        "x.ssc:2:1: expected one of 'dyn', 'ssd', 'wrap', 'torq', 'dest', 'tol', 'maxiter', "
        "'dt', 'known_weight', 'obstacle', 'domain', 'hold', 'policy', found 'ssdd'",
    ),
    (
        replace_line(2, "ssd omega -500.0 500.0"),
        "x.ssc:2:23: expected a whole number for samples, found end of line",
    ),
    (
        replace_line(2, "ssd omega -500.0 500.0 21.0"),
        "x.ssc:2:24: expected a whole number for samples, found '21.0'",
    ),
    (
        replace_line(2, "ssd omega -500.0 500.0 1"),
        "x.ssc:2:24: expected a whole number >= 2 for samples, found '1'",
    ),
    (
        replace_line(2, "ssd omega 500 -500 21"),
        "x.ssc:2:15: expected a number > min (500) for max, found '-500'",
    ),
    (
        replace_line(2, "ssd omega -500 -500 21"),
        "x.ssc:2:16: expected a number > min (-500) for max, found '-500'",
    ),
    (
        replace_line(2, "ssd 2omega -500 500 21"),
        "x.ssc:2:5: expected a name for the state dimension, found '2omega'",
    ),
    (
        replace_line(2, "ssd"),
        "x.ssc:2:4: expected a name for the state dimension, found end of line",
    ),
    (
        replace_line(3, "ssd angle -180 170 36 wrapped"),
        "x.ssc:3:23: expected 'wrap' or end of line, found 'wrapped'",
    ),
    (
        replace_line(3, "ssd angle -180 170 36 wrap twice"),
        "x.ssc:3:28: expected end of line, found 'twice'",
    ),
    (
        SpecLines(BASE).insert(4, "wrap theta"),
        "x.ssc:4:6: expected the name of a state dimension an earlier ssd line declares "
        "('omega', 'angle'), found 'theta'",
    ),
    (
        SpecLines(BASE).insert(2, "wrap angle"),
        "x.ssc:2:6: expected the name of a state dimension an earlier ssd line declares "
        "(none yet), found 'angle'",
    ),
    (
        SpecLines(BASE).insert(4, "wrap"),
        "x.ssc:4:5: expected a name for the periodic state dimension, found end of line",
    ),
    (
        SpecLines(BASE).insert(4, "wrap angle omega"),
        "x.ssc:4:12: expected end of line, found 'omega'",
    ),
    (
        replace_line(3, "ssd omega -180 170 36 wrap"),
        "x.ssc:3:5: expected a name for the state dimension not used by another ssd or torq "
        "line (line 2), found 'omega'",
    ),
    (
        replace_line(4, "torq angle -10.0 10.0 11 0.1"),
        "x.ssc:4:6: expected a name for the control not used by another ssd or torq line "
        "(line 3), found 'angle'",
    ),
    (
        replace_line(4, "torq torque -10.0 10.0 0 0.1"),
        "x.ssc:4:24: expected a whole number >= 1 for samples, found '0'",
    ),
    (
        replace_line(4, "torq torque -10.0 10.0 1 0.1"),
        "x.ssc:4:24: expected samples >= 2 for a range from -10 to 10 "
        "(1 sample needs max equal to min), found '1'",
    ),
    (
        replace_line(4, "torq torque 10.0 -10.0 11 0.1"),
        "x.ssc:4:18: expected a number >= min (10) for max, found '-10.0'",
    ),
    (
        replace_line(4, "torq torque -10.0 10.0 11 -0.1"),
        "x.ssc:4:27: expected a number >= 0 for K, found '-0.1'",
    ),
    (
        replace_line(4, "torq torque -10.0 10.0 11"),
        "x.ssc:4:26: expected a number for K, found end of line",
    ),
    (
        replace_line(4, "torq torque -10.0 10.0 11 0.1 0.2"),
        "x.ssc:4:31: expected end of line, found '0.2'",
    ),
    (
        replace_line(5, "dest theta=0 omega=0"),
        "x.ssc:5:6: expected an ssd name (one of 'omega', 'angle') before '=', found 'theta'",
    ),
    (
        replace_line(5, "dest angle=5 omega=0"),
        "x.ssc:5:12: expected a grid node of ssd angle (-180 + k * 10) for dest angle, found '5'",
    ),
    (
        replace_line(5, "dest angle=0 omega=550"),
        "x.ssc:5:20: expected a value from -500 to 500 (ssd omega) for dest omega, found '550'",
    ),
    (
        replace_line(5, "dest angle=0 omega=zero"),
        "x.ssc:5:20: expected a number for dest omega, found 'zero'",
    ),
    (
        replace_line(5, "dest angle= omega=0"),
        "x.ssc:5:12: expected a number for dest angle, found ''",
    ),
    (
        replace_line(5, "dest angle=0 angle=10"),
        "x.ssc:5:14: expected 'angle=' only once, found 'angle=10'",
    ),
    (
        replace_line(5, "dest angle 0"),
        "x.ssc:5:6: expected a 'name=value' destination, found 'angle'",
    ),
    (
        replace_line(5, "dest   # nothing"),
        "x.ssc:5:5: expected a 'name=value' destination, found end of line",
    ),
    (
        BASE + "dest omega=0 angle=0\n",
        "x.ssc:6:1: expected a destination different from line 5's, found 'dest'",
    ),
    (  # the same node: 360 deg is 0 deg on the wrapped angle axis
        BASE + "dest angle=90\n  dest angle=360 omega=0\n",
        "x.ssc:7:3: expected a destination different from line 5's, found 'dest'",
    ),
    (  # each further line is checked as the first is
        BASE + "dest angle=5 omega=0\n",
        "x.ssc:6:12: expected a grid node of ssd angle (-180 + k * 10) for dest angle, found '5'",
    ),
    (
        BASE + "dest angle=90 omega=0\npolicy lookahead angle=1",
        "x.ssc:7:8: expected 'interpolate' with several dest lines (lines 5, 6): lookahead "
        "brakes to rest at one destination, found 'lookahead'",
    ),
    (
        replace_line(1, "dyn link1 link2"),
        "x.ssc:1:11: expected end of line, found 'link2'",
    ),
    (
        replace_line(1, "dyn"),
        "x.ssc:1:4: expected a name for the figure, found end of line",
    ),
    (drop_line(5), "x.ssc:5:1: expected a 'dest' line, found end of file"),
    (drop_line(4), "x.ssc:5:1: expected a 'torq' line, found end of file"),
    (drop_line(1), "x.ssc:5:1: expected a 'dyn' line, found end of file"),
    ("dyn link1\n\n\n# only comments\n", "x.ssc:2:1: expected a 'ssd' line, found end of file"),
    ("", "x.ssc:1:1: expected a 'dyn' line, found end of file"),
    (BASE + "tol 0", "x.ssc:6:5: expected a number > 0 for tol (s), found '0'"),
    (BASE + "dt -1e-3", "x.ssc:6:4: expected a number > 0 for dt (s), found '-1e-3'"),
    (BASE + "dt 1e-300", "x.ssc:6:4: expected a dt of at least 1e-05 s, found '1e-300'"),
    (BASE + "maxiter 0", "x.ssc:6:9: expected a whole number >= 1 for maxiter, found '0'"),
    (
        BASE + "known_weight 0",
        "x.ssc:6:14: expected a number > 0 for known_weight (a share of the weight), found '0'",
    ),
    (BASE + "known_weight 1.5", "x.ssc:6:14: expected a known_weight in (0, 1], found '1.5'"),
    (
        BASE + "known_weight 0.5\nknown_weight 0.5",
        "x.ssc:7:1: expected one 'known_weight' line only (the first is line 6), "
        "found 'known_weight'",
    ),
    (
        BASE + "maxiter 10\nmaxiter 20",
        "x.ssc:7:1: expected one 'maxiter' line only (the first is line 6), found 'maxiter'",
    ),
    (BASE + "tol", "x.ssc:6:4: expected a number for tol (s), found end of line"),
    (
        replace_line(2, "ssd omega -1e308 1e308 21"),
        "x.ssc:2:18: expected a max with a finite max - min, found '1e308'",
    ),
]


@pytest.mark.parametrize(("text", "message"), ERRORS)
def test_error_messages(text, message):
    with pytest.raises(SpecError) as error:
        parse_controller_text(text, "x.ssc")
    assert str(error.value) == message


def test_a_byte_order_mark_is_dropped(tmp_path):
    """Windows editors may save UTF-8 with a byte-order mark: the spec reads the same, and its
    digest is still that of its bytes."""
    plain, marked = tmp_path / "plain.ssc", tmp_path / "marked.ssc"
    text = (Path(__file__).resolve().parents[1] / "specs/controllers/pendulum/A.ssc").read_bytes()
    plain.write_bytes(text)
    marked.write_bytes(codecs.BOM_UTF8 + text)
    one, two = parse_controller_spec(plain), parse_controller_spec(marked)
    assert two.spec_sha256 == hashlib.sha256(codecs.BOM_UTF8 + text).hexdigest()
    assert dataclasses.replace(two, spec_sha256=one.spec_sha256, path=one.path) == one


def test_file_errors_and_path(tmp_path):
    missing = tmp_path / "missing.ssc"
    with pytest.raises(SpecError) as error:
        parse_controller_spec(missing)
    assert str(error.value) == f"{missing}:1:1: expected an existing spec file, found no such file"
    binary = tmp_path / "binary.ssc"
    binary.write_bytes(b"dyn link1\n\xff\n")
    with pytest.raises(SpecError) as error:
        parse_controller_spec(binary)
    assert str(error.value) == f"{binary}:1:1: expected UTF-8 text, found 'byte 10'"
    marked = tmp_path / "marked.ssc"  # a byte-order mark: dropped, and bytes still counted
    marked.write_bytes(codecs.BOM_UTF8 + b"dyn link1\n\xff\n")
    with pytest.raises(SpecError) as error:
        parse_controller_spec(marked)
    assert str(error.value) == f"{marked}:1:1: expected UTF-8 text, found 'byte 13'"
    bad = tmp_path / "bad.ssc"
    bad.write_text(replace_line(2, "ssd omega -500.0 fivehundred 21"))
    with pytest.raises(SpecError) as error:
        parse_controller_spec(bad)
    assert str(error.value) == f"{bad}:2:18: expected a number for max, found 'fivehundred'"


# --- hypothesis -----------------------------------------------------------------------------

PARK = (ROOT / "specs" / "controllers" / "car" / "park.ssc").read_text()
SPECS = [
    *((PENDULUM / f"{name}.ssc").read_text() for name in [*sorted(FIGURE_13), "G"]),
    PARK,
    PARK.replace("heading=4.9 aim=0.7", "heading=4.9 aim=0.7 arrival_value"),
]
WORDS = [
    *("dyn", "ssd", "torq", "dest", "tol", "maxiter", "dt", "wrap", "angle", "omega"),
    *("angle=0", "omega=50", "=", "=1", "#", ",", "1e999", "nan", "inf", "-0", "0", "1", "2"),
    *("policy", "lookahead", "interpolate", "aim=0.5", "arrival_value", "x=0.1", "hold"),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
)


def sound_and_round_trips(spec: ControllerSpec) -> None:
    """What a spec the parser accepts satisfies, and it reads back from its rendering."""
    assert spec.state and spec.controls and spec.destination
    assert values(parse_controller_text(render_controller_spec(spec))) == values(spec)


FAST = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST
@given(st.text())
def test_any_text_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_controller_text, text, "fuzz.ssc", sound_and_round_trips)


@FAST
@given(st.lists(st.lists(garbage, max_size=7).map(" ".join), max_size=8).map("\n".join))
def test_keyword_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_controller_text, text, "fuzz.ssc", sound_and_round_trips)


mutated_specs = token_mutations(st.sampled_from(SPECS), garbage)


@FAST
@given(mutated_specs)
def test_mutated_specs_parse_or_raise_spec_error(text):
    parses_or_spec_error(parse_controller_text, text, "fuzz.ssc", sound_and_round_trips)


NAMES = st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True).filter(
    lambda name: name not in {"wrap"}
)
STEPS = st.sampled_from([0.1, 0.25, 0.5, 1.0, 2.5, 10.0, 50.0])


@st.composite
def controller_specs(draw) -> ControllerSpec:
    token = Token("x", 1, 1)
    names = draw(st.lists(NAMES, min_size=2, max_size=5, unique=True))
    n_state = draw(st.integers(1, len(names) - 1))
    state = []
    for name in names[:n_state]:
        minimum = draw(st.integers(-400, 400)) * draw(STEPS)
        samples = draw(st.integers(2, 40))
        maximum = minimum + draw(STEPS) * (samples - 1)
        state.append(StateDimension(name, minimum, maximum, samples, draw(st.booleans()), token))
    controls = []
    for name in names[n_state:]:
        samples = draw(st.integers(1, 12))
        minimum = draw(st.integers(-100, 100)) * 0.5
        maximum = minimum if samples == 1 else minimum + draw(st.integers(0, 100)) * 0.25
        weight = draw(st.sampled_from([0.0, 0.1, 1.0, 2.5]))
        controls.append(ControlDimension(name, minimum, maximum, samples, weight, token))
    destinations = []
    for _ in range(draw(st.integers(1, 3))):
        chosen = draw(st.lists(st.sampled_from(state), min_size=1, unique_by=lambda d: d.name))
        destination = []
        for dimension in chosen:
            index = draw(st.integers(0, dimension.samples - 1))
            value = dimension.node(index)
            if dimension.wrap:
                value += draw(st.integers(-2, 2)) * dimension.period
            destination.append(Destination(dimension.name, value, index, token))
        nodes = {(entry.name, entry.index) for entry in destination}
        if all(nodes != {(e.name, e.index) for e in other} for other in destinations):
            destinations.append(tuple(destination))  # a repeated destination is an error
    return ControllerSpec(
        path="generated.ssc",
        figure=draw(NAMES),
        figure_token=token,
        state=tuple(state),
        controls=tuple(controls),
        destination=destinations[0],
        further_destinations=tuple(destinations[1:]),
        tolerance=draw(st.sampled_from([DEFAULT_TOLERANCE, 1e-3, 2.5e-8])),
        max_iterations=draw(st.sampled_from([DEFAULT_MAX_ITERATIONS, 1, 20])),
        dt=draw(st.sampled_from([DEFAULT_DT, 0.01, 1e-4])),
        known_weight=draw(st.sampled_from([0.0, 0.5, 1.0])),
        spec_sha256="",
    )


@FAST
@given(controller_specs())
def test_render_then_parse_round_trips(spec):
    text = render_controller_spec(spec)
    parsed = parse_controller_text(text, "generated.ssc")
    assert values(parsed) == values(spec)
    assert parsed.spec_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert render_controller_spec(parsed) == text
