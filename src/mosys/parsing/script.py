"""The animation script (``.anim``): the 1990 paper's Figure 15, and motor programs, runs until
the destination and state-space breakpoints (§3.1, §7).

::

    object luxo figure=luxo  # optional: the object is an instance of figure 'luxo'
    state link -135,350      # starting state of object 'link', in its controller's state order
    state luxo x=0.5 elbow=120   # or by name: figure state variables, the others 0
    swapcon link conB.ctab   # invoke controller B (the table built from B.ssc)
    sim 0.4                  # simulate 0.4 seconds
    sim 3 until=dest         # at most 3 s: stop once back at the controller's destination
    motor luxo hop           # run the motor program 'hop' (a .mot spec of the figure) to its end
    when link angle>-20 angle<20 swapcon conA.ctab   # breakpoint: in this box, A drives
    when link angle>75 angle<105 swapcon conB.ctab once   # on entering this box, B takes over
    slew link torque=40      # from here on, the torque changes at most 40 N m per second

A script animates one object. The state order of a controller is the figure's state order
(coordinates, then rates) restricted to the controller's ``ssd`` dimensions: for the pendulum
(angle, omega), so ``-135,350`` is angle -135 deg, omega 350 deg/s. The full grammar is in the
README ("Animation scripts").
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path

from mosys.parsing.tokens import (
    NAME,
    Line,
    SpecError,
    Token,
    missing_line,
    parse_name,
    parse_number,
    read_spec_text,
    tokenize,
    unknown_keyword,
    value_token,
)

KEYWORDS = ("object", "state", "swapcon", "sim", "motor", "when", "slew")
TABLE = re.compile(r"con([A-Za-z_][A-Za-z0-9_]*)\.ctab")  # the paper's table names: conB.ctab
CONDITION = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)([<>])(.*)")  # a breakpoint's 'name<value'


@dataclass(frozen=True)
class DeclareObject:
    """``object OBJECT figure=FIGURE``: the object is an instance of ``figure``
    (specs/figures/FIGURE.fig). Without it, the figure is that of the first controller."""

    object: str
    figure: str
    token: Token
    object_token: Token
    figure_token: Token


@dataclass(frozen=True)
class SetState:
    """``state OBJECT V1,V2,...``: set the object's state (spec units: degrees, deg/s, metres,
    m/s), in its controller's state order; or ``state OBJECT NAME=V ...``: by figure state
    variable (``names`` aligned with ``values``; empty for the positional form). Variables not
    given are 0. ``token`` is the keyword; ``object_token`` the object's name; ``value_tokens``
    one (sub-)token per value, for errors such as a count that does not match the controller;
    ``name_tokens`` the names' tokens."""

    object: str
    values: tuple[float, ...]
    token: Token
    object_token: Token
    value_tokens: tuple[Token, ...]
    names: tuple[str, ...] = ()
    name_tokens: tuple[Token, ...] = ()


@dataclass(frozen=True)
class SwapController:
    """``swapcon OBJECT TABLE``: from now on, ``controller`` drives the object. ``table`` is the
    reference as written (``conB.ctab``); ``controller`` the controller it names (``B``: the
    table built from ``B.ssc`` of the object's figure). ``token`` is the keyword;
    ``table_token`` the reference."""

    object: str
    table: str
    controller: str
    token: Token
    object_token: Token
    table_token: Token


@dataclass(frozen=True)
class Simulate:
    """``sim SECONDS [until=dest]``: simulate ``seconds`` (> 0, s) under the current controller
    (and the breakpoints); with ``until_dest``, stop earlier once the figure is back at the
    controller's destination. ``token`` is the keyword; ``seconds_token`` the number."""

    seconds: float
    token: Token
    seconds_token: Token
    until_dest: bool = False


@dataclass(frozen=True)
class RunMotorProgram:
    """``motor OBJECT PROGRAM``: run the motor program ``program`` (PROGRAM.mot of the object's
    figure) from the current state to its end. ``program_token`` is its name's token."""

    object: str
    program: str
    token: Token
    object_token: Token
    program_token: Token


@dataclass(frozen=True)
class Condition:
    """One bound of a breakpoint's box: ``name`` ``<`` or ``>`` ``value`` (spec units)."""

    name: str
    operator: str
    value: float
    token: Token


