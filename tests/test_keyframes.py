"""Keyframed motor programs (``key`` lines of a ``.mot``) and the motor kernel's slew limit.

The interpolant (``keyframe_curve``) with hypothesis; the grammar's errors, whole messages; the
shipped pendulum swing (specs/motor/link1/swing.mot) tracking its keyframes on the real
dynamics; the slew limit (paper §5) on real runs; and phase programs run by the one per-step
kernel agreeing bit for bit with an independent re-implementation of the phase servo."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from conftest import SpecLines, parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations

from mosys.animation.motor_program import (
    BoundMotorProgram,
    keyframe_curve,
    load_motor_program,
)
from mosys.animation.runner import ScriptSources, load_programs, run_script
from mosys.dynamics.compile import compile_figure
from mosys.dynamics.load import load_dynamics
from mosys.kernels.motor import run_motor_program
from mosys.parsing.motor import (
    LIMP,
    SERVO,
    TORQUE,
    Key,
    MotorProgram,
    Setting,
    bind_motor_program,
    parse_motor_program,
    parse_motor_program_text,
    render_motor_program,
)
from mosys.parsing.script import parse_script_text
from mosys.parsing.tokens import SpecError, Token

SPECS = Path(__file__).resolve().parents[1] / "specs"
SWING = SPECS / "motor" / "link1" / "swing.mot"
HANGING = np.array([-math.pi / 2, 0.0])  # link1 at rest, hanging straight down
LUXO_COORDINATES = ("x", "y", "base", "hip", "elbow")
LUXO_ACTUATORS = ("", "", "", "hip_torque", "elbow_torque")
FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@pytest.fixture(scope="module")
def luxo(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """Luxo's dynamics, compiled from specs/figures/luxo.fig."""
    path = tmp_path_factory.mktemp("dynamics") / "luxo.py"
    compile_figure(SPECS / "figures" / "luxo.fig", path)
    return load_dynamics(path)


def luxo_standing() -> np.ndarray:
    """Luxo standing: base flat at x = 0, hip 0, elbow 120 deg, at rest."""
    state = np.zeros(10)
    state[4] = math.radians(120.0)
    return state


# --- the interpolant ------------------------------------------------------------------------


