"""The .mot grammar: Luxo's hop, binding to a figure, whole-message errors, hypothesis fuzzing."""

from __future__ import annotations

import hashlib
import math
import string

import numpy as np
import pytest
from conftest import SpecLines, parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations
from test_keyframes import KEY_ERRORS

from mosys.parsing.motor import (
    LIMP,
    SERVO,
    TORQUE,
    MotorProgram,
    Phase,
    Setting,
    bind_motor_program,
    parse_motor_program,
    parse_motor_program_text,
    render_motor_program,
)
from mosys.parsing.tokens import SpecError, Token

HOP = """\
# hop: a short hop forward
figure luxo                               # the figure this program drives
limit hip_torque=5 elbow_torque=5         # |torque| cap per actuator, N m
gains kp=6 kd=0.25                        # default servo gains
phase 0.35 hip=10 elbow=150               # servo 'hip' towards 10 deg, 'elbow' towards 150
phase 0.12 hip=-30 elbow=40 kp=40 kd=0.3  # gains for this phase only
phase 0.30 hip_torque=-2 elbow_torque=1.5 # constant torques, N m
phase 0.2 hip=0 elbow_torque=0.5          # mixed: hip servoed, elbow a constant torque
"""
LUXO_COORDINATES = ("x", "y", "base", "hip", "elbow")
LUXO_ACTUATORS = ("", "", "", "hip_torque", "elbow_torque")


def values(program: MotorProgram) -> tuple:
    """Everything a program says, without tokens, path and hash."""
    return (
        program.figure,
        tuple((limit.name, limit.value) for limit in program.limits),
        program.kp,
        program.kd,
        tuple(
            (
                phase.seconds,
                tuple((setting.name, setting.value) for setting in phase.settings),
                phase.kp,
                phase.kd,
            )
            for phase in program.phases
        ),
    )


replace_line = SpecLines(HOP).replace
drop_line = SpecLines(HOP).drop


def test_hop():
    program = parse_motor_program_text(HOP, "hop.mot")
    assert values(program) == (
        "luxo",
        (("hip_torque", 5.0), ("elbow_torque", 5.0)),
        6.0,
        0.25,
        (
            (0.35, (("hip", 10.0), ("elbow", 150.0)), None, None),
            (0.12, (("hip", -30.0), ("elbow", 40.0)), 40.0, 0.3),
            (0.30, (("hip_torque", -2.0), ("elbow_torque", 1.5)), None, None),
            (0.2, (("hip", 0.0), ("elbow_torque", 0.5)), None, None),
        ),
    )
    assert program.path == "hop.mot"
    assert program.name == "hop"
    assert program.duration() == pytest.approx(0.97)
    assert program.spec_sha256 == hashlib.sha256(HOP.encode()).hexdigest()
    assert program.figure_token == Token("luxo", 2, 8)
    assert program.limits[1].token == Token("elbow_torque=5", 3, 20)
    assert program.limits[1].name_token == Token("elbow_torque", 3, 20)
    assert program.limits[1].value_token == Token("5", 3, 33)
    second = program.phases[1]
    assert second.token == Token("phase", 6, 1)
    assert second.seconds_token == Token("0.12", 6, 7)
    assert second.settings[0].token == Token("hip=-30", 6, 12)
    assert second.settings[0].value_token == Token("-30", 6, 16)


def test_defaults_and_a_limp_phase():
    program = parse_motor_program_text("figure luxo\nphase 1\nphase 2 hip_torque=1e-1\n")
    assert values(program) == (
        "luxo",
        (),
        0.0,
        0.0,
        ((1.0, (), None, None), (2.0, (("hip_torque", 0.1),), None, None)),
    )
    assert program.duration() == 3.0
    assert render_motor_program(program) == "figure luxo\nphase 1.0\nphase 2.0 hip_torque=0.1\n"