@dataclass(frozen=True)
class Breakpoint:
    """``when OBJECT CONDITION... swapcon TABLE [once]``: a state-space breakpoint (§3.1). From
    this line on, during every ``sim``, ``controller`` drives the object whenever its state lies
    in the box the conditions bound (all of them hold); the first breakpoint whose box holds the
    state wins, and outside every box the last ``swapcon`` drives. With ``once``, the first time
    the state lies in the box, ``controller`` takes over for good, as a ``swapcon`` at that
    moment would, and the breakpoint is spent."""

    object: str
    conditions: tuple[Condition, ...]
    table: str
    controller: str
    token: Token
    object_token: Token
    table_token: Token
    once: bool = False

    def box(self) -> dict[str, tuple[float, float]]:
        """The conditions as {name: (low, high)}, spec units (±inf where unbounded)."""
        box: dict[str, tuple[float, float]] = {}
        for condition in self.conditions:
            low, high = box.get(condition.name, (-math.inf, math.inf))
            if condition.operator == "<":
                high = min(high, condition.value)
            else:
                low = max(low, condition.value)
            box[condition.name] = (low, high)
        return box


@dataclass(frozen=True)
class SlewLimit:
    """``slew OBJECT CONTROL=RATE ...``: from this line on, each named control (an actuator of
    the object's figure) changes by at most ``RATE`` of its unit per second (N m/s for a torque),
    across controller exchanges and inside controllers and motor programs (the 1990 paper's §5).
    ``rates`` maps control -> rate (> 0; inf for ``CONTROL=off``, which lifts the limit);
    ``name_tokens`` the controls' names, for errors found when the figure is known."""

    object: str
    rates: tuple[tuple[str, float], ...]
    token: Token
    object_token: Token
    name_tokens: tuple[Token, ...]


Command = (
    DeclareObject | SetState | SwapController | Simulate | RunMotorProgram | Breakpoint | SlewLimit
)


@dataclass(frozen=True)
class AnimationScript:
    """A parsed ``.anim`` file: its commands in file order, and the hex SHA-256 of its bytes."""

    path: str
    commands: tuple[Command, ...]
    spec_sha256: str

    @property
    def name(self) -> str:
        """The script's name: the file's stem (``pendulum`` for ``pendulum.anim``)."""
        return Path(self.path).stem

    @property
    def object(self) -> str:
        """The one object the script animates (declared by its first ``object`` or ``state``
        line)."""
        return next(c.object for c in self.commands if isinstance(c, DeclareObject | SetState))

    @property
    def declared_figure(self) -> DeclareObject | None:
        """The ``object`` line that names the object's figure, if there is one."""
        return next((c for c in self.commands if isinstance(c, DeclareObject)), None)

    def controllers(self) -> tuple[str, ...]:
        """The controllers the script uses (``swapcon`` and ``when``), in order of first use,
        each once."""
        names = (c.controller for c in self.commands if isinstance(c, SwapController | Breakpoint))
        return tuple(dict.fromkeys(names))

    def motor_programs(self) -> tuple[str, ...]:
        """The motor programs the script runs, in order of first use, each once."""
        return tuple(
            dict.fromkeys(c.program for c in self.commands if isinstance(c, RunMotorProgram))
        )

    def motor_program_files(self, motor_dir: str | Path, figure: str) -> dict[str, Path]:
        """Each motor program the script runs, in order of first use, and its file,
        ``motor_dir/FIGURE/NAME.mot``; SpecError at the first ``motor`` line whose file is not
        there (``mosys run`` and the pipeline's planning both check it so)."""
        files: dict[str, Path] = {}
        for command in self.commands:
            if isinstance(command, RunMotorProgram) and command.program not in files:
                path = Path(motor_dir) / figure / f"{command.program}.mot"
                if not path.exists():
                    expected = f"a motor program ({path} does not exist)"
                    raise self.error(command.program_token, expected)
                files[command.program] = path
        return files

    def duration(self) -> float:
        """The longest simulated time of its ``sim`` lines, s (motor programs add their own)."""
        return sum(c.seconds for c in self.commands if isinstance(c, Simulate))

    def error(self, token: Token, expected: str, why: str | None = None) -> SpecError:
        """A SpecError at ``token`` of this script, found its text (and ``why`` it will not do):
        for checks made after parsing (a controller that does not exist, a state of the wrong
        length)."""
        return SpecError.at(self.path, token, expected, why)