@st.composite
def keyframes(draw, min_gap: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Key times (K,) from 0, strictly increasing by at least ``min_gap`` s, and values (K,)."""
    gaps = draw(st.lists(st.floats(min_gap, 3.0), min_size=1, max_size=7))
    times = np.concatenate([[0.0], np.cumsum(gaps)])
    values = draw(
        st.lists(st.floats(-360.0, 360.0), min_size=len(times), max_size=len(times)).map(np.array)
    )
    return times, values


def tangents(times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The documented key tangents: Catmull-Rom inside, 0 at the ends."""
    m = np.zeros_like(values)
    m[1:-1] = (values[2:] - values[:-2]) / (times[2:] - times[:-2])
    return m


@FAST
@given(keyframes())
def test_the_curve_passes_exactly_through_every_key_at_the_key_tangents(keys):
    times, values = keys
    target, rate = keyframe_curve(times, values, times)
    np.testing.assert_array_equal(target, values)
    np.testing.assert_array_equal(rate, tangents(times, values))
    assert rate[0] == 0 and rate[-1] == 0  # starts and ends at rest


@FAST
@given(keyframes(), st.floats(0.05, 0.95))
def test_the_rate_is_the_derivative_of_the_target(keys, fraction):
    """Central finite differences inside every interval, where the curve is one cubic: the
    error is at most eps² |p'''| / 6 plus rounding."""
    times, values = keys
    h = np.diff(times)
    t = times[:-1] + fraction * h
    eps = 1e-5 * h
    m = tangents(times, values)
    third = (12 * np.abs(np.diff(values)) + 6 * h * (np.abs(m[:-1]) + np.abs(m[1:]))) / h**3
    _, rate = keyframe_curve(times, values, t)
    ahead, _ = keyframe_curve(times, values, t + eps)
    behind, _ = keyframe_curve(times, values, t - eps)
    difference = (ahead - behind) / (2 * eps)
    rounding = 1e-14 * (np.abs(values).max() + 1) / eps
    assert (np.abs(difference - rate) <= eps**2 * third + rounding).all()


@FAST
@given(keyframes(), st.floats(1e-9, 1e-6))
def test_the_rate_is_continuous_at_the_keys(keys, fraction):
    """C1: just before and just after each key, the rate is within delta·max|p''| of the key's
    tangent (|p''| <= 6 |rise| / h² + 4 (|m_k| + |m_k+1|) / h on an interval)."""
    times, values = keys
    h = np.diff(times)
    m = tangents(times, values)
    second = (6 * np.abs(np.diff(values)) / h**2 + 4 * (np.abs(m[:-1]) + np.abs(m[1:])) / h).max()
    delta = fraction * h.min()
    _, at = keyframe_curve(times, values, times)
    for shifted in (times - delta, times + delta):
        _, rate = keyframe_curve(times, values, shifted)
        assert (np.abs(rate - at) <= delta * second * (1 + 1e-9) + 1e-9).all()


@FAST
@given(keyframes(), st.floats(-1000.0, 1000.0), st.lists(st.floats(-5.0, 20.0), max_size=20))
def test_constant_keys_give_a_constant_target_at_rate_zero(keys, value, t):
    times, _ = keys
    target, rate = keyframe_curve(times, np.full(len(times), value), np.array(t))
    np.testing.assert_array_equal(target, np.full(len(t), value))
    np.testing.assert_array_equal(rate, np.zeros(len(t)))


@FAST
@given(keyframes(), keyframes(), st.floats(0.0, 1.0))
def test_columns_are_interpolated_independently_and_the_ends_are_held(one, two, fraction):
    times, first = one
    second = np.resize(two[1], len(times))
    t = np.array([-1.0, fraction * times[-1], times[-1], times[-1] + 1.0])
    target, rate = keyframe_curve(times, np.column_stack([first, second]), t)
    assert target.shape == rate.shape == (4, 2)
    for column, values in enumerate((first, second)):
        alone, alone_rate = keyframe_curve(times, values, t)
        np.testing.assert_array_equal(target[:, column], alone)
        np.testing.assert_array_equal(rate[:, column], alone_rate)
        assert (alone[0], alone[-1], alone_rate[0], alone_rate[-1]) == (
            values[0],
            values[-1],
            0,
            0,
        )
    scalar, scalar_rate = keyframe_curve(times, first, 0.5 * times[-1])
    assert scalar.shape == scalar_rate.shape == ()


def test_a_worked_example():
    """Keys 0 -> 1 -> 0 at t = 0, 1, 2: m_1 = 0, so each half is 3s² - 2s³ (smoothstep)."""
    target, rate = keyframe_curve([0.0, 1.0, 2.0], [0.0, 1.0, 0.0], [0.25, 0.5, 1.5])
    np.testing.assert_allclose(target, [0.15625, 0.5, 0.5], rtol=0, atol=1e-15)
    np.testing.assert_allclose(rate, [1.125, 1.5, -1.5], rtol=0, atol=1e-15)


# --- the grammar ----------------------------------------------------------------------------

SWING_TEXT = """\
figure link1
limit torque=10
gains kp=200 kd=15
key 0 angle=-90
key 0.6 angle=-30
key 1.4 angle=-150
key 2.0 angle=-90
"""
LUXO_KEYS = "figure luxo\ngains kp=6\nkey 0 hip=0 elbow=120\nkey 1 hip=10 elbow=100\n"
replace_line = SpecLines(SWING_TEXT).replace
drop_line = SpecLines(SWING_TEXT).drop


def key_values(program: MotorProgram) -> tuple:
    """What a keyframed program says, without tokens, path and hash."""
    return (
        program.figure,
        tuple((limit.name, limit.value) for limit in program.limits),
        program.kp,
        program.kd,
        tuple(
            (key.time, tuple((setting.name, setting.value) for setting in key.settings))
            for key in program.keys
        ),
    )


def test_swing_text():
    program = parse_motor_program_text(SWING_TEXT, "swing.mot")
    assert key_values(program) == (
        "link1",
        (("torque", 10.0),),
        200.0,
        15.0,
        (
            (0.0, (("angle", -90.0),)),
            (0.6, (("angle", -30.0),)),
            (1.4, (("angle", -150.0),)),
            (2.0, (("angle", -90.0),)),
        ),
    )
    assert program.keyframed and program.phases == ()
    assert program.duration() == 2.0
    assert program.keys[1].token == Token("key", 5, 1)
    assert program.keys[1].time_token == Token("0.6", 5, 5)
    assert program.keys[1].settings[0].value_token == Token("-30", 5, 15)
    assert render_motor_program(program) == (
        "figure link1\nlimit torque=10.0\ngains kp=200.0 kd=15.0\nkey 0.0 angle=-90.0\n"
        "key 0.6 angle=-30.0\nkey 1.4 angle=-150.0\nkey 2.0 angle=-90.0\n"
    )
    assert not parse_motor_program(SPECS / "motor" / "luxo" / "hop.mot").keyframed


def test_the_shipped_swing_parses():
    program = parse_motor_program(SWING)
    assert program.keyframed and program.figure == "link1"
    assert [key.time for key in program.keys] == [0.0, 0.6, 1.4, 2.0, 2.5]
    assert [key.settings[0].value for key in program.keys] == [-90, -30, -150, -90, -90]


# the keyframe grammar's errors: checked with the phase grammar's by test_motor_parser.py
KEY_ERRORS = [
    (
        replace_line(6, "key 0.5 angle=-150"),
        "x.mot:6:5: expected a time after 0.6 s, the previous key's (line 5; keyframes out of "
        "order), found '0.5'",
    ),
    (
        replace_line(6, "key 0.6 angle=-150"),
        "x.mot:6:5: expected a time after 0.6 s, the previous key's (line 5; keyframes out of "
        "order), found '0.6'",
    ),
    (
        replace_line(6, "key 6e-1 angle=-150"),
        "x.mot:6:5: expected a time after 0.6 s, the previous key's (line 5; keyframes out of "
        "order), found '6e-1'",
    ),
    (
        "figure link1\ngains kp=1\nkey 0 angle=-90\n",
        "x.mot:4:1: expected a second 'key' line (a keyframed program needs 2 or more; the first "
        "is line 3), found end of file",
    ),
    (
        "figure link1\ngains kp=1\nkey 0 angle=-90\n# only one\n\n",  # just past the last key
        "x.mot:4:1: expected a second 'key' line (a keyframed program needs 2 or more; the first "
        "is line 3), found end of file",
    ),
    (
        SWING_TEXT + "phase 1 angle=0\n",
        "x.mot:8:1: expected a 'key' line (a program has 'phase' lines or 'key' lines, not both; "
        "the first 'key' is line 4), found 'phase'",
    ),
    (
        "figure link1\ngains kp=1\nphase 1 angle=0\nkey 0 angle=1\n",
        "x.mot:4:1: expected a 'phase' line (a program has 'phase' lines or 'key' lines, not "
        "both; the first 'phase' is line 3), found 'key'",
    ),
    (
        replace_line(4, "key -1 angle=-90"),
        "x.mot:4:5: expected a number >= 0 for the key time, found '-1'",
    ),
    (
        replace_line(6, "key -1.4 angle=-150"),
        "x.mot:6:5: expected a number >= 0 for the key time, found '-1.4'",
    ),
    (
        replace_line(4, "key 0.1 angle=-90"),
        "x.mot:4:5: expected 0 for the first key's time (a keyframed program starts at its first "
        "key), found '0.1'",
    ),
    (
        replace_line(6, "key nan angle=-150"),
        "x.mot:6:5: expected a number for the key time, found 'nan'",
    ),
    (
        replace_line(6, "key inf angle=-150"),
        "x.mot:6:5: expected a number for the key time, found 'inf'",
    ),
    (
        replace_line(6, "key 1e999 angle=-150"),
        "x.mot:6:5: expected a finite number for the key time, found '1e999'",
    ),
    (replace_line(6, "key"), "x.mot:6:4: expected a number for the key time, found end of line"),
    (
        replace_line(6, "key angle=-150"),
        "x.mot:6:5: expected a number for the key time, found 'angle=-150'",
    ),
    (
        replace_line(5, "key 0.6 angle=-30 angle=-20"),
        "x.mot:5:19: expected 'angle=' only once, found 'angle=-20'",
    ),
    (
        replace_line(5, "key 0.6"),
        "x.mot:5:8: expected a joint target 'joint=degrees', found end of line",
    ),
    (
        replace_line(5, "key 0.6 angle -30"),
        "x.mot:5:9: expected a joint target 'joint=degrees', found 'angle'",
    ),
    (replace_line(5, "key 0.6 angle=far"), "x.mot:5:15: expected a number for angle, found 'far'"),
    (
        replace_line(5, "key 0.6 angle=-30 kp=3"),
        "x.mot:5:19: expected a joint target 'joint=degrees' (gains go on the 'gains' line, not "
        "on keys), found 'kp=3'",
    ),
    (
        replace_line(5, "key 0.6 kd=3 angle=-30"),
        "x.mot:5:9: expected a joint target 'joint=degrees' (gains go on the 'gains' line, not "
        "on keys), found 'kd=3'",
    ),
    (
        LUXO_KEYS + "key 2 hip=10\n",
        "x.mot:5:13: expected a target for 'elbow' (every key names the joints of the first, "
        "line 3), found end of line",
    ),
    (
        LUXO_KEYS + "key 2 hip=10 elbow=100 base=3\n",
        "x.mot:5:24: expected a joint the first key names (line 3: 'hip', 'elbow'), found 'base=3'",
    ),
    (
        drop_line(3) + "gains kp=1\n",
        "x.mot:7:1: expected a 'key' line ('gains' goes before the first 'key', line 3), "
        "found 'gains'",
    ),
    (
        "key 0 angle=1\nfigure link1\n",
        "x.mot:1:1: expected a 'figure' line before the first 'key', found 'key'",
    ),
]


def test_keys_may_name_their_joints_in_any_order():
    program = parse_motor_program_text(LUXO_KEYS + "key 2 elbow=90 hip=-5\n")
    bound = bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    np.testing.assert_array_equal(np.degrees(bound.value).round(9), [[0, 120], [10, 100], [-5, 90]])


KEY_BIND_ERRORS = [
    (
        SWING_TEXT.replace(" angle=", " torque="),
        ("angle",),
        ("torque",),
        "x.mot:4:7: expected a joint angle of figure 'link1' (a key sets joint targets, not "
        "torques; one of: 'angle'), found 'torque'",
    ),
    (
        LUXO_KEYS.replace("hip=0", "base=0").replace("hip=10", "base=10"),
        LUXO_COORDINATES,
        LUXO_ACTUATORS,
        "x.mot:3:7: expected an actuated joint angle of figure 'luxo' (coordinate 'base' has no "
        "actuator; one of: 'hip', 'elbow'), found 'base'",
    ),
    (
        LUXO_KEYS.replace("elbow", "knee"),
        LUXO_COORDINATES,
        LUXO_ACTUATORS,
        "x.mot:3:13: expected a joint angle of figure 'luxo' (one of: 'hip', 'elbow'), "
        "found 'knee'",
    ),
    (
        drop_line(3),
        ("angle",),
        ("torque",),
        "x.mot:3:7: expected servo gains kp > 0 or kd > 0 to servo 'angle' (set 'gains'), "
        "found 'angle=-90'",
    ),
    (
        SWING_TEXT.replace("limit torque", "limit angle"),
        ("angle",),
        ("torque",),
        "x.mot:2:7: expected an actuator of figure 'link1' (one of: 'torque'), found 'angle'",
    ),
]


@pytest.mark.parametrize(("text", "coordinates", "actuators", "message"), KEY_BIND_ERRORS)
def test_key_bind_error_messages(text, coordinates, actuators, message):
    program = parse_motor_program_text(text, "x.mot")
    with pytest.raises(SpecError) as error:
        bind_motor_program(program, coordinates, actuators)
    assert str(error.value) == message


def test_bind_keys_to_luxo():
    """A key program laid out per key: the joints it names servoed, the others limp."""
    program = parse_motor_program_text(
        "figure luxo\nlimit elbow_torque=3\ngains kd=0.5\nkey 0 elbow=120\nkey 0.25 elbow=90\n"
        "key 1 elbow=150\n"
    )
    bound = bind_motor_program(program, LUXO_COORDINATES, LUXO_ACTUATORS)
    assert bound.keyframed and bound.duration() == 1.0
    np.testing.assert_array_equal(bound.key_times, [0, 0.25, 1])
    np.testing.assert_array_equal(bound.durations, [0.25, 0.75])
    np.testing.assert_array_equal(bound.mode, [[LIMP, SERVO]] * 3)
    np.testing.assert_array_equal(
        bound.value, [[0, math.radians(120)], [0, math.radians(90)], [0, math.radians(150)]]
    )
    np.testing.assert_array_equal(bound.kp, np.zeros((3, 2)))
    np.testing.assert_array_equal(bound.kd, np.full((3, 2), 0.5))
    np.testing.assert_array_equal(bound.limit, [np.inf, 3.0])
    phased = bind_motor_program(
        parse_motor_program(SPECS / "motor" / "luxo" / "hop.mot"), LUXO_COORDINATES, LUXO_ACTUATORS
    )
    assert not phased.keyframed and phased.key_times is None
    assert phased.duration() == pytest.approx(0.259 + 0.215 + 0.228)


# --- hypothesis: keyframed programs parse or fail cleanly, and round-trip ---------------------

WORDS = [
    *("figure", "limit", "gains", "key", "phase", "link1", "angle", "torque", "kp", "kd"),
    *("angle=10", "angle=-90", "torque=2", "kp=6", "angle=", "=", "angle==1", "#", "0", "0.6"),
    *("-1", "1e999", "nan", "inf", "angle=nan", "-0", "2.0", "hip=3"),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
)


def sound_keys_round_trip(program: MotorProgram) -> None:
    """A keyframed program the parser accepts has 2+ keys from 0, strictly increasing and
    finite, each naming the first key's joints once; it reads back from its rendering."""
    if program.keys:
        times = [key.time for key in program.keys]
        assert len(times) >= 2 and times[0] == 0 and math.isfinite(times[-1])
        assert all(a < b for a, b in zip(times, times[1:], strict=False))
        names = {setting.name for setting in program.keys[0].settings}
        for key in program.keys:
            assert len(key.settings) == len(names) and {s.name for s in key.settings} == names
        assert program.duration() == times[-1]
    again = parse_motor_program_text(render_motor_program(program))
    assert key_values(again) == key_values(program)
    assert len(again.phases) == len(program.phases)


@FAST
@given(token_mutations(st.just(SWING_TEXT + "# end\n"), garbage))
def test_mutated_keyframed_programs_parse_or_raise_spec_error(text):
    parses_or_spec_error(parse_motor_program_text, text, "fuzz.mot", sound_keys_round_trip)


@FAST
@given(st.lists(st.lists(garbage, max_size=5).map(" ".join), max_size=8).map("\n".join))
def test_key_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_motor_program_text, text, "fuzz.mot", sound_keys_round_trip)