def test_file(tmp_path):
    path = tmp_path / "hop.mot"
    path.write_text(HOP)
    program = parse_motor_program(path)
    assert (program.path, program.name) == (str(path), "hop")
    assert program.spec_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    missing = tmp_path / "missing.mot"
    with pytest.raises(SpecError) as error:
        parse_motor_program(missing)
    assert str(error.value) == f"{missing}:1:1: expected an existing spec file, found no such file"
    path.write_text(HOP.replace("phase 0.2", "phase 0"))
    with pytest.raises(SpecError) as error:
        parse_motor_program(path)
    assert str(error.value) == f"{path}:8:7: expected a number > 0 for seconds, found '0'"


def test_render_hop():
    program = parse_motor_program_text(HOP)
    text = render_motor_program(program)
    assert text == (
        "figure luxo\n"
        "limit hip_torque=5.0 elbow_torque=5.0\n"
        "gains kp=6.0 kd=0.25\n"
        "phase 0.35 hip=10.0 elbow=150.0\n"
        "phase 0.12 hip=-30.0 elbow=40.0 kp=40.0 kd=0.3\n"
        "phase 0.3 hip_torque=-2.0 elbow_torque=1.5\n"
        "phase 0.2 hip=0.0 elbow_torque=0.5\n"
    )
    assert values(parse_motor_program_text(text)) == values(program)


# --- binding to a figure --------------------------------------------------------------------


def test_bind_hop_to_luxo():
    program = parse_motor_program_text(HOP)
    bound = bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    assert bound.actuator_names == ("hip_torque", "elbow_torque")
    assert bound.coordinate.dtype == np.int64 and bound.mode.dtype == np.int64
    np.testing.assert_array_equal(bound.coordinate, [3, 4])
    np.testing.assert_array_equal(bound.durations, [0.35, 0.12, 0.30, 0.2])
    assert bound.durations.sum() == pytest.approx(program.duration())
    np.testing.assert_array_equal(
        bound.mode, [[SERVO, SERVO], [SERVO, SERVO], [TORQUE, TORQUE], [SERVO, TORQUE]]
    )
    np.testing.assert_allclose(
        bound.value,
        [
            [math.radians(10), math.radians(150)],
            [math.radians(-30), math.radians(40)],
            [-2.0, 1.5],
            [0.0, 0.5],
        ],
    )
    np.testing.assert_array_equal(bound.kp, [[6, 6], [40, 40], [6, 6], [6, 6]])
    np.testing.assert_array_equal(bound.kd, [[0.25, 0.25], [0.3, 0.3], [0.25, 0.25], [0.25, 0.25]])
    np.testing.assert_array_equal(bound.limit, [5.0, 5.0])
    for array in (bound.durations, bound.value, bound.kp, bound.kd, bound.limit):
        assert array.dtype == np.float64


def test_bind_limp_actuators_uncapped_limits_and_phase_gains():
    program = parse_motor_program_text(
        "figure luxo\nlimit elbow_torque=2\nphase 0.5\nphase 0.25 kd=1 elbow=-90\n"
    )
    bound = bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    np.testing.assert_array_equal(bound.mode, [[LIMP, LIMP], [LIMP, SERVO]])
    np.testing.assert_array_equal(bound.value, [[0, 0], [0, -math.pi / 2]])
    np.testing.assert_array_equal(bound.kp, [[0, 0], [0, 0]])
    np.testing.assert_array_equal(bound.kd, [[0, 0], [1, 1]])
    np.testing.assert_array_equal(bound.limit, [np.inf, 2.0])


def test_bind_argument_lengths():
    program = parse_motor_program_text(HOP)
    with pytest.raises(ValueError) as error:
        bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS[1:])
    assert str(error.value) == "5 coordinate names but 4 actuator names"


