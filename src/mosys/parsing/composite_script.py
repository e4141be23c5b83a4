"""A parsed composite-motion script (``specs/composite/NAME.comp``, the 1995 paper's Table 4):
what ``parsing.composite`` produces and the transition-point search consumes.

A script names the figure, the phases in time order (each a BSR controller run for a number of
simulator ticks), one score expression per phase (the phase's credit) and a total expression
over the phases' scores, and the settings of Figure 5's search. Expressions are small trees of
frozen nodes (``Number``, ``Name``, ``Unary``, ``Binary``, ``Call``), each keeping the token it
was parsed from so that later checks can point at it.

Values carry named axes: ``t`` (one entry per sample of the phase) and ``i`` (one per rod
endpoint). ``x_i``/``y_i`` have both, ``cm_x``/``cm_y`` only ``t``, the rest none; ``min_t`` and
``max_t`` remove ``t``, ``min_i`` and ``max_i`` remove ``i``, arithmetic keeps the union of its
operands' axes. A score or total has no axis left: one value.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from mosys.parsing.tokens import Token

_NO_TOKEN = Token("", 0, 0)

TIME = "t"  # the samples of the phase
ENDPOINT = "i"  # the rod endpoints

# function -> the axis it reduces
FUNCTIONS = {"max_t": TIME, "min_t": TIME, "max_i": ENDPOINT, "min_i": ENDPOINT}
BINARY_OPERATORS = ("+", "-", "*", "/", "?=")
UNARY_OPERATORS = ("-",)
# the names a score expression may use -> their axes
SCORE_NAMES: dict[str, frozenset[str]] = {
    "dcm_x": frozenset(),  # the phase's horizontal displacement of the centre of mass, m
    "dcm_y": frozenset(),  # ... and vertical, m
    "dtime": frozenset(),  # the phase's duration, simulator ticks
    "x_i": frozenset({TIME, ENDPOINT}),  # rod endpoint positions, per sample and endpoint, m
    "y_i": frozenset({TIME, ENDPOINT}),
    "cm_x": frozenset({TIME}),  # the centre of mass per sample, m
    "cm_y": frozenset({TIME}),
}
# names that may carry the paper's decoration '(t)': y_i(t) is y_i
TIME_DECORATED = ("x_i", "y_i", "cm_x", "cm_y")
# a ?= b falls off as exp(-((a - b) / w)^2), w = FALLOFF_FRACTION * max(|b|, 1)
FALLOFF_FRACTION = 0.2

DEFAULT_Q = 16
DEFAULT_G = 16
DEFAULT_H = 4
DEFAULT_SEED = 1


@dataclass(frozen=True)
class Number:
    """A number as written (the parser gives values >= 0; a minus sign is a ``Unary``)."""

    value: float
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class Name:
    """A variable: a ``SCORE_NAMES`` entry in a score, a phase name in the total."""

    name: str
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class Unary:
    """``-operand``; the token is the minus sign."""

    op: str
    operand: Expr
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)

    def __post_init__(self):
        if self.op not in UNARY_OPERATORS:
            raise ValueError(f"unary operator {self.op!r} is not one of {UNARY_OPERATORS}")


@dataclass(frozen=True)
class Binary:
    """``left op right``, op one of + - * / ?=; the token is the operator."""

    op: str
    left: Expr
    right: Expr
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)

    def __post_init__(self):
        if self.op not in BINARY_OPERATORS:
            raise ValueError(f"binary operator {self.op!r} is not one of {BINARY_OPERATORS}")


@dataclass(frozen=True)
class Call:
    """``function(argument)``, function one of ``FUNCTIONS``; the token is the function's name."""

    function: str
    argument: Expr
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)

    def __post_init__(self):
        if self.function not in FUNCTIONS:
            raise ValueError(f"function {self.function!r} is not one of {tuple(FUNCTIONS)}")


Expr = Number | Name | Unary | Binary | Call


def expression_axes(expr: Expr, name_axes: Mapping[str, frozenset[str]]) -> frozenset[str]:
    """The axes of ``expr``'s value when each name has the axes ``name_axes`` gives it (an empty
    set: one value). An unknown name, or a reduction of an axis its argument lacks, raises
    ValueError (the parser reports these at their column; this is for expressions built in
    code)."""
    if isinstance(expr, Number):
        return frozenset()
    if isinstance(expr, Name):
        if expr.name not in name_axes:
            raise ValueError(f"unknown name {expr.name!r} (known: {', '.join(name_axes)})")
        return name_axes[expr.name]
    if isinstance(expr, Unary):
        return expression_axes(expr.operand, name_axes)
    if isinstance(expr, Binary):
        return expression_axes(expr.left, name_axes) | expression_axes(expr.right, name_axes)
    if isinstance(expr, Call):
        axes = expression_axes(expr.argument, name_axes)
        axis = FUNCTIONS[expr.function]
        if axis not in axes:
            raise ValueError(f"{expr.function} reduces axis {axis!r}, which its argument lacks")
        return axes - {axis}
    raise TypeError(f"not an expression node: {expr!r}")


@dataclass(frozen=True)
class Phase:
    """One phase of the composite motion: the BSR search ``controller`` (results/bsr/NAME/)
    run for ``ticks`` simulator ticks (the user's guess; None: equally spaced), with the
    controller of seed ``seed`` (None: the caller picks the best seed), scored by ``score``.
    ``token`` is the phase's name on its ``phase`` line."""

    name: str
    controller: str
    score: Expr
    seed: int | None = None
    ticks: int | None = None
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class SearchSettings:
    """Figure 5's sizes: ``q`` transition-point arrays, ``g`` generations, ``h`` mutations of
    each array per generation; ``seed`` seeds the search's random numbers."""

    q: int = DEFAULT_Q
    g: int = DEFAULT_G
    h: int = DEFAULT_H
    seed: int = DEFAULT_SEED

    @property
    def simulations(self) -> int:
        """Q x G x H: the mutants the search simulates (the paper: 1,024)."""
        return self.q * self.g * self.h


@dataclass(frozen=True)
class CompositeScript:
    """One ``.comp`` file: the figure (specs/figures/FIGURE.fig), the phases in time order, the
    total expression (its names are phase names) and the search settings. ``tokens`` keeps the
    token of each setting, keyed ``figure``, ``phase.NAME``, ``phase.NAME.controller``,
    ``phase.NAME.seed``, ``phase.NAME.ticks``, ``score.NAME`` (the phase name on the score line)
    and ``total`` (the keyword), so that later checks can point at the offending word."""

    path: str
    figure: str
    phases: tuple[Phase, ...]
    total: Expr
    search: SearchSettings = field(default_factory=SearchSettings)
    spec_sha256: str = field(default="", compare=False)
    tokens: dict[str, Token] = field(default_factory=dict, compare=False, repr=False)

    @property
    def name(self) -> str:
        """The script's name: the spec file's stem."""
        return Path(self.path).stem

    @property
    def phase_names(self) -> tuple[str, ...]:
        return tuple(phase.name for phase in self.phases)

    @property
    def guessed_ticks(self) -> tuple[int, ...] | None:
        """The user's guessed phase durations, ticks, or None (then equally spaced). The parser
        makes every phase have ``ticks=`` or none."""
        ticks = tuple(phase.ticks for phase in self.phases)
        return None if any(tick is None for tick in ticks) else ticks  # type: ignore[return-value]