@st.composite
def keyframed_programs(draw) -> MotorProgram:
    token = Token("x", 1, 1)
    names = draw(
        st.lists(st.sampled_from(["hip", "elbow", "angle", "q_1"]), min_size=1, unique=True)
    )
    times, _ = draw(keyframes(min_gap=1e-6))
    keys = []
    for time in times:
        order = draw(st.permutations(names))
        angles = st.floats(-1e6, 1e6)
        settings_ = tuple(Setting(name, draw(angles), token) for name in order)
        keys.append(Key(float(time), settings_, token, token))
    return MotorProgram(
        path="generated.mot",
        figure="luxo",
        figure_token=token,
        limits=(),
        kp=draw(st.floats(0.0, 1e3)),
        kd=draw(st.floats(0.0, 1e3)),
        phases=(),
        spec_sha256="",
        keys=tuple(keys),
    )


@FAST
@given(keyframed_programs())
def test_render_then_parse_round_trips_keyframed_programs(program):
    text = render_motor_program(program)
    parsed = parse_motor_program_text(text, "generated.mot")
    assert key_values(parsed) == key_values(program)
    assert parsed.spec_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert render_motor_program(parsed) == text


# --- the shipped swing on the real pendulum --------------------------------------------------

TRACKING_DEG = 1.5  # the swing's bound on |angle - target|; measured 1.30 deg (dt 0.001 and 0.01)
END_RATE_DEG_S = 3.0  # measured 1.87 deg/s at the end, 0.5 s after the last swing key


