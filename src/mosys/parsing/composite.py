"""The composite-motion script (``.comp``): the 1995 paper's Table 4. Phases run BSR controllers
one after another; each phase's score and the total say what a good composite motion is, and
the transition-point search of Figure 5 tunes the phase durations to maximise the total.

::

    # starman_show: the 1995 paper's Table 4, a cartwheel, a jump and a shuffle
    figure starman
    phase cartwheel controller=starman_cartwheel_robust ticks=215
    phase jump controller=starman_jump_robust ticks=150
    phase shuffle controller=starman_shuffle_robust ticks=100
    score cartwheel = dcm_x * (dtime ?= 215)
    score jump = max_t(min_i(y_i(t))) * (dtime ?= 150)
    score shuffle = dcm_x * (dtime ?= 100)
    total = (1.0 + cartwheel) * (1.0 + jump) * (1.0 + shuffle)
    search q=16 g=16 h=4 seed=1

Grammar (one line each; ``#`` comments and blank lines are ignored)::

    figure NAME                       once, required: specs/figures/NAME.fig
    phase NAME controller=SEARCH [seed=K] [ticks=N]
                                      one per phase, at least one, in time order. NAME: a new
                                      identifier, not a function name. SEARCH: a BSR search
                                      (results/bsr/SEARCH/); K: whole >= 0, that seed's controller
                                      (default: the caller picks the best seed); N: whole >= 1, the
                                      guessed duration in simulator ticks, on every phase or on
                                      none (none: equally spaced)
    score NAME = EXPR                 one per phase, after its phase line: the phase's credit
    total = EXPR                      once, required, after every phase and score line; its
                                      names are the phase names
    search [q=Q] [g=G] [h=H] [seed=S] optional, once, at least one key: Figure 5's Q, G, H (whole
                                      >= 1; defaults 16, 16, 4) and the random seed (whole >= 0;
                                      default 1)

Expressions (whitespace free; lowest precedence first)::

    a ?= b                 1 when a == b, falling to 0 as they differ: exp(-((a - b) / w)^2),
                           w = 0.2 max(|b|, 1); does not chain (a ?= b ?= c is an error)
    a + b, a - b           left associative
    a * b, a / b           left associative
    -a
    NUMBER, NAME, (EXPR), max_t(EXPR), min_t(EXPR), max_i(EXPR), min_i(EXPR)

Score names: ``dcm_x``, ``dcm_y`` (the centre of mass's displacement over the phase, m),
``dtime`` (the phase's duration, ticks), ``x_i``, ``y_i`` (rod endpoint positions per sample and
endpoint, m), ``cm_x``, ``cm_y`` (the centre of mass per sample, m); ``x_i(t)``, ``y_i(t)``,
``cm_x(t)`` and ``cm_y(t)`` are the same, as the paper writes them. ``*_t`` functions reduce over
the samples, ``*_i`` over the endpoints; a score and the total must come to one value, which is
checked here, not when the search runs.
"""

from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from mosys.parsing.composite_script import (
    ENDPOINT,
    FUNCTIONS,
    SCORE_NAMES,
    TIME,
    TIME_DECORATED,
    Binary,
    Call,
    CompositeScript,
    Expr,
    Name,
    Number,
    Phase,
    SearchSettings,
    Unary,
)
from mosys.parsing.tokens import (
    END_OF_FILE,
    MAX_INT64,
    MAX_WHOLE,
    Line,
    SpecError,
    Token,
    figure_line,
    format_number,
    missing_line,
    parse_int,
    parse_name,
    read_spec_text,
    record_once,
    tokenize,
    unknown_keyword,
    value_token,
)

KEYWORDS = ("figure", "phase", "score", "total", "search")
# deepest nesting of parentheses, calls and operators in one expression (keeps the recursive
# parser, evaluator and renderer far from Python's recursion limit)
MAX_DEPTH = 50

