"""The one tokenizer and error type of every spec kind (.fig, .ssc, .anim, .mot, .bsr, .comp).

Specs are line based: ``keyword positional-args key=value ...``; ``#`` starts a comment, blank lines
are ignored. Tokens are separated by whitespace and keep their 1-based line and column, so every
grammar can report ``file:line:column: expected ..., found ...``.
"""

from __future__ import annotations

import codecs
import hashlib
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from mosys.files import input_problem

NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
ENDPOINT_ENDS = ("proximal", "distal")  # a rod's ends, as specs name them: ROD.END
END_OF_FILE = "\x00end of file"  # the 'found' of an error about a line that never came
NO_FILE = "\x00no such file"  # the 'found' of an error about a spec file that is not there
MAX_WHOLE = 2**31 - 1  # the largest count (generations, controllers, sweeps...) kernels index
MAX_INT64 = 2**63 - 1  # the largest whole number a result file stores (int64): seeds, ticks
SHOWN_CHARACTERS = 200  # of one word an error quotes: a longer word is cut, its length said


def shown_text(found: str) -> str:
    """``found`` as an error message quotes it: its repr, or, past ``SHOWN_CHARACTERS``, the repr
    of its start and its length (a 100 kB word is not echoed whole)."""
    if len(found) <= SHOWN_CHARACTERS:
        return repr(found)
    return f"{found[:SHOWN_CHARACTERS]!r}... ({len(found):,} characters)"


def shortened_words(text: str) -> str:
    """``text`` with every word longer than ``SHOWN_CHARACTERS`` cut to its start and its length
    (a name a spec defined, quoted back in a list of what was expected)."""
    return re.sub(
        rf"\S{{{SHOWN_CHARACTERS + 1},}}",
        lambda word: f"{word.group()[:SHOWN_CHARACTERS]}... ({len(word.group()):,} characters)",
        text,
    )


class SpecError(Exception):
    """A spec that does not parse: names the file, the 1-based line and column, what the grammar
    expected there and what it found (``None`` for the end of the line, ``END_OF_FILE``,
    ``NO_FILE`` for a file that is not there: 'found end of line' read as a parse error), and
    optionally ``why`` what was found will not do, in brackets after it (another file's error
    that the word brought about)."""

    def __init__(
        self,
        path: str,
        line: int,
        column: int,
        expected: str,
        found: str | None,
        why: str | None = None,
    ):
        self.path = str(path)
        self.line = line
        self.column = column
        self.expected = expected
        self.found = found
        special = {None: "end of line", END_OF_FILE: "end of file", NO_FILE: "no such file"}
        shown = special.get(found) or shown_text(found)
        where = f"{self.path}:{line}:{column}"
        message = f"{where}: expected {shortened_words(expected)}, found {shown}"
        super().__init__(message if why is None else f"{message} ({why})")

    @classmethod
    def at(cls, path: str, token: Token, expected: str, why: str | None = None) -> SpecError:
        """The error at ``token`` of the spec ``path``, having found the token's text."""
        return cls(path, token.line, token.column, expected, token.text, why)


@dataclass(frozen=True)
class Token:
    """One whitespace-separated word of a spec, with its 1-based line and column."""

    text: str
    line: int
    column: int


def location(path: str, token: Token) -> str:
    """``path:line:column`` of ``token`` in the spec ``path``: how a message about that word
    begins (as a SpecError's does)."""
    return f"{path}:{token.line}:{token.column}"


@dataclass(frozen=True)
class Line:
    """One non-blank spec line with its comment removed; ``tokens[0]`` is the keyword."""

    path: str
    number: int
    tokens: tuple[Token, ...]
    end_column: int  # the column just past the last token, where 'end of line' errors point

    @property
    def keyword(self) -> Token:
        return self.tokens[0]

    def reader(self) -> LineReader:
        """A cursor over the arguments after the keyword."""
        return LineReader(self)


def tokenize(text: str, path: str) -> list[Line]:
    """Split spec text into lines of tokens. Comments (``#`` to the end of the line) and blank
    lines are dropped; line and column numbers refer to the original text."""
    lines = []
    # lines end at '\n' only (as editors count them), not at every character splitlines() knows
    for number, raw in enumerate(text.split("\n"), start=1):
        raw = raw.removesuffix("\r")
        content = raw.split("#", 1)[0]
        tokens = tuple(
            Token(match.group(), number, match.start() + 1)
            for match in re.finditer(r"\S+", content)
        )
        if tokens:
            end = tokens[-1].column + len(tokens[-1].text)
            lines.append(Line(str(path), number, tokens, end))
    return lines