@pytest.mark.parametrize("dt", [0.001, 0.01])
def test_the_swing_tracks_its_keyframes(link1, dt):
    """specs/motor/link1/swing.mot from hanging at rest: the angle stays within 1.5 deg of the
    interpolated target throughout (measured 1.30 deg at t = 0.14 s, where the swing first
    accelerates), passes each key's angle within 1.5 deg at its time (measured <= 1.06 deg),
    and ends hanging within 0.5 deg of -90, at under 3 deg/s. The torque peaks at 6.8 N m: the
    10 N m limit never bites."""
    program = load_motor_program(SWING, "link1", link1)
    assert program.duration() == 2.5
    run = program.run(HANGING, dt)
    rows = program.step_rows(dt)
    steps = round(2.5 / dt)
    assert run.states.shape == (steps + 1, 2) and run.controls.shape == (steps, 1)
    np.testing.assert_array_equal(rows.mode, np.full((steps, 1), SERVO))
    target = np.degrees(rows.value[:, 0])
    error = np.degrees(run.states[:-1, 0]) - target
    assert np.abs(error).max() <= TRACKING_DEG
    assert np.abs(error).max() > 0.5 * TRACKING_DEG  # the bound is a measured one, not slack
    angle = np.degrees(run.states[:, 0])
    for key in program.program.keys:
        step = round(key.time / dt)
        assert angle[step] == pytest.approx(key.settings[0].value, abs=TRACKING_DEG)
        if step < steps:
            assert target[step] == pytest.approx(key.settings[0].value, abs=1e-12)
    assert angle[-1] == pytest.approx(-90.0, abs=0.5)
    assert abs(math.degrees(run.states[-1, 1])) <= END_RATE_DEG_S
    assert np.abs(run.controls).max() < 10.0
    # the phase of a keyframed run: the key interval of each step
    t = dt * np.arange(steps)
    np.testing.assert_array_equal(
        run.phase, np.minimum(np.searchsorted([0.6, 1.4, 2.0], t, "right"), 3)
    )
    np.testing.assert_array_equal(run.final_controls, run.controls[-1])


