"""The .anim grammar: Figure 15, whole-message errors, and hypothesis fuzzing."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import pytest
from conftest import parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations

from mosys.parsing.script import (
    AnimationScript,
    Breakpoint,
    Condition,
    DeclareObject,
    RunMotorProgram,
    SetState,
    Simulate,
    SwapController,
    parse_script,
    parse_script_text,
    render_script,
)
from mosys.parsing.tokens import SpecError, Token

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ROOT / "specs" / "scripts" / "pendulum.anim"
FIGURE_15 = [("B", 0.4), ("A", 0.7), ("D", 0.6), ("E", 0.4), ("C", 0.4), ("F", 0.7)]
BASE = """\
state link -135,350
swapcon link conB.ctab
sim 0.4
"""


def values(script: AnimationScript) -> tuple:
    """The commands without tokens."""
    out = []
    for command in script.commands:
        if isinstance(command, DeclareObject):
            out.append(("object", command.object, command.figure))
        elif isinstance(command, SetState):
            named = (command.names,) if command.names else ()
            out.append(("state", command.object, command.values, *named))
        elif isinstance(command, SwapController):
            out.append(("swapcon", command.object, command.table, command.controller))
        elif isinstance(command, RunMotorProgram):
            out.append(("motor", command.object, command.program))
        elif isinstance(command, Breakpoint):
            bounds = tuple((c.name, c.operator, c.value) for c in command.conditions)
            out.append(("when", command.object, bounds, command.table, command.controller))
        else:
            out.append(("sim", command.seconds, *(("until=dest",) if command.until_dest else ())))
    return tuple(out)


def test_pendulum_script():
    script = parse_script(PENDULUM)
    expected = [("state", "link", (-135.0, 350.0))]
    for name, seconds in FIGURE_15:
        expected += [("swapcon", "link", f"con{name}.ctab", name), ("sim", seconds)]
    assert values(script) == tuple(expected)
    assert script.path == str(PENDULUM)
    assert script.name == "pendulum"
    assert script.object == "link"
    assert script.controllers() == ("B", "A", "D", "E", "C", "F")
    assert script.duration() == pytest.approx(3.2)
    assert script.spec_sha256 == hashlib.sha256(PENDULUM.read_bytes()).hexdigest()
    state, swap, sim = script.commands[:3]
    assert state.token == Token("state", 1, 1)
    assert state.object_token == Token("link", 1, 7)
    assert state.value_tokens == (Token("-135", 1, 12), Token("350", 1, 17))
    assert swap.table_token == Token("conB.ctab", 2, 14)
    assert sim.seconds_token == Token("0.4", 3, 5)


def test_pendulum_script_is_figure_15_verbatim():
    lines = ["state link -135,350\t# starting state"]
    for name, seconds in FIGURE_15:
        lines.append(f"swapcon link con{name}.ctab\t# invoke controller {name}")
        lines.append(f"sim {seconds}\t# simulate {seconds} seconds")
    assert PENDULUM.read_text() == "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "written", ["-135,350", "-135, 350", "-135 ,350", "-135 , 350", "-135 350", "-135,\t350"]
)
def test_state_value_spellings(written):
    script = parse_script_text(BASE.replace("-135,350", written))
    assert script.commands[0].values == (-135.0, 350.0)


def test_plain_controller_names_restates_and_trailing_commands():
    script = parse_script_text(
        "state link 1e1\nswapcon link B\nsim 1\nstate link -5,5,6\nsim 2\nswapcon link con_x.ctab\n"
    )
    assert values(script) == (
        ("state", "link", (10.0,)),
        ("swapcon", "link", "B", "B"),
        ("sim", 1.0),
        ("state", "link", (-5.0, 5.0, 6.0)),
        ("sim", 2.0),
        ("swapcon", "link", "con_x.ctab", "_x"),
    )
    assert script.controllers() == ("B", "_x")


def test_error_helper_points_at_tokens():
    script = parse_script_text(BASE, "x.anim")
    assert str(script.error(script.commands[1].table_token, "a built controller of link1")) == (
        "x.anim:2:14: expected a built controller of link1, found 'conB.ctab'"
    )


ERRORS = [
    (
        "sim 0.4\n" + BASE,
        "x.anim:1:1: expected a 'state' line before the first 'sim', found 'sim'",
    ),
    (
        "state link -135,350\nsim 0.4\n",
        "x.anim:2:1: expected a 'swapcon' line before the first 'sim', found 'sim'",
    ),
    (
        "swapcon link conB.ctab\n" + BASE,
        "x.anim:1:9: expected an object declared by an earlier 'state' line, found 'link'",
    ),
    (
        BASE.replace("conB.ctab", "B.h5"),
        "x.anim:2:14: expected a controller table 'conX.ctab' or a controller name, found 'B.h5'",
    ),
    (
        BASE.replace("conB.ctab", "con.ctab"),
        "x.anim:2:14: expected a controller table 'conX.ctab' or a controller name, "
        "found 'con.ctab'",
    ),
    (
        BASE.replace(" conB.ctab", ""),
        "x.anim:2:13: expected a controller table 'conX.ctab' or a controller name, "
        "found end of line",
    ),
    (
        BASE.replace("conB.ctab", "conB.ctab conA.ctab"),
        "x.anim:2:24: expected end of line, found 'conA.ctab'",
    ),
    (BASE.replace("sim 0.4", "sim 0"), "x.anim:3:5: expected a number > 0 for seconds, found '0'"),
    (
        BASE.replace("sim 0.4", "sim -0.4"),
        "x.anim:3:5: expected a number > 0 for seconds, found '-0.4'",
    ),
    (
        BASE.replace("sim 0.4", "sim 0.4s"),
        "x.anim:3:5: expected a number for seconds, found '0.4s'",
    ),
    (
        BASE.replace("sim 0.4", "sim"),
        "x.anim:3:4: expected a number for seconds, found end of line",
    ),
    (
        BASE.replace("sim 0.4", "sim 0.4 0.5"),
        "x.anim:3:9: expected one of 'until=', found '0.5'",
    ),
    (
        BASE.replace("-135,350", "-135,,350"),
        "x.anim:1:17: expected a number for state value 2 of 'link', found ','",
    ),
    (
        BASE.replace("-135,350", "-135, ,350"),
        "x.anim:1:18: expected a number for state value 2 of 'link', found ','",
    ),
    (
        BASE.replace("-135,350", ",-135,350"),
        "x.anim:1:12: expected a number for state value 1 of 'link', found ','",
    ),
    (
        BASE.replace("-135,350", "-135,"),
        "x.anim:1:17: expected a number for state value 2 of 'link', found end of line",
    ),
    (
        BASE.replace("-135,350", "-135,fast"),
        "x.anim:1:17: expected a number for state value 2 of 'link', found 'fast'",
    ),
    (
        BASE.replace(" -135,350", ""),
        "x.anim:1:11: expected a number for state value 1 of 'link', found end of line",
    ),
    (
        "state\n",
        "x.anim:1:6: expected a name for the object, found end of line",
    ),
    (
        BASE.replace("swapcon link", "swapcon cart"),
        "x.anim:2:9: expected object 'link' (a script animates one object; line 1), found 'cart'",
    ),
    (
        BASE + "state 2link 0,0\n",
        "x.anim:4:7: expected a name for the object, found '2link'",
    ),
    (
        BASE + "simulate 0.4\n",
        "x.anim:4:1: expected one of 'object', 'state', 'swapcon', 'sim', 'motor', 'when', "
        "'slew', found 'simulate'",
    ),
    ("", "x.anim:1:1: expected a 'state' line, found end of file"),
    ("# nothing\n\n", "x.anim:1:1: expected a 'state' line, found end of file"),
    ("state link 0,0\n", "x.anim:2:1: expected a 'swapcon' line, found end of file"),
    (
        "state link 0,0\nswapcon link conA.ctab # no sim\n\n",
        "x.anim:3:1: expected a 'sim' line, found end of file",
    ),
]


@pytest.mark.parametrize(("text", "message"), ERRORS)
def test_error_messages(text, message):
    with pytest.raises(SpecError) as error:
        parse_script_text(text, "x.anim")
    assert str(error.value) == message


def test_file_errors(tmp_path):
    missing = tmp_path / "missing.anim"
    with pytest.raises(SpecError) as error:
        parse_script(missing)
    assert str(error.value) == f"{missing}:1:1: expected an existing spec file, found no such file"
    bad = tmp_path / "bad.anim"
    bad.write_text(BASE.replace("sim 0.4", "sim 0"))
    with pytest.raises(SpecError) as error:
        parse_script(bad)
    assert str(error.value) == f"{bad}:3:5: expected a number > 0 for seconds, found '0'"


# --- hypothesis -----------------------------------------------------------------------------

SOURCE = PENDULUM.read_text()
WORDS = [
    *("state", "swapcon", "sim", "link", "conB.ctab", "con.ctab", "B", "-135,350", ","),
    *("1,", ",2", "0", "-0.4", "0.4", "1e999", "nan", "#", "=", "cart"),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.lists(st.floats(-1e3, 1e3).map(repr), min_size=1, max_size=3).map(",".join),
)
FAST = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def sound_and_round_trips(script: AnimationScript) -> None:
    """What a script the parser accepts satisfies, and it reads back from its rendering."""
    assert any(isinstance(command, Simulate) for command in script.commands)
    assert values(parse_script_text(render_script(script))) == values(script)


@FAST
@given(st.text())
def test_any_text_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_script_text, text, "fuzz.anim", sound_and_round_trips)


@FAST
@given(st.lists(st.lists(garbage, max_size=5).map(" ".join), max_size=8).map("\n".join))
def test_keyword_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_script_text, text, "fuzz.anim", sound_and_round_trips)


mutated_scripts = token_mutations(st.just(SOURCE), garbage)


@FAST
@given(mutated_scripts)
def test_mutated_scripts_parse_or_raise_spec_error(text):
    parses_or_spec_error(parse_script_text, text, "fuzz.anim", sound_and_round_trips)


NAMES = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,5}", fullmatch=True)
NUMBERS = st.floats(allow_nan=False, allow_infinity=False)


def leaves_room(bounds: list[tuple[str, str, float]]) -> bool:
    """Whether a name bounded both ways has its lower bound below its upper, as a 'when' line
    must (the parser's rule)."""
    lower = {name: value for name, operator, value in bounds if operator == ">"}
    upper = {name: value for name, operator, value in bounds if operator == "<"}
    return all(lower[name] < upper[name] for name in lower.keys() & upper.keys())


@st.composite
def scripts(draw) -> AnimationScript:
    token = Token("x", 1, 1)
    target = draw(NAMES)

    def state():
        numbers = tuple(draw(st.lists(NUMBERS, min_size=1, max_size=5)))
        if not draw(st.booleans()):
            return SetState(target, numbers, token, token, ())
        count = len(numbers)
        names = tuple(draw(st.lists(NAMES, min_size=count, max_size=count, unique=True)))
        return SetState(target, numbers, token, token, (), names, (token,) * len(names))

    def swap():
        controller = draw(NAMES)
        table = draw(st.sampled_from([f"con{controller}.ctab", controller]))
        return SwapController(target, table, controller, token, token, token)

    def sim():
        seconds = draw(st.floats(min_value=1e-6, max_value=1e6, allow_nan=False))
        return Simulate(seconds, token, token, draw(st.booleans()))

    def motor():
        return RunMotorProgram(target, draw(NAMES), token, token, token)

    def when():
        controller = draw(NAMES)
        bounds = st.tuples(NAMES, st.sampled_from("<>"), NUMBERS)
        drawn = draw(
            st.lists(bounds, min_size=1, max_size=3, unique_by=lambda b: b[:2]).filter(leaves_room)
        )
        conditions = tuple(Condition(name, op, value, token) for name, op, value in drawn)
        return Breakpoint(
            target, conditions, f"con{controller}.ctab", controller, token, token, token
        )

    commands = [state(), swap(), sim()]
    for _ in range(draw(st.integers(0, 8))):
        command = draw(st.sampled_from([state, swap, sim, motor, when]))
        commands.insert(draw(st.integers(3, len(commands))), command())
    if draw(st.booleans()):
        commands.insert(0, DeclareObject(target, draw(NAMES), token, token, token))
    return AnimationScript("generated.anim", tuple(commands), "")


@FAST
@given(scripts())
def test_render_then_parse_round_trips(script):
    text = render_script(script)
    parsed = parse_script_text(text, "generated.anim")
    assert values(parsed) == values(script)
    assert parsed.spec_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert render_script(parsed) == text


# --- Luxo's additions: object, named state, motor, sim until=dest, when ---------------------

LUXO = """object luxo figure=luxo
state luxo x=0.5 hip=0 elbow=120
swapcon luxo conland.ctab
motor luxo hop
sim 3 until=dest
when luxo hip>-20 hip<20 elbow_rate<100 swapcon conland.ctab
sim 1
"""


def test_luxo_commands_parse_to_values():
    script = parse_script_text(LUXO, "s.anim")
    declare, state, _, motor, until, when, sim = script.commands
    assert (declare.object, declare.figure) == ("luxo", "luxo")
    assert script.declared_figure is declare and script.object == "luxo"
    assert state.names == ("x", "hip", "elbow") and state.values == (0.5, 0.0, 120.0)
    assert motor.program == "hop" and script.motor_programs() == ("hop",)
    assert until.until_dest and not sim.until_dest
    assert when.box() == {"hip": (-20.0, 20.0), "elbow_rate": (-math.inf, 100.0)}
    assert script.controllers() == ("land",)
    rendered = render_script(script)
    assert render_script(parse_script_text(rendered)) == rendered


LUXO_ERRORS = [
    (LUXO.replace("until=dest", "until=now"), "s.anim:5:13: expected 'dest', found 'now'"),
    (
        LUXO.replace("hip>-20 hip<20 elbow_rate<100 ", ""),
        "s.anim:6:11: expected at least one condition 'NAME<VALUE' or 'NAME>VALUE' before "
        "'swapcon', found 'swapcon'",
    ),
    (
        LUXO.replace("hip<20", "hip=20"),
        "s.anim:6:19: expected a condition 'NAME<VALUE' or 'NAME>VALUE', or 'swapcon', "
        "found 'hip=20'",
    ),
    (
        LUXO.replace("hip<20", "hip<-30"),
        "s.anim:6:11: expected bounds on 'hip' that leave room (low -20 < high -30), "
        "found 'hip>-20'",
    ),
    (
        LUXO.replace("hip<20", "hip>3"),
        "s.anim:6:19: expected one 'hip>' bound (the first is column 11), found 'hip>3'",
    ),
    (
        LUXO.replace(" swapcon conland.ctab\nsim 1", "\nsim 1"),
        "s.anim:6:40: expected a condition 'NAME<VALUE' or 'NAME>VALUE', or 'swapcon', "
        "found end of line",
    ),
    (
        "object luxo figure=luxo\nmotor luxo hop\n",
        "s.anim:2:1: expected a 'state' line before the first 'motor', found 'motor'",
    ),
    (
        LUXO.replace("state luxo", "object luxo figure=luxo\nstate luxo"),
        "s.anim:2:1: expected one 'object' line, before the object's other lines (line 1 "
        "names it), found 'object'",
    ),
    (
        LUXO.replace("elbow=120", "hip=120"),
        "s.anim:2:24: expected 'hip=' only once, found 'hip=120'",
    ),
    (LUXO.replace("figure=luxo", ""), "s.anim:1:12: expected 'figure=NAME', found end of line"),
    (
        LUXO.replace("motor luxo hop", "motor luxo 2hop"),
        "s.anim:4:12: expected a name for the motor program, found '2hop'",
    ),
]


@pytest.mark.parametrize(("text", "message"), LUXO_ERRORS)
def test_luxo_command_errors(text, message):
    with pytest.raises(SpecError) as error:
        parse_script_text(text, "s.anim")
    assert str(error.value) == message
