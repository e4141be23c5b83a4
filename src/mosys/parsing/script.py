"""The animation script (``.anim``): the 1990 paper's Figure 15.

::

    state link -135,350      # starting state of object 'link', in its controller's state order
    swapcon link conB.ctab   # invoke controller B (the table built from B.ssc)
    sim 0.4                  # simulate 0.4 seconds

A script animates one object. The state order of a controller is the figure's state order
(coordinates, then rates) restricted to the controller's ``ssd`` dimensions: for the pendulum
(angle, omega), so ``-135,350`` is angle -135 deg, omega 350 deg/s. The full grammar is in
``docs/script-spec.md``.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path

from mosys.parsing.tokens import (
    NAME,
    Line,
    SpecError,
    Token,
    missing_line,
    parse_number,
    read_spec_text,
    tokenize,
    unknown_keyword,
)

KEYWORDS = ("state", "swapcon", "sim")
TABLE = re.compile(r"con([A-Za-z_][A-Za-z0-9_]*)\.ctab")  # the paper's table names: conB.ctab


@dataclass(frozen=True)
class SetState:
    """``state OBJECT V1,V2,...``: set the object's state (spec units: degrees, deg/s, metres,
    m/s), in its controller's state order. ``token`` is the keyword; ``object_token`` the
    object's name; ``value_tokens`` one (sub-)token per value, for errors such as a count that
    does not match the controller."""

    object: str
    values: tuple[float, ...]
    token: Token
    object_token: Token
    value_tokens: tuple[Token, ...]


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
    """``sim SECONDS``: simulate ``seconds`` (> 0, s) under the current controller. ``token`` is
    the keyword; ``seconds_token`` the number."""

    seconds: float
    token: Token
    seconds_token: Token


Command = SetState | SwapController | Simulate


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
        """The one object the script animates (declared by its first ``state`` line)."""
        return next(c.object for c in self.commands if isinstance(c, SetState))

    def controllers(self) -> tuple[str, ...]:
        """The controllers the script uses, in order of first use, each once."""
        names = (c.controller for c in self.commands if isinstance(c, SwapController))
        return tuple(dict.fromkeys(names))

    def duration(self) -> float:
        """Total simulated time, s."""
        return sum(c.seconds for c in self.commands if isinstance(c, Simulate))

    def error(self, token: Token, expected: str) -> SpecError:
        """A SpecError at ``token`` of this script, found its text: for checks made after
        parsing (a controller that does not exist, a state of the wrong length)."""
        return SpecError.at(self.path, token, expected)


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
    declared: Token | None = None  # the object's name in its first 'state' line
    controlled = False  # a 'swapcon' came
    for line in lines:
        keyword = line.keyword.text
        if keyword == "state":
            command = _set_state(line)
            if declared is None:
                declared = command.object_token
            _same_object(line, command.object_token, declared)
        elif keyword == "swapcon":
            command = _swap_controller(line)
            if declared is None:
                raise SpecError(
                    path,
                    command.object_token.line,
                    command.object_token.column,
                    "an object declared by an earlier 'state' line",
                    command.object,
                )
            _same_object(line, command.object_token, declared)
            controlled = True
        elif keyword == "sim":
            command = _simulate(line)
            for missing, needed in ((declared is None, "state"), (not controlled, "swapcon")):
                if missing:
                    raise SpecError(
                        path,
                        line.number,
                        line.keyword.column,
                        f"a '{needed}' line before the first 'sim'",
                        "sim",
                    )
        else:
            raise unknown_keyword(line, KEYWORDS)
        commands.append(command)
    if not any(isinstance(command, Simulate) for command in commands):
        needed = "state" if declared is None else "swapcon" if not controlled else "sim"
        raise missing_line(path, lines, needed)
    return AnimationScript(path, tuple(commands), spec_sha256)


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


def _set_state(line: Line) -> SetState:
    """``state OBJECT`` then numbers separated by a comma, whitespace, or both."""
    name = _object(line)
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


def _swap_controller(line: Line) -> SwapController:
    name = _object(line)
    reader = line.reader()
    reader.word("the object")
    table = reader.word("a controller table 'conX.ctab' or a controller name")
    reader.end()
    match = TABLE.fullmatch(table.text)
    if match is not None:
        controller = match.group(1)
    elif NAME.fullmatch(table.text) is not None:
        controller = table.text
    else:
        raise SpecError(
            line.path,
            table.line,
            table.column,
            "a controller table 'conX.ctab' or a controller name",
            table.text,
        )
    return SwapController(name.text, table.text, controller, line.keyword, name, table)


def _simulate(line: Line) -> Simulate:
    reader = line.reader()
    token = reader.peek()
    seconds = reader.number("seconds")
    assert token is not None
    if not seconds > 0:
        raise SpecError(line.path, token.line, token.column, "a number > 0 for seconds", token.text)
    reader.end()
    return Simulate(seconds, line.keyword, token)


def render_script(script: AnimationScript) -> str:
    """The ``.anim`` text of ``script`` (parsing it gives back the same commands' values)."""
    lines = []
    for command in script.commands:
        if isinstance(command, SetState):
            values = ",".join(repr(value) for value in command.values)
            lines.append(f"state {command.object} {values}")
        elif isinstance(command, SwapController):
            lines.append(f"swapcon {command.object} {command.table}")
        else:
            lines.append(f"sim {command.seconds!r}")
    return "\n".join(lines) + "\n"