def test_the_swing_runs_from_a_script(link1):
    """``motor link swing`` in an animation script: the runner finds specs/motor/link1/swing.mot
    and records its motion."""
    script = parse_script_text("state link angle=-90 omega=0\nmotor link swing\n", "x.anim")
    programs = load_programs(script, SPECS / "motor", "link1", link1)
    run = run_script(script, ScriptSources(link1, {}, programs), 0.001)
    assert run.switches == ((0.0, "swing"),)
    assert run.t[-1] == pytest.approx(2.5)
    direct = programs["swing"].run(HANGING, 0.001)
    np.testing.assert_array_equal(run.figure_states[: len(direct.states)], direct.states)


# --- slew limitation ------------------------------------------------------------------------


@pytest.mark.parametrize(("rate", "previous"), [(150.0, 0.0), (150.0, -4.0), (40.0, 3.0)])
def test_a_slew_limit_bounds_every_change_of_torque(link1, rate, previous):
    dt = 0.001
    program = load_motor_program(SWING, "link1", link1)
    start = np.array([previous])
    run = program.run(HANGING, dt, slew_rate=np.array([rate]), previous=start)
    assert start[0] == previous  # the caller's array is left alone
    steps = np.diff(np.concatenate([[previous], run.controls[:, 0]]))
    assert np.abs(steps).max() <= rate * dt + 1e-12
    assert np.isclose(np.abs(steps), rate * dt, rtol=0, atol=1e-12).any()  # it does bite
    np.testing.assert_array_equal(run.final_controls, run.controls[-1])