# the shared NUMBER without its sign: in an expression a minus is an operator
_LEXEME = re.compile(
    r"(?P<space>\s+)"
    r"|(?P<number>(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<op>\?=|[-+*/=(),])"
)
_OPERATORS = "an operator (+ - * / ?=)"
_OPERAND = "a number, a name, '(' or '-'"
_FUNCTION_NAMES = ", ".join(FUNCTIONS)
_AXIS_ARGUMENT = {
    TIME: "an argument with samples over time (x_i, y_i, cm_x or cm_y, not yet reduced by "
    "min_t/max_t)",
    ENDPOINT: "an argument with rod endpoints (x_i or y_i, not yet reduced by min_i/max_i)",
}
_ONE_VALUE = (
    "an expression with one value (reduce x_i/y_i with min_i/max_i and over time with min_t/max_t)"
)
_PHASE_KEYS = {
    "controller": "a name for controller= (a BSR search)",
    "seed": "a whole number >= 0 for seed=",
    "ticks": "a whole number >= 1 for ticks=",
}
# key -> (minimum, maximum): counts the kernels index; the seed, stored as int64
_SEARCH_KEYS = {
    "q": (1, MAX_WHOLE),
    "g": (1, MAX_WHOLE),
    "h": (1, MAX_WHOLE),
    "seed": (0, MAX_INT64),
}


def parse_composite_script(path: str | Path) -> CompositeScript:
    """Parse a ``.comp`` file; any problem (a missing or unreadable file too, at 1:1) raises
    SpecError naming file, line and column. ``spec_sha256`` is the SHA-256 of the file's bytes."""
    text, digest = read_spec_text(path)
    return parse_composite_text(text, str(path), digest)