BIND_ERRORS = [
    (
        HOP.replace("hip=10 ", "knee=10 "),
        "x.mot:5:12: expected a joint angle or an actuator of figure 'luxo' "
        "(one of: 'hip', 'elbow', 'hip_torque', 'elbow_torque'), or a phase's gain kp= or "
        "kd=, found 'knee'",
    ),
    (
        HOP.replace("hip=10 ", "base=10 "),
        "x.mot:5:12: expected an actuated joint angle or an actuator of figure 'luxo' "
        "(coordinate 'base' has no actuator; one of: 'hip', 'elbow', 'hip_torque', "
        "'elbow_torque'), found 'base'",
    ),
    (
        HOP.replace("elbow_torque=0.5", "hip_torque=0.5"),
        "x.mot:8:17: expected one setting per actuator ('hip=0' at column 11 already drives "
        "'hip_torque' in this phase), found 'hip_torque'",
    ),
    (
        HOP.replace("elbow_torque=1.5", "hip=1.5"),
        "x.mot:7:26: expected one setting per actuator ('hip_torque=-2' at column 12 already "
        "drives 'hip_torque' in this phase), found 'hip'",
    ),
    (
        HOP.replace("limit hip_torque=5", "limit hip=5"),
        "x.mot:3:7: expected an actuator of figure 'luxo' (one of: 'hip_torque', "
        "'elbow_torque'), found 'hip'",
    ),
    (
        drop_line(4),
        "x.mot:4:12: expected servo gains kp > 0 or kd > 0 to servo 'hip' "
        "(set 'gains' or kp= on the phase), found 'hip=10'",
    ),
    (
        HOP.replace("kp=40 kd=0.3", "kp=0 kd=0"),
        "x.mot:6:12: expected servo gains kp > 0 or kd > 0 to servo 'hip' "
        "(set 'gains' or kp= on the phase), found 'hip=-30'",
    ),
]


@pytest.mark.parametrize(("text", "message"), BIND_ERRORS)
def test_bind_error_messages(text, message):
    program = parse_motor_program_text(text, "x.mot")
    with pytest.raises(SpecError) as error:
        bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    assert str(error.value) == message


def test_bind_to_a_figure_without_actuators():
    program = parse_motor_program_text("figure link\nphase 1 angle=0 kp=1\n", "x.mot")
    with pytest.raises(SpecError) as error:
        bind_motor_program(program, ("angle",), ("",))
    assert str(error.value) == (
        "x.mot:2:9: expected an actuated joint angle or an actuator of figure 'link' "
        "(coordinate 'angle' has no actuator; the figure has none), found 'angle'"
    )
    assert bind_motor_program(program, ("angle",), ("torque",)).mode.tolist() == [[SERVO]]


# --- errors: the whole message --------------------------------------------------------------