def test_a_slow_slew_rate_lags_the_swing(link1):
    """The swing asks for up to 300 N m/s (kd times the target's jump in acceleration at the
    first key); 150 N m/s still tracks within 1.5 deg, but 40 N m/s lags the stiff servo into
    a growing oscillation: a slew limit inside a feedback loop is a delay."""
    program = load_motor_program(SWING, "link1", link1)
    target = np.degrees(program.step_rows(0.001).value[:, 0])
    errors = {}
    for rate in (150.0, 40.0):
        run = program.run(HANGING, 0.001, slew_rate=[rate])
        errors[rate] = np.abs(np.degrees(run.states[:-1, 0]) - target).max()
    assert errors[150.0] <= TRACKING_DEG < 10 < errors[40.0]


def test_slew_zero_holds_the_previous_torque(link1):
    run = load_motor_program(SWING, "link1", link1).run(
        HANGING, 0.01, slew_rate=[0.0], previous=[1.5]
    )
    np.testing.assert_array_equal(run.controls, np.full((250, 1), 1.5))
    assert run.final_controls.tolist() == [1.5]


def test_the_slew_limit_applies_after_the_torque_limit(link1):
    """A torque from before the program above the program's limit comes down at the slew rate:
    the slew limit wins (actuators cannot jump), then the limit holds."""
    run = load_motor_program(SWING, "link1", link1).run(
        HANGING, 0.001, slew_rate=[1000.0], previous=[15.0]
    )
    np.testing.assert_allclose(run.controls[:5, 0], [14, 13, 12, 11, 10], rtol=0, atol=1e-12)
    assert np.abs(run.controls[5:]).max() <= 10.0