def parse_composite_text(
    text: str, path: str = "<text>", spec_sha256: str | None = None
) -> CompositeScript:
    """Parse ``.comp`` text; ``path`` names it in errors and becomes ``CompositeScript.path``.
    ``spec_sha256`` defaults to the SHA-256 of the text's UTF-8 encoding. A NUL character,
    comments included, is an error: the result file keeps the script's text as an HDF5
    string."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    if "\x00" in text:  # even in a comment: the result file keeps the text, and HDF5 cannot
        before = text[: text.index("\x00")]
        line, column = before.count("\n") + 1, len(before) - before.rfind("\n")
        raise SpecError(str(path), line, column, "text without NUL characters", "\x00")
    return _Parser(str(path)).parse(tokenize(text, str(path)), spec_sha256)


# --- expressions ----------------------------------------------------------------------------


@dataclass(frozen=True)
class _Lexeme:
    """One word of an expression line: ``kind`` number, name or op; ``index`` is 0-based in the
    line (the column is index + 1)."""

    kind: str
    text: str
    index: int

    @property
    def end(self) -> int:
        return self.index + len(self.text)


@dataclass(frozen=True)
class _Parsed:
    """A parsed subexpression, its axes, its tree depth and where it lies in the line."""

    node: Expr
    axes: frozenset[str]
    depth: int
    start: int
    end: int


def _line_text(line: Line) -> str:
    """The line as written, comment removed, every character at its column (index column - 1);
    whitespace between tokens becomes spaces."""
    chars = [" "] * (line.end_column - 1)
    for token in line.tokens:
        chars[token.column - 1 : token.column - 1 + len(token.text)] = token.text
    return "".join(chars)


def _lex(path: str, line: Line, text: str, start: int) -> list[_Lexeme]:
    """The lexemes of ``text`` from index ``start``; a character that starts none is an error."""
    lexemes = []
    index = start
    while index < len(text):
        match = _LEXEME.match(text, index)
        if match is None:
            raise SpecError(
                path,
                line.number,
                index + 1,
                f"a number, a name, {_OPERATORS}, '=' or a parenthesis",
                text[index],
            )
        kind = match.lastgroup
        assert kind is not None
        if kind != "space":
            lexemes.append(_Lexeme(kind, match.group(), index))
        index = match.end()
    return lexemes


class _ExpressionParser:
    """Recursive descent over one line's lexemes from ``position``. ``name_axes``: the names the
    expression may use and their axes; ``names_expected``: what an unknown name's error expects;
    ``decorate``: whether ``TIME_DECORATED`` names may carry ``(t)``."""

    def __init__(
        self,
        path: str,
        line: Line,
        text: str,
        lexemes: list[_Lexeme],
        position: int,
        name_axes: dict[str, frozenset[str]],
        names_expected: str,
        decorate: bool,
    ):
        self.path = path
        self.line = line
        self.text = text
        self.lexemes = lexemes
        self.position = position
        self.name_axes = name_axes
        self.names_expected = names_expected
        self.decorate = decorate
        self.nesting = 0

    # --- cursor ---

    def peek(self) -> _Lexeme | None:
        return self.lexemes[self.position] if self.position < len(self.lexemes) else None

    def peek_is(self, text: str) -> bool:
        lexeme = self.peek()
        return lexeme is not None and lexeme.kind == "op" and lexeme.text == text

    def take(self) -> _Lexeme:
        lexeme = self.lexemes[self.position]
        self.position += 1
        return lexeme

    def error(self, lexeme: _Lexeme | None, expected: str) -> SpecError:
        """The error at ``lexeme`` (None: the end of the line)."""
        if lexeme is None:
            return SpecError(self.path, self.line.number, self.line.end_column, expected, None)
        return SpecError(self.path, self.line.number, lexeme.index + 1, expected, lexeme.text)

    def token(self, lexeme: _Lexeme) -> Token:
        return Token(lexeme.text, self.line.number, lexeme.index + 1)

    def enter(self, lexeme: _Lexeme) -> None:
        self.nesting += 1
        if self.nesting > MAX_DEPTH:
            raise self.error(lexeme, f"an expression nested at most {MAX_DEPTH} deep")

    def node(
        self, node: Expr, axes: Iterable[str], children: tuple[_Parsed, ...], start: int, end: int
    ) -> _Parsed:
        depth = 1 + max((child.depth for child in children), default=0)
        if depth > MAX_DEPTH:
            token = node.token
            raise SpecError(
                self.path,
                token.line,
                token.column,
                f"an expression nested at most {MAX_DEPTH} deep",
                token.text,
            )
        return _Parsed(node, frozenset(axes), depth, start, end)

    # --- grammar ---

    def expression(self) -> _Parsed:
        """The whole rest of the line."""
        parsed = self.comparison()
        lexeme = self.peek()
        if lexeme is not None:
            if lexeme.text == ")":
                raise self.error(lexeme, "end of line (this ')' closes no '(')")
            raise self.error(lexeme, f"{_OPERATORS} or end of line")
        return parsed

    def comparison(self) -> _Parsed:
        left = self.additive()
        if not self.peek_is("?="):
            return left
        operator = self.take()
        right = self.additive()
        if self.peek_is("?="):
            raise self.error(
                self.peek(), "no second '?=' (a ?= b ?= c is ambiguous: add parentheses)"
            )
        return self.binary(operator, left, right)

    def additive(self) -> _Parsed:
        left = self.multiplicative()
        while self.peek_is("+") or self.peek_is("-"):
            operator = self.take()
            left = self.binary(operator, left, self.multiplicative())
        return left

    def multiplicative(self) -> _Parsed:
        left = self.unary()
        while self.peek_is("*") or self.peek_is("/"):
            operator = self.take()
            left = self.binary(operator, left, self.unary())
        return left

    def binary(self, operator: _Lexeme, left: _Parsed, right: _Parsed) -> _Parsed:
        node = Binary(operator.text, left.node, right.node, self.token(operator))
        return self.node(node, left.axes | right.axes, (left, right), left.start, right.end)

    def unary(self) -> _Parsed:
        if not self.peek_is("-"):
            return self.primary()
        minus = self.take()
        self.enter(minus)
        operand = self.unary()
        self.nesting -= 1
        node = Unary("-", operand.node, self.token(minus))
        return self.node(node, operand.axes, (operand,), minus.index, operand.end)

    def close(self, opening: _Lexeme, what: str, comma: str | None = None) -> _Lexeme:
        """The ')' that closes ``opening`` (``what`` names it in errors; ``comma``, if given, is
        the error's expectation at a ',')."""
        lexeme = self.peek()
        if lexeme is None:
            raise self.error(None, f"')' to close {what} at column {opening.index + 1}")
        if lexeme.text == ")":
            return self.take()
        if lexeme.text == "," and comma is not None:
            raise self.error(lexeme, comma)
        raise self.error(
            lexeme, f"{_OPERATORS} or ')' to close {what} at column {opening.index + 1}"
        )

    def primary(self) -> _Parsed:
        lexeme = self.peek()
        if lexeme is None or lexeme.kind == "op" and lexeme.text != "(":
            raise self.error(lexeme, _OPERAND)
        self.take()
        if lexeme.kind == "number":
            value = float(lexeme.text)
            if not math.isfinite(value):
                raise self.error(lexeme, "a finite number")
            return self.node(Number(value, self.token(lexeme)), (), (), lexeme.index, lexeme.end)
        if lexeme.kind == "op":  # '('
            self.enter(lexeme)
            inner = self.comparison()
            closing = self.close(lexeme, "the '('")
            self.nesting -= 1
            return _Parsed(inner.node, inner.axes, inner.depth, lexeme.index, closing.end)
        name = lexeme.text
        if name in FUNCTIONS:
            return self.call(lexeme)
        if self.peek_is("(") and not (self.decorate and name in TIME_DECORATED):
            raise self.error(lexeme, f"a function before '(' (one of {_FUNCTION_NAMES})")
        if name not in self.name_axes:
            raise self.error(lexeme, self.names_expected)
        end = lexeme.end
        if self.peek_is("("):  # the paper's decoration: y_i(t)
            self.take()
            letter = self.peek()
            if letter is None or letter.text != "t":
                raise self.error(letter, f"'t' as in '{name}(t)'")
            self.take()
            closing = self.peek()
            if closing is None or closing.text != ")":
                raise self.error(closing, f"')' as in '{name}(t)'")
            end = self.take().end
        return self.node(
            Name(name, self.token(lexeme)), self.name_axes[name], (), lexeme.index, end
        )

    def call(self, function: _Lexeme) -> _Parsed:
        name = function.text
        opening = self.peek()
        if not self.peek_is("("):
            raise self.error(opening, f"'(' after {name}")
        assert opening is not None
        self.take()
        self.enter(opening)
        argument = self.comparison()
        closing = self.close(
            opening,
            f"'{name}('",
            f"')' to close '{name}(' at column {opening.index + 1} ({name} takes one argument)",
        )
        self.nesting -= 1
        axis = FUNCTIONS[name]
        if axis not in argument.axes:
            raise SpecError(
                self.path,
                self.line.number,
                argument.start + 1,
                f"{_AXIS_ARGUMENT[axis]} for {name}",
                self.text[argument.start : argument.end],
            )
        node = Call(name, argument.node, self.token(function))
        return self.node(node, argument.axes - {axis}, (argument,), function.index, closing.end)


# --- lines ----------------------------------------------------------------------------------


@dataclass
class _PhaseLine:
    line: int
    controller: str
    seed: int | None
    ticks: int | None
    token: Token


class _Parser:
    def __init__(self, path: str):
        self.path = path
        self.first_line: dict[str, int] = {}  # figure/total/search -> the line number of its line
        self.tokens: dict[str, Token] = {}
        self.figure = ""
        self.phases: dict[str, _PhaseLine] = {}
        self.scores: dict[str, tuple[int, Expr]] = {}  # phase -> (line, expression)
        self.total: Expr | None = None
        self.search = SearchSettings()

    def error(self, token: Token, expected: str) -> SpecError:
        return SpecError.at(self.path, token, expected)

    def parse(self, lines: list[Line], spec_sha256: str) -> CompositeScript:
        for line in lines:
            keyword = line.keyword
            if keyword.text not in KEYWORDS:
                raise unknown_keyword(line, KEYWORDS)
            if keyword.text in ("figure", "total", "search"):
                record_once(line, self.first_line)
            elif "total" in self.first_line:  # a phase or score line after the total
                raise self.error(
                    keyword,
                    f"no '{keyword.text}' line after the 'total' line "
                    f"(line {self.first_line['total']})",
                )
            getattr(self, f"line_{keyword.text}")(line)
        if "figure" not in self.first_line:
            raise missing_line(self.path, lines, "figure")
        if not self.phases:
            raise missing_line(self.path, lines, "phase")
        for name in self.phases:
            if name not in self.scores:
                raise SpecError(
                    self.path, lines[-1].number + 1, 1, f"a 'score {name} = ...' line", END_OF_FILE
                )
        if self.total is None:
            raise missing_line(self.path, lines, "total = ...")
        phases = tuple(
            Phase(
                name=name,
                controller=phase.controller,
                score=self.scores[name][1],
                seed=phase.seed,
                ticks=phase.ticks,
                token=phase.token,
            )
            for name, phase in self.phases.items()
        )
        return CompositeScript(
            path=self.path,
            figure=self.figure,
            phases=phases,
            total=self.total,
            search=self.search,
            spec_sha256=spec_sha256,
            tokens=self.tokens,
        )

    def line_figure(self, line: Line) -> None:
        token = figure_line(line)
        self.figure = token.text
        self.tokens["figure"] = token

    def line_phase(self, line: Line) -> None:
        reader = line.reader()
        token = reader.peek()
        name = reader.name("the phase")
        assert token is not None
        if name in FUNCTIONS:
            raise self.error(token, f"a phase name that is not a function ({_FUNCTION_NAMES})")
        if name in self.phases:
            raise self.error(
                token,
                f"a phase name not yet used ('{name}' is the phase of line "
                f"{self.phases[name].line})",
            )
        found = reader.key_values(_PHASE_KEYS)
        if "controller" not in found:
            raise SpecError(
                self.path,
                line.number,
                line.end_column,
                f"'controller=' ({_PHASE_KEYS['controller']})",
                None,
            )
        controller_token = value_token(found["controller"][0], "controller")
        controller = parse_name(controller_token, self.path, "controller= (a BSR search)")
        seed = ticks = None
        if "seed" in found:
            seed = parse_int(
                value_token(found["seed"][0], "seed"), self.path, "seed=", 0, MAX_INT64
            )
        if "ticks" in found:
            ticks = parse_int(
                value_token(found["ticks"][0], "ticks"), self.path, "ticks=", 1, MAX_INT64
            )
        if self.phases:
            first_name, first = next(iter(self.phases.items()))
            if first.ticks is not None and ticks is None:
                raise SpecError(
                    self.path,
                    line.number,
                    line.end_column,
                    f"'ticks=' (as on every phase: the first, '{first_name}' on line "
                    f"{first.line}, has it)",
                    None,
                )
            if first.ticks is None and ticks is not None:
                raise self.error(
                    found["ticks"][0],
                    f"end of line (ticks= is on every phase or none: the first, '{first_name}' "
                    f"on line {first.line}, has none)",
                )
        self.phases[name] = _PhaseLine(line.number, controller, seed, ticks, token)
        self.tokens[f"phase.{name}"] = token
        self.tokens[f"phase.{name}.controller"] = controller_token
        for key in ("seed", "ticks"):
            if key in found:
                self.tokens[f"phase.{name}.{key}"] = value_token(found[key][0], key)

    def expression_parser(
        self, line: Line, text: str, lexemes: list[_Lexeme], position: int, score: bool
    ) -> _ExpressionParser:
        if score:
            names = dict(SCORE_NAMES)
            expected = f"one of {', '.join(SCORE_NAMES)}"
        else:
            names = {name: frozenset() for name in self.phases}
            expected = f"a phase name, one of {', '.join(self.phases)}"
        return _ExpressionParser(
            self.path, line, text, lexemes, position, names, expected, decorate=score
        )

    def one_value(self, line: Line, parser: _ExpressionParser) -> Expr:
        """The expression after the parser's position, which must have one value."""
        parsed = parser.expression()
        if parsed.axes:
            raise SpecError(
                self.path,
                line.number,
                parsed.start + 1,
                _ONE_VALUE,
                parser.text[parsed.start : parsed.end],
            )
        return parsed.node

    def equals(self, line: Line, lexemes: list[_Lexeme], index: int, after: str) -> None:
        """Fail unless lexeme ``index`` is '='."""
        if index >= len(lexemes):
            raise SpecError(self.path, line.number, line.end_column, f"'=' after {after}", None)
        lexeme = lexemes[index]
        if lexeme.text != "=":
            raise SpecError(
                self.path, line.number, lexeme.index + 1, f"'=' after {after}", lexeme.text
            )

    def line_score(self, line: Line) -> None:
        text = _line_text(line)
        keyword = line.keyword
        lexemes = _lex(self.path, line, text, keyword.column - 1 + len(keyword.text))
        if not self.phases:
            expected = "a phase declared above (there is no 'phase' line yet)"
        else:
            expected = f"a phase declared above, one of {', '.join(self.phases)}"
        if not lexemes:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        first = lexemes[0]
        if first.kind != "name" or first.text not in self.phases:
            raise SpecError(self.path, line.number, first.index + 1, expected, first.text)
        name = first.text
        token = Token(name, line.number, first.index + 1)
        if name in self.scores:
            raise self.error(
                token, f"one 'score {name}' line only (the first is line {self.scores[name][0]})"
            )
        self.equals(line, lexemes, 1, f"'score {name}'")
        parser = self.expression_parser(line, text, lexemes, 2, score=True)
        self.scores[name] = (line.number, self.one_value(line, parser))
        self.tokens[f"score.{name}"] = token

    def line_total(self, line: Line) -> None:
        text = _line_text(line)
        keyword = line.keyword
        lexemes = _lex(self.path, line, text, keyword.column - 1 + len(keyword.text))
        self.equals(line, lexemes, 0, "'total'")
        parser = self.expression_parser(line, text, lexemes, 1, score=False)
        self.total = self.one_value(line, parser)
        self.tokens["total"] = keyword

    def line_search(self, line: Line) -> None:
        allowed = {
            key: f"a whole number >= {low} for {key}=" for key, (low, _) in _SEARCH_KEYS.items()
        }
        if len(line.tokens) == 1:
            choices = ", ".join(f"'{key}='" for key in allowed)
            raise SpecError(self.path, line.number, line.end_column, f"one of {choices}", None)
        found = line.reader().key_values(allowed)
        values = {
            key: parse_int(value_token(token, key), self.path, f"{key}=", *_SEARCH_KEYS[key])
            for key, (token, _) in found.items()
        }
        self.search = SearchSettings(**values)


# --- rendering ------------------------------------------------------------------------------

_PRECEDENCE = {"?=": 1, "+": 2, "-": 2, "*": 3, "/": 3}
_UNARY_PRECEDENCE = 4
_ATOM_PRECEDENCE = 5


def _precedence(expr: Expr) -> int:
    if isinstance(expr, Binary):
        return _PRECEDENCE[expr.op]
    if isinstance(expr, Unary) or isinstance(expr, Number) and math.copysign(1, expr.value) < 0:
        return _UNARY_PRECEDENCE
    return _ATOM_PRECEDENCE


def render_expression(expr: Expr) -> str:
    """The text of an expression with the fewest parentheses that keep its tree: parsing it
    gives back an equal tree (a negative ``Number`` comes back as ``Unary`` minus of its
    magnitude, with the same value)."""

    def wrapped(child: Expr, parenthesise: bool) -> str:
        text = render_expression(child)
        return f"({text})" if parenthesise else text

    if isinstance(expr, Number):
        text = format_number(abs(expr.value))
        return "-" + text if math.copysign(1, expr.value) < 0 else text
    if isinstance(expr, Name):
        return expr.name
    if isinstance(expr, Unary):
        return expr.op + wrapped(expr.operand, _precedence(expr.operand) < _UNARY_PRECEDENCE)
    if isinstance(expr, Call):
        return f"{expr.function}({render_expression(expr.argument)})"
    if isinstance(expr, Binary):
        level = _PRECEDENCE[expr.op]
        left_level, right_level = _precedence(expr.left), _precedence(expr.right)
        # left associative: a left operand of the same level needs none, except for '?='
        left = wrapped(expr.left, left_level < level or expr.op == "?=" and left_level == level)
        right = wrapped(expr.right, right_level <= level)
        return f"{left} {expr.op} {right}"
    raise TypeError(f"not an expression node: {expr!r}")


def render_composite_script(script: CompositeScript) -> str:
    """The ``.comp`` text of ``script``: parsing it gives back an equal CompositeScript (numbers
    in their shortest form). The search line is always written."""
    lines = [f"figure {script.figure}"]
    for phase in script.phases:
        text = f"phase {phase.name} controller={phase.controller}"
        if phase.seed is not None:
            text += f" seed={phase.seed}"
        if phase.ticks is not None:
            text += f" ticks={phase.ticks}"
        lines.append(text)
    for phase in script.phases:
        lines.append(f"score {phase.name} = {render_expression(phase.score)}")
    lines.append(f"total = {render_expression(script.total)}")
    search = script.search
    lines.append(f"search q={search.q} g={search.g} h={search.h} seed={search.seed}")
    return "\n".join(lines) + "\n"