def check_spec_file(path: str | Path) -> None:
    """SpecError at 1:1 if ``path`` is a directory, a FIFO (whose read would block forever) or
    a device; else it is recorded as read by this command (``files.input_problem``)."""
    problem = input_problem(path)
    if problem:
        raise SpecError(str(path), 1, 1, "a spec file", problem)


def read_spec_text(path: str | Path) -> tuple[str, str]:
    """The text of a spec file (UTF-8, a leading byte-order mark dropped) and the hex SHA-256 of
    its bytes, read once. A file that is missing, unreadable or not UTF-8 raises SpecError at
    1:1, as does one that is a directory, a FIFO or a device."""
    path = Path(path)
    check_spec_file(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise SpecError(str(path), 1, 1, "an existing spec file", NO_FILE) from None
    except OSError as error:
        raise SpecError(str(path), 1, 1, "a readable spec file", error.strerror) from None
    mark = len(codecs.BOM_UTF8) if data.startswith(codecs.BOM_UTF8) else 0
    try:
        text = data[mark:].decode("utf-8")  # a byte-order mark (Windows editors write one) dropped
    except UnicodeDecodeError as error:
        raise SpecError(str(path), 1, 1, "UTF-8 text", f"byte {mark + error.start}") from None
    return text, hashlib.sha256(data).hexdigest()


def format_number(value: float) -> str:
    """A number in spec text: the shortest repr that reads back to the same float (``2``,
    ``0.1``, ``1e-06``)."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def parse_number(token: Token, path: str, what: str, text: str | None = None) -> float:
    """A finite decimal number (``1``, ``-2.5``, ``1e-3``); ``what`` names it in the error.
    ``text`` overrides the token's text (for parts of a token such as ``-135`` in ``-135,350``)."""
    text = token.text if text is None else text
    if NUMBER.fullmatch(text) is None:
        raise SpecError(path, token.line, token.column, f"a number for {what}", text)
    value = float(text)
    if not math.isfinite(value):
        raise SpecError(path, token.line, token.column, f"a finite number for {what}", text)
    return value


def parse_int(
    token: Token, path: str, what: str, minimum: int | None = None, maximum: int | None = None
) -> int:
    """A whole number (an optional sign, no point or exponent), at least ``minimum`` and at most
    ``maximum`` if given."""
    if re.fullmatch(r"[+-]?\d+", token.text) is None:
        raise SpecError(path, token.line, token.column, f"a whole number for {what}", token.text)
    try:
        value = int(token.text)
    except ValueError:  # more digits than Python converts (sys.get_int_max_str_digits)
        raise SpecError(
            path, token.line, token.column, f"a whole number of fewer digits for {what}", token.text
        ) from None
    if minimum is not None and value < minimum:
        raise SpecError(
            path, token.line, token.column, f"a whole number >= {minimum} for {what}", token.text
        )
    if maximum is not None and value > maximum:
        bounds = f"<= {maximum}" if minimum is None else f"from {minimum} to {maximum}"
        raise SpecError(
            path, token.line, token.column, f"a whole number {bounds} for {what}", token.text
        )
    return value


def parse_name(token: Token, path: str, what: str) -> str:
    """An identifier: a letter or underscore, then letters, digits or underscores."""
    if NAME.fullmatch(token.text) is None:
        raise SpecError(path, token.line, token.column, f"a name for {what}", token.text)
    return token.text


class LineReader:
    """A cursor over one line's arguments (everything after the keyword).

    Grammar modules read positional arguments with ``word``/``number``/``integer``/``name``,
    then ``key_values`` for trailing ``key=value`` options, then ``end``.
    """

    def __init__(self, line: Line):
        self.line = line
        self.path = line.path
        self.position = 1

    def _take(self, expected: str) -> Token:
        if self.position >= len(self.line.tokens):
            raise SpecError(self.path, self.line.number, self.line.end_column, expected, None)
        token = self.line.tokens[self.position]
        self.position += 1
        return token

    def peek(self) -> Token | None:
        """The next token without consuming it, or None at the end of the line."""
        if self.position >= len(self.line.tokens):
            return None
        return self.line.tokens[self.position]

    def at_end(self) -> bool:
        return self.position >= len(self.line.tokens)

    def word(self, expected: str) -> Token:
        """The next token, whatever it is."""
        return self._take(expected)

    def number(self, what: str) -> float:
        return parse_number(self._take(f"a number for {what}"), self.path, what)

    def integer(self, what: str, minimum: int | None = None) -> int:
        return parse_int(self._take(f"a whole number for {what}"), self.path, what, minimum)

    def name(self, what: str) -> str:
        return parse_name(self._take(f"a name for {what}"), self.path, what)

    def remaining(self) -> Iterator[Token]:
        """Consume and yield every remaining token."""
        while not self.at_end():
            yield self._take("a token")

    def key_values(
        self, allowed: dict[str, str], unknown: str | None = None
    ) -> dict[str, tuple[Token, str]]:
        """Consume every remaining token as ``key=value``. ``allowed`` maps each permitted key to
        a description used in errors; ``unknown`` says what was expected of an unknown key
        (default: one of the keys). Returns key -> (token, value text); repeated keys and
        unknown keys are errors."""
        found: dict[str, tuple[Token, str]] = {}
        if unknown is None:
            unknown = "one of " + ", ".join(f"'{key}='" for key in allowed)
        for token in self.remaining():
            key, sep, value = token.text.partition("=")
            if not sep or key not in allowed:
                raise SpecError(self.path, token.line, token.column, unknown, token.text)
            if key in found:
                raise SpecError(
                    self.path, token.line, token.column, f"'{key}=' only once", token.text
                )
            if not value:
                raise SpecError(
                    self.path,
                    token.line,
                    token.column + len(key) + 1,
                    allowed[key],
                    None,
                )
            found[key] = (token, value)
        return found

    def end(self) -> None:
        """Fail if anything is left on the line."""
        token = self.peek()
        if token is not None:
            raise SpecError(self.path, token.line, token.column, "end of line", token.text)


def figure_line(line: Line) -> Token:
    """The name of a ``figure NAME`` line (a BSR search spec's, a composite script's) as its
    token: the figure spec ``specs/figures/NAME.fig``. Nothing may follow the name."""
    reader = line.reader()
    token = reader.peek()
    reader.name("the figure")
    reader.end()
    assert token is not None
    return token


def parse_endpoint(token: Token, path: str, expected: str) -> tuple[str, str]:
    """The rod and end (``proximal`` or ``distal``) of a ``ROD.END`` word; SpecError at the
    word (``expected`` naming what it should be), at the rod or at the end otherwise."""
    rod, sep, end = token.text.partition(".")
    if not sep:
        raise SpecError.at(path, token, expected)
    if NAME.fullmatch(rod) is None:
        raise SpecError(path, token.line, token.column, "a rod name before '.'", rod)
    if end not in ENDPOINT_ENDS:
        raise SpecError(
            path,
            token.line,
            token.column + len(rod) + 1,
            f"'proximal' or 'distal' after '{rod}.'",
            end,
        )
    return rod, end


def value_token(token: Token, key: str) -> Token:
    """The value part of a ``key=value`` token, with its own column, for precise errors."""
    return Token(token.text[len(key) + 1 :], token.line, token.column + len(key) + 1)


def unknown_keyword(line: Line, keywords: tuple[str, ...]) -> SpecError:
    """The error for a line whose keyword the grammar does not know."""
    choices = ", ".join(f"'{keyword}'" for keyword in keywords)
    return SpecError(
        line.path, line.number, line.keyword.column, f"one of {choices}", line.keyword.text
    )


def record_once(line: Line, first_line: dict[str, int]) -> None:
    """Note a line whose keyword may appear once in ``first_line`` (keyword -> line number);
    a second one is an error at its keyword naming the first."""
    keyword = line.keyword
    if keyword.text in first_line:
        raise SpecError.at(
            line.path,
            keyword,
            f"one '{keyword.text}' line only (the first is line {first_line[keyword.text]})",
        )
    first_line[keyword.text] = line.number


def missing_line(path: str, lines: list[Line], keyword: str) -> SpecError:
    """The error for a required line that never came: points just past the last line."""
    last = lines[-1].number + 1 if lines else 1
    return SpecError(path, last, 1, f"a '{keyword}' line", END_OF_FILE)