@pytest.mark.parametrize("dt", [0.001, 0.01])
def test_an_infinite_slew_rate_is_no_limit_bit_for_bit(link1, luxo, dt):
    for program, start in (
        (load_motor_program(SWING, "link1", link1), HANGING),
        (load_motor_program(SPECS / "motor" / "luxo" / "hop.mot", "luxo", luxo), luxo_standing()),
    ):
        free = program.run(start, dt)
        actuators = len(program.coordinate)
        limited = program.run(
            start, dt, slew_rate=np.full(actuators, np.inf), previous=np.full(actuators, 7.0)
        )
        np.testing.assert_array_equal(limited.states, free.states)
        np.testing.assert_array_equal(limited.controls, free.controls)
        np.testing.assert_array_equal(limited.phase, free.phase)


def test_the_kernel_slew_arguments(link1):
    """run_motor_program directly: ``previous`` is updated in place to the last torque."""
    steps = 5
    mode = np.full((steps, 1), TORQUE, dtype=np.int64)
    value = np.array([[3.0], [3.0], [-3.0], [-3.0], [0.25]])
    zeros = np.zeros((steps, 1))
    previous = np.array([0.5])
    state = HANGING.copy()
    record_state = np.empty((steps, 2))
    record_control = np.empty((steps, 1))
    run_motor_program(
        link1.derivative_into,
        mode,
        value,
        zeros,
        zeros,
        zeros,
        np.array([2.0]),  # limit
        np.array([1.0]),  # slew_step
        previous,
        np.array([0], dtype=np.int64),
        1,
        state,
        0.01,
        record_state,
        record_control,
    )
    np.testing.assert_array_equal(record_control[:, 0], [1.5, 2.0, 1.0, 0.0, 0.25])
    assert previous.tolist() == [0.25]
    assert record_state[0].tolist() == HANGING.tolist() and not np.array_equal(state, HANGING)


def test_bad_slew_arguments(link1):
    program = load_motor_program(SWING, "link1", link1)
    for kwargs, message in (
        ({"slew_rate": [1.0, 2.0]}, "slew_rate has shape (2,), expected (1,)"),
        ({"slew_rate": [-1.0]}, "slew_rate must be >= 0 N m/s, got [-1.0]"),
        ({"slew_rate": [math.nan]}, "slew_rate must be >= 0 N m/s, got [nan]"),
        ({"previous": [[0.0]]}, "previous has shape (1, 1), expected (1,)"),
        ({"previous": [math.inf]}, "previous must be finite N m, got [inf]"),
    ):
        with pytest.raises(ValueError) as error:
            program.run(HANGING, 0.01, **kwargs)
        assert str(error.value).startswith(message)


# --- phase programs: the per-step kernel agrees with the phase servo bit for bit ---------------