def parse_script(path: str | Path) -> AnimationScript:
    """Parse a ``.anim`` file; any problem raises SpecError naming file, line and column."""
    text, digest = read_spec_text(path)
    return parse_script_text(text, str(path), digest)


def parse_script_text(
    text: str, path: str = "<text>", spec_sha256: str | None = None
) -> AnimationScript:
    """Parse ``.anim`` text; ``path`` names it in errors. ``spec_sha256`` defaults to the SHA-256
    of the text's UTF-8 encoding."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    lines = tokenize(text, path)
    commands: list[Command] = []
    declared: Token | None = None  # the object's name in its first 'object' or 'state' line
    stated = False  # a 'state' line came
    controlled = False  # a 'swapcon' came
    for line in lines:
        keyword = line.keyword.text
        if keyword == "object":
            command = _declare_object(line)
            if declared is not None:
                raise SpecError(
                    path,
                    line.number,
                    line.keyword.column,
                    f"one 'object' line, before the object's other lines (line {declared.line} "
                    "names it)",
                    "object",
                )
            declared = command.object_token
        elif keyword == "state":
            command = _set_state(line)
            if declared is None:
                declared = command.object_token
            _same_object(line, command.object_token, declared)
            stated = True
        elif keyword in ("swapcon", "when", "motor", "slew"):
            command = {
                "swapcon": _swap_controller,
                "when": _breakpoint,
                "motor": _motor,
                "slew": _slew,
            }[keyword](line)
            if declared is None:
                raise SpecError(
                    path,
                    command.object_token.line,
                    command.object_token.column,
                    "an object declared by an earlier 'state' line",
                    command.object,
                )
            _same_object(line, command.object_token, declared)
            controlled = controlled or keyword == "swapcon"
            if keyword == "motor":
                _needs(line, ((not stated, "state"),))
        elif keyword == "sim":
            command = _simulate(line)
            _needs(line, ((not stated, "state"), (not controlled, "swapcon")))
        else:
            raise unknown_keyword(line, KEYWORDS)
        commands.append(command)
    if not any(isinstance(command, Simulate | RunMotorProgram) for command in commands):
        needed = "state" if not stated else "swapcon" if not controlled else "sim"
        raise missing_line(path, lines, needed)
    return AnimationScript(path, tuple(commands), spec_sha256)


def _needs(line: Line, requirements: tuple[tuple[bool, str], ...]) -> None:
    """SpecError at the keyword of ``line`` for the first (missing, keyword) that is missing."""
    for missing, needed in requirements:
        if missing:
            raise SpecError(
                line.path,
                line.number,
                line.keyword.column,
                f"a '{needed}' line before the first '{line.keyword.text}'",
                line.keyword.text,
            )


def _same_object(line: Line, token: Token, declared: Token) -> None:
    if token.text != declared.text:
        raise SpecError(
            line.path,
            token.line,
            token.column,
            f"object '{declared.text}' (a script animates one object; line {declared.line})",
            token.text,
        )


def _object(line: Line) -> Token:
    reader = line.reader()
    token = reader.peek()
    reader.name("the object")
    assert token is not None
    return token


def _declare_object(line: Line) -> DeclareObject:
    name = _object(line)
    reader = line.reader()
    reader.word("the object")
    found = reader.key_values({"figure": "the figure's name"})
    if "figure" not in found:
        raise SpecError(line.path, line.number, line.end_column, "'figure=NAME'", None)
    figure = value_token(found["figure"][0], "figure")
    parse_name(figure, line.path, "the figure")
    return DeclareObject(name.text, figure.text, line.keyword, name, figure)


def _set_state(line: Line) -> SetState:
    """``state OBJECT`` then numbers separated by a comma, whitespace, or both; or
    ``NAME=VALUE`` pairs."""
    name = _object(line)
    if len(line.tokens) > 2 and "=" in line.tokens[2].text:
        return _set_named_state(line, name)
    pieces: list[Token] = []  # numbers and commas, each with its own column
    for token in line.tokens[2:]:
        for match in re.finditer(r"[^,]+|,", token.text):
            pieces.append(Token(match.group(), token.line, token.column + match.start()))
    values: list[float] = []
    value_tokens: list[Token] = []
    after_comma = True  # a value is due: at the start, and after each comma
    for piece in pieces:
        what = f"state value {len(values) + 1} of '{name.text}'"
        if piece.text == ",":
            if after_comma:
                raise SpecError(line.path, piece.line, piece.column, f"a number for {what}", ",")
            after_comma = True
            continue
        values.append(parse_number(piece, line.path, what))
        value_tokens.append(piece)
        after_comma = False
    if after_comma:
        what = f"state value {len(values) + 1} of '{name.text}'"
        raise SpecError(line.path, line.number, line.end_column, f"a number for {what}", None)
    return SetState(name.text, tuple(values), line.keyword, name, tuple(value_tokens))


def _set_named_state(line: Line, name: Token) -> SetState:
    names: list[str] = []
    name_tokens: list[Token] = []
    values: list[float] = []
    value_tokens: list[Token] = []
    for token in line.tokens[2:]:
        key, sep, _ = token.text.partition("=")
        if not sep:
            raise SpecError(line.path, token.line, token.column, "'NAME=VALUE'", token.text)
        parse_name(Token(key, token.line, token.column), line.path, "a state variable")
        if key in names:
            raise SpecError(line.path, token.line, token.column, f"'{key}=' only once", token.text)
        value = value_token(token, key)
        if not value.text:
            raise SpecError(line.path, value.line, value.column, f"a number for '{key}'", None)
        names.append(key)
        name_tokens.append(Token(key, token.line, token.column))
        values.append(parse_number(value, line.path, f"'{key}'"))
        value_tokens.append(value)
    return SetState(
        name.text,
        tuple(values),
        line.keyword,
        name,
        tuple(value_tokens),
        tuple(names),
        tuple(name_tokens),
    )


def _table_reference(line: Line, table: Token) -> str:
    """The controller a table reference names: ``conB.ctab`` or ``B`` -> ``B``."""
    match = TABLE.fullmatch(table.text)
    if match is not None:
        return match.group(1)
    if NAME.fullmatch(table.text) is not None:
        return table.text
    raise SpecError(
        line.path,
        table.line,
        table.column,
        "a controller table 'conX.ctab' or a controller name",
        table.text,
    )


def _swap_controller(line: Line) -> SwapController:
    name = _object(line)
    reader = line.reader()
    reader.word("the object")
    table = reader.word("a controller table 'conX.ctab' or a controller name")
    reader.end()
    controller = _table_reference(line, table)
    return SwapController(name.text, table.text, controller, line.keyword, name, table)


def _breakpoint(line: Line) -> Breakpoint:
    """``when OBJECT name<value name>value ... swapcon TABLE [once]``."""
    name = _object(line)
    reader = line.reader()
    reader.word("the object")
    conditions: list[Condition] = []
    bounds: dict[tuple[str, str], Token] = {}
    while True:
        token = reader.word("a condition 'NAME<VALUE' or 'NAME>VALUE', or 'swapcon'")
        if token.text == "swapcon":
            break
        match = CONDITION.fullmatch(token.text)
        if match is None:
            raise SpecError(
                line.path,
                token.line,
                token.column,
                "a condition 'NAME<VALUE' or 'NAME>VALUE', or 'swapcon'",
                token.text,
            )
        variable, operator, number = match.groups()
        if (variable, operator) in bounds:
            raise SpecError(
                line.path,
                token.line,
                token.column,
                f"one '{variable}{operator}' bound (the first is column "
                f"{bounds[variable, operator].column})",
                token.text,
            )
        bounds[variable, operator] = token
        number_token = Token(number, token.line, token.column + len(variable) + 1)
        if not number:
            raise SpecError(
                line.path, token.line, number_token.column, f"a number for '{variable}'", None
            )
        value = parse_number(number_token, line.path, f"'{variable}{operator}'")
        conditions.append(Condition(variable, operator, value, token))
    if not conditions:
        raise SpecError(
            line.path,
            line.tokens[reader.position - 1].line,
            line.tokens[reader.position - 1].column,
            "at least one condition 'NAME<VALUE' or 'NAME>VALUE' before 'swapcon'",
            "swapcon",
        )
    table = reader.word("a controller table 'conX.ctab' or a controller name")
    once = reader.peek()
    if once is not None:
        if once.text != "once":
            raise SpecError(line.path, once.line, once.column, "'once' or end of line", once.text)
        reader.word("'once'")
        reader.end()
    controller = _table_reference(line, table)
    breakpoint_ = Breakpoint(
        name.text,
        tuple(conditions),
        table.text,
        controller,
        line.keyword,
        name,
        table,
        once is not None,
    )
    for variable, (low, high) in breakpoint_.box().items():
        if not low < high:
            token = bounds.get((variable, ">")) or bounds[variable, "<"]
            raise SpecError(
                line.path,
                token.line,
                token.column,
                f"bounds on '{variable}' that leave room (low {low:g} < high {high:g})",
                token.text,
            )
    return breakpoint_


def _motor(line: Line) -> RunMotorProgram:
    name = _object(line)
    reader = line.reader()
    reader.word("the object")
    program = reader.peek()
    reader.name("the motor program")
    reader.end()
    assert program is not None
    return RunMotorProgram(name.text, program.text, line.keyword, name, program)


def _slew(line: Line) -> SlewLimit:
    """``slew OBJECT CONTROL=RATE ...``: at least one pair, each control once, each rate a number
    > 0 (its unit per second) or ``off``."""
    name = _object(line)
    rates: list[tuple[str, float]] = []
    name_tokens: list[Token] = []
    for token in line.tokens[2:]:
        key, sep, _ = token.text.partition("=")
        if not sep:
            raise SpecError(line.path, token.line, token.column, "'CONTROL=RATE'", token.text)
        key_token = Token(key, token.line, token.column)
        parse_name(key_token, line.path, "a control")
        if any(key == named for named, _ in rates):
            raise SpecError(line.path, token.line, token.column, f"'{key}=' only once", token.text)
        value = value_token(token, key)
        what = f"a rate > 0 (per second) or 'off' for '{key}'"
        if not value.text:
            raise SpecError(line.path, value.line, value.column, what, None)
        if value.text == "off":
            rate = math.inf
        else:
            rate = parse_number(value, line.path, f"the slew rate of '{key}'")
            if not rate > 0:
                raise SpecError(line.path, value.line, value.column, what, value.text)
        rates.append((key, rate))
        name_tokens.append(key_token)
    if not rates:
        raise SpecError(line.path, line.number, line.end_column, "'CONTROL=RATE'", None)
    return SlewLimit(name.text, tuple(rates), line.keyword, name, tuple(name_tokens))


def _simulate(line: Line) -> Simulate:
    reader = line.reader()
    token = reader.peek()
    seconds = reader.number("seconds")
    assert token is not None
    if not seconds > 0:
        raise SpecError(line.path, token.line, token.column, "a number > 0 for seconds", token.text)
    found = reader.key_values({"until": "'dest'"})
    until_dest = False
    if "until" in found:
        value = value_token(found["until"][0], "until")
        if value.text != "dest":
            raise SpecError(line.path, value.line, value.column, "'dest'", value.text)
        until_dest = True
    return Simulate(seconds, line.keyword, token, until_dest)


def render_script(script: AnimationScript) -> str:
    """The ``.anim`` text of ``script`` (parsing it gives back the same commands' values)."""
    lines = []
    for command in script.commands:
        if isinstance(command, DeclareObject):
            lines.append(f"object {command.object} figure={command.figure}")
        elif isinstance(command, SetState):
            if command.names:
                values = " ".join(
                    f"{name}={value!r}"
                    for name, value in zip(command.names, command.values, strict=True)
                )
            else:
                values = ",".join(repr(value) for value in command.values)
            lines.append(f"state {command.object} {values}")
        elif isinstance(command, SwapController):
            lines.append(f"swapcon {command.object} {command.table}")
        elif isinstance(command, Breakpoint):
            bounds = " ".join(f"{c.name}{c.operator}{c.value!r}" for c in command.conditions)
            once = " once" if command.once else ""
            lines.append(f"when {command.object} {bounds} swapcon {command.table}{once}")
        elif isinstance(command, SlewLimit):
            rates = " ".join(
                f"{name}={'off' if math.isinf(rate) else repr(rate)}"
                for name, rate in command.rates
            )
            lines.append(f"slew {command.object} {rates}")
        elif isinstance(command, RunMotorProgram):
            lines.append(f"motor {command.object} {command.program}")
        else:
            until = " until=dest" if command.until_dest else ""
            lines.append(f"sim {command.seconds!r}{until}")
    return "\n".join(lines) + "\n"