ERRORS = [
    ("", "x.mot:1:1: expected a 'figure' line, found end of file"),
    ("# nothing\n\n", "x.mot:1:1: expected a 'figure' line, found end of file"),
    (
        "figure luxo\ngains kp=1\n",
        "x.mot:3:1: expected a 'phase' or 'key' line, found end of file",
    ),
    ("limit a=1\n", "x.mot:2:1: expected a 'figure' line, found end of file"),
    (
        "phase 1\nfigure luxo\n",
        "x.mot:1:1: expected a 'figure' line before the first 'phase', found 'phase'",
    ),
    (
        replace_line(5, "stage 0.35 hip=10"),
        "x.mot:5:1: expected one of 'figure', 'limit', 'gains', 'phase', 'key', found 'stage'",
    ),
    (replace_line(2, "figure"), "x.mot:2:7: expected a name for the figure, found end of line"),
    (replace_line(2, "figure 2luxo"), "x.mot:2:8: expected a name for the figure, found '2luxo'"),
    (replace_line(2, "figure luxo lamp"), "x.mot:2:13: expected end of line, found 'lamp'"),
    (
        HOP + "figure luxo\n",
        "x.mot:9:1: expected one 'figure' line only (the first is line 2), found 'figure'",
    ),
    (
        HOP + "limit hip_torque=1\n",
        "x.mot:9:1: expected one 'limit' line only (the first is line 3), found 'limit'",
    ),
    (
        drop_line(4) + "gains kp=6\n",
        "x.mot:8:1: expected a 'phase' line ('gains' goes before the first 'phase', line 4), "
        "found 'gains'",
    ),
    (
        replace_line(3, "limit"),
        "x.mot:3:6: expected a torque limit 'actuator=value' (N m), found end of line",
    ),
    (
        replace_line(3, "limit hip_torque 5"),
        "x.mot:3:7: expected a torque limit 'actuator=value' (N m), found 'hip_torque'",
    ),
    (replace_line(3, "limit =5"), "x.mot:3:7: expected a name before '=', found ''"),
    (
        replace_line(3, "limit hip_torque=0"),
        "x.mot:3:18: expected a number > 0 for limit hip_torque, found '0'",
    ),
    (
        replace_line(3, "limit hip_torque=-5"),
        "x.mot:3:18: expected a number > 0 for limit hip_torque, found '-5'",
    ),
    (
        replace_line(3, "limit hip_torque="),
        "x.mot:3:18: expected a number for limit hip_torque, found ''",
    ),
    (
        replace_line(3, "limit hip_torque=inf"),
        "x.mot:3:18: expected a number for limit hip_torque, found 'inf'",
    ),
    (
        replace_line(3, "limit hip_torque=1e999"),
        "x.mot:3:18: expected a finite number for limit hip_torque, found '1e999'",
    ),
    (
        replace_line(3, "limit hip_torque=5 hip_torque=6"),
        "x.mot:3:20: expected 'hip_torque=' only once, found 'hip_torque=6'",
    ),
    (replace_line(4, "gains"), "x.mot:4:6: expected one of 'kp=', 'kd=', found end of line"),
    (replace_line(4, "gains ki=1"), "x.mot:4:7: expected one of 'kp=', 'kd=', found 'ki=1'"),
    (replace_line(4, "gains 6"), "x.mot:4:7: expected one of 'kp=', 'kd=', found '6'"),
    (replace_line(4, "gains kp=-6"), "x.mot:4:10: expected a number >= 0 for kp, found '-6'"),
    (replace_line(4, "gains kd=nan"), "x.mot:4:10: expected a number for kd, found 'nan'"),
    (replace_line(4, "gains kp=1 kp=2"), "x.mot:4:12: expected 'kp=' only once, found 'kp=2'"),
    (replace_line(5, "phase"), "x.mot:5:6: expected a number for seconds, found end of line"),
    (replace_line(5, "phase hip=10"), "x.mot:5:7: expected a number for seconds, found 'hip=10'"),
    (replace_line(5, "phase 0 hip=10"), "x.mot:5:7: expected a number > 0 for seconds, found '0'"),
    (
        replace_line(5, "phase -0.35 hip=10"),
        "x.mot:5:7: expected a number > 0 for seconds, found '-0.35'",
    ),
    (
        replace_line(5, "phase 1e308") + "phase 1e308\n",
        "x.mot:9:7: expected seconds with a finite total duration, found '1e308'",
    ),
    (
        replace_line(5, "phase 0.35 hip 10"),
        "x.mot:5:12: expected a setting 'name=value' (joint=degrees, actuator=N m, kp= or kd=), "
        "found 'hip'",
    ),
    (replace_line(5, "phase 0.35 hip=ten"), "x.mot:5:16: expected a number for hip, found 'ten'"),
    (replace_line(5, "phase 0.35 hip="), "x.mot:5:16: expected a number for hip, found ''"),
    (replace_line(5, "phase 0.35 hip==1"), "x.mot:5:16: expected a number for hip, found '=1'"),
    (replace_line(5, "phase 0.35 hip=-inf"), "x.mot:5:16: expected a number for hip, found '-inf'"),
    (replace_line(5, "phase 0.35 h.p=1"), "x.mot:5:12: expected a name before '=', found 'h.p'"),
    (
        replace_line(5, "phase 0.35 hip=10 elbow=1 hip=20"),
        "x.mot:5:27: expected 'hip=' only once, found 'hip=20'",
    ),
    (
        replace_line(5, "phase 0.35 kp=1 hip=10 kp=2"),
        "x.mot:5:24: expected 'kp=' only once, found 'kp=2'",
    ),
    (
        replace_line(5, "phase 0.35 hip=10 kd=-1"),
        "x.mot:5:22: expected a number >= 0 for kd, found '-1'",
    ),
]


@pytest.mark.parametrize(("text", "message"), ERRORS + KEY_ERRORS)
def test_error_messages(text, message):
    with pytest.raises(SpecError) as error:
        parse_motor_program_text(text, "x.mot")
    assert str(error.value) == message