def phase_servo_reference(program: BoundMotorProgram, start: np.ndarray, dt: float):
    """The phase servo as the motor kernel ran it before keyframes, in numpy: phase p for
    round(duration / dt) RK4 steps, torque per actuator LIMP 0, TORQUE value, SERVO
    kp (value - q) - kd qd, clamped to ±limit, held over the step."""
    bound = program.bound
    derivative_into = program.dynamics.derivative_into
    state = np.array(start, dtype=np.float64)
    n = len(state) // 2
    inputs = np.zeros(len(program.dynamics.INPUT_NAMES))
    k = np.empty((4, len(state)))
    states, controls, phases = [state.copy()], [], []
    for p, steps in enumerate(np.rint(bound.durations / dt).astype(int)):
        for _ in range(steps):
            inputs[:] = 0.0
            row = np.zeros(len(bound.coordinate))
            for a, c in enumerate(bound.coordinate):
                torque = 0.0
                if bound.mode[p, a] == TORQUE:
                    torque = bound.value[p, a]
                elif bound.mode[p, a] == SERVO:
                    torque = (
                        bound.kp[p, a] * (bound.value[p, a] - state[c])
                        - bound.kd[p, a] * state[n + c]
                    )
                row[a] = torque = min(max(torque, -bound.limit[a]), bound.limit[a])
                inputs[c] += torque
            controls.append(row)
            phases.append(p)
            derivative_into(state, inputs, k[0])
            derivative_into(state + 0.5 * dt * k[0], inputs, k[1])
            derivative_into(state + 0.5 * dt * k[1], inputs, k[2])
            derivative_into(state + dt * k[2], inputs, k[3])
            state = state + dt / 6.0 * (k[0] + 2.0 * k[1] + 2.0 * k[2] + k[3])
            states.append(state.copy())
    return np.array(states), np.array(controls), np.array(phases)


MIXED = """\
figure luxo
limit hip_torque=5 elbow_torque=5
gains kp=6 kd=0.25
phase 0.35 hip=10 elbow=150
phase 0.12 hip=-30 elbow=40 kp=40 kd=0.3
phase 0.30 hip_torque=-2 elbow_torque=1.5
phase 0.2 hip=0 elbow_torque=0.5
phase 0.1
"""


@pytest.mark.parametrize("name", ["hop", "backflip", "long_jump"])
@pytest.mark.parametrize("dt", [0.0005, 0.0007])
def test_shipped_phase_programs_run_bit_for_bit_as_the_phase_servo(luxo, name, dt):
    program = load_motor_program(SPECS / "motor" / "luxo" / f"{name}.mot", "luxo", luxo)
    states, controls, phases = phase_servo_reference(program, luxo_standing(), dt)
    run = program.run(luxo_standing(), dt)
    np.testing.assert_array_equal(run.states, states)
    np.testing.assert_array_equal(run.controls, controls)
    np.testing.assert_array_equal(run.phase, phases)


def test_limp_torque_and_servo_phases_run_bit_for_bit(luxo, link1):
    """Every mode, phase gains overriding the program's, on both figures."""
    for program, start, dt in (
        (BoundMotorProgram(parse_motor_program_text(MIXED), luxo), luxo_standing(), 0.001),
        (
            BoundMotorProgram(
                parse_motor_program_text(
                    "figure link1\ngains kp=30 kd=3\nphase 0.5 angle=-30\nphase 0.3 torque=2\n"
                    "phase 0.4 angle=-150 kd=0\nphase 0.2\n"
                ),
                link1,
            ),
            HANGING,
            0.002,
        ),
    ):
        states, controls, phases = phase_servo_reference(program, start, dt)
        run = program.run(start, dt)
        np.testing.assert_array_equal(run.states, states)
        np.testing.assert_array_equal(run.controls, controls)
        np.testing.assert_array_equal(run.phase, phases)


def test_a_keyframed_luxo_program_leaves_unnamed_actuators_limp(luxo):
    """Keys naming only the elbow: the hip's torque is 0 on every step."""
    program = BoundMotorProgram(
        parse_motor_program_text(
            "figure luxo\nlimit elbow_torque=20\ngains kp=6 kd=0.25\nkey 0 elbow=120\n"
            "key 0.3 elbow=100\nkey 0.6 elbow=120\n"
        ),
        luxo,
    )
    run = program.run(luxo_standing(), 0.001)
    assert run.controls.shape == (600, 2)
    np.testing.assert_array_equal(run.controls[:, 0], 0.0)
    assert np.abs(run.controls[:, 1]).max() > 0