def test_error_helper_points_at_tokens():
    program = parse_motor_program_text(HOP, "x.mot")
    assert str(program.error(program.figure_token, "a figure in specs/figures")) == (
        "x.mot:2:8: expected a figure in specs/figures, found 'luxo'"
    )


# --- hypothesis -----------------------------------------------------------------------------

WORDS = [
    *("figure", "limit", "gains", "phase", "luxo", "hip", "elbow", "hip_torque", "kp", "kd"),
    *("hip=10", "hip_torque=-2", "kp=6", "kd=0", "kp=", "=", "=1", "hip==1", "#", "0", "0.35"),
    *("-1", "1e999", "nan", "inf", "hip=nan"),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.tuples(st.sampled_from(["hip", "kp", "kd", "x"]), st.floats()).map(
        lambda pair: f"{pair[0]}={pair[1]!r}"
    ),
)
FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def sound_and_round_trips(program: MotorProgram) -> None:
    """What a program the parser accepts satisfies, and it reads back from its rendering."""
    assert (program.phases or len(program.keys) >= 2) and math.isfinite(program.duration())
    assert values(parse_motor_program_text(render_motor_program(program))) == values(program)


@FAST
@given(st.text())
def test_any_text_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_motor_program_text, text, "fuzz.mot", sound_and_round_trips)


@FAST
@given(st.lists(st.lists(garbage, max_size=6).map(" ".join), max_size=8).map("\n".join))
def test_keyword_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_motor_program_text, text, "fuzz.mot", sound_and_round_trips)


@FAST
@given(token_mutations(st.just(HOP), garbage))
def test_mutated_programs_parse_or_raise_spec_error(text):
    parses_or_spec_error(parse_motor_program_text, text, "fuzz.mot", sound_and_round_trips)


IDENTIFIERS = st.tuples(
    st.sampled_from(string.ascii_letters + "_"),
    st.text(string.ascii_letters + string.digits + "_", max_size=6),
).map("".join)
NAMES = st.sampled_from(LUXO_COORDINATES + LUXO_ACTUATORS[3:]) | IDENTIFIERS
SETTING_NAMES = NAMES.filter(lambda name: name not in {"kp", "kd"})
NUMBERS = st.floats(allow_nan=False, allow_infinity=False)
GAIN_VALUES = st.floats(min_value=0, max_value=1e6)
POSITIVE = st.floats(min_value=1e-9, max_value=1e6)


@st.composite
def motor_programs(draw) -> MotorProgram:
    token = Token("x", 1, 1)
    limit_names = draw(st.lists(NAMES, max_size=4, unique=True))
    limits = tuple(Setting(name, draw(POSITIVE), token) for name in limit_names)
    phases = []
    for _ in range(draw(st.integers(1, 5))):
        names = draw(st.lists(SETTING_NAMES, max_size=4, unique=True))
        phases.append(
            Phase(
                seconds=draw(POSITIVE),
                settings=tuple(Setting(name, draw(NUMBERS), token) for name in names),
                kp=draw(st.none() | GAIN_VALUES),
                kd=draw(st.none() | GAIN_VALUES),
                token=token,
                seconds_token=token,
            )
        )
    return MotorProgram(
        path="generated.mot",
        figure=draw(NAMES),
        figure_token=token,
        limits=limits,
        kp=draw(st.just(0.0) | GAIN_VALUES),
        kd=draw(st.just(0.0) | GAIN_VALUES),
        phases=tuple(phases),
        spec_sha256="",
    )


@FAST
@given(motor_programs())
def test_render_then_parse_round_trips(program):
    text = render_motor_program(program)
    parsed = parse_motor_program_text(text, "generated.mot")
    assert values(parsed) == values(program)
    assert parsed.spec_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert render_motor_program(parsed) == text


@settings(FAST, max_examples=100)
@given(motor_programs())
def test_bind_never_raises_anything_but_spec_error(program):
    try:
        bound = bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    except SpecError as error:
        # every token of a generated program stands at 1:1
        assert str(error) == f"generated.mot:1:1: expected {error.expected}, found {error.found!r}"
    else:
        assert bound.mode.shape == bound.value.shape == (len(program.phases), 2)
