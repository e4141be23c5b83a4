"""Scoring a composite motion with its script (the 1995 paper's Table 4): each phase's score
expression on that phase's samples, then the total on the phase scores.

The expression trees of ``composite.script`` are walked node by node with numpy; no user text is
ever handed to Python's ``eval``, ``exec`` or ``compile``. Values are float64 arrays of shape
(samples or 1, endpoints or 1): axis 0 is the time axis ``t``, axis 1 the endpoint axis ``i``,
a length-1 axis means the value does not vary along it, so arithmetic broadcasts by axis name
(``cm_y - y_i`` is each endpoint's height below the centre of mass, sample by sample). Division
by zero and overflow follow IEEE arithmetic (inf, nan) without warnings; ``max``/``min``
propagate nan.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from mosys.kernels.libm import exp_each
from mosys.parsing.composite_script import (
    ENDPOINT,
    FALLOFF_FRACTION,
    FUNCTIONS,
    SCORE_NAMES,
    Binary,
    Call,
    CompositeScript,
    Expr,
    Name,
    Number,
    Unary,
    expression_axes,
)

_AXIS_INDEX = {"t": 0, ENDPOINT: 1}


@dataclass(frozen=True, eq=False)
class PhaseMotion:
    """One phase of a composite motion: ``com`` (samples, 2) m, the figure's centre of mass;
    ``endpoints`` (samples, endpoints, 2) m, every rod endpoint (x, y); ``ticks``: the phase's
    duration in simulator ticks. The first sample is the phase's start (and, for a phase after
    the first, the previous phase's last sample); at least one sample."""

    com: np.ndarray
    endpoints: np.ndarray
    ticks: int

    def __post_init__(self):
        com = np.array(self.com, dtype=np.float64)
        endpoints = np.array(self.endpoints, dtype=np.float64)
        if com.ndim != 2 or com.shape[1] != 2 or com.shape[0] < 1:
            raise ValueError(f"com must have shape (samples >= 1, 2), not {com.shape}")
        if endpoints.ndim != 3 or endpoints.shape[2] != 2 or endpoints.shape[1] < 1:
            raise ValueError(
                f"endpoints must have shape (samples, endpoints >= 1, 2), not {endpoints.shape}"
            )
        if endpoints.shape[0] != com.shape[0]:
            raise ValueError(
                f"endpoints has {endpoints.shape[0]} samples and com {com.shape[0]}: they differ"
            )
        if int(self.ticks) != self.ticks or self.ticks < 0:
            raise ValueError(f"ticks must be a whole number >= 0, not {self.ticks!r}")
        com.flags.writeable = False
        endpoints.flags.writeable = False
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "endpoints", endpoints)
        object.__setattr__(self, "ticks", int(self.ticks))

    @classmethod
    def from_rod_ends(cls, com: np.ndarray, rod_ends: np.ndarray, ticks: int) -> PhaseMotion:
        """From the figure-motion layout: ``rod_ends`` (samples, rods, 2, 2) m, each rod's
        proximal then distal end, become (samples, 2 rods, 2) endpoints."""
        rod_ends = np.asarray(rod_ends, dtype=np.float64)
        if rod_ends.ndim != 4 or rod_ends.shape[2:] != (2, 2):
            raise ValueError(
                f"rod_ends must have shape (samples, rods, 2, 2), not {rod_ends.shape}"
            )
        return cls(com, rod_ends.reshape(rod_ends.shape[0], -1, 2), ticks)

    def values(self) -> dict[str, np.ndarray]:
        """Each score name's value, shaped (samples or 1, endpoints or 1)."""
        com, ends = self.com, self.endpoints
        return {
            "dcm_x": np.array([[com[-1, 0] - com[0, 0]]]),
            "dcm_y": np.array([[com[-1, 1] - com[0, 1]]]),
            "dtime": np.array([[float(self.ticks)]]),
            "x_i": ends[:, :, 0],
            "y_i": ends[:, :, 1],
            "cm_x": com[:, 0:1],
            "cm_y": com[:, 1:2],
        }


def falloff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a ?= b``: 1 where a == b, falling towards 0 as they differ, a Gaussian of width 20 % of
    the target b (at least 0.2): exp(-((a - b) / w)^2), w = 0.2 max(|b|, 1). One w apart gives
    exp(-1) = 0.37, two give 0.018; 159 ticks ?= 159 is 1, w = 31.8 ticks."""
    width = FALLOFF_FRACTION * np.maximum(np.abs(b), 1.0)
    return exp_each(-np.square((a - b) / width))


def _evaluate(expr: Expr, values: Mapping[str, np.ndarray]) -> np.ndarray:
    if isinstance(expr, Number):
        return np.array([[expr.value]], dtype=np.float64)
    if isinstance(expr, Name):
        return values[expr.name]
    if isinstance(expr, Unary):
        return -_evaluate(expr.operand, values)
    if isinstance(expr, Binary):
        left, right = _evaluate(expr.left, values), _evaluate(expr.right, values)
        if expr.op == "+":
            return left + right
        if expr.op == "-":
            return left - right
        if expr.op == "*":
            return left * right
        if expr.op == "/":
            return left / right
        return falloff(left, right)
    if isinstance(expr, Call):
        argument = _evaluate(expr.argument, values)
        axis = _AXIS_INDEX[FUNCTIONS[expr.function]]
        reduce = np.max if expr.function.startswith("max") else np.min
        return reduce(argument, axis=axis, keepdims=True)
    raise TypeError(f"not an expression node: {expr!r}")


def _one_value(
    expr: Expr, name_axes: Mapping[str, frozenset[str]], values: Mapping[str, np.ndarray]
) -> float:
    axes = expression_axes(expr, name_axes)
    if axes:
        raise ValueError(
            f"the expression keeps the axes {sorted(axes)}: reduce them to one value "
            "(min_i/max_i, min_t/max_t)"
        )
    with np.errstate(all="ignore"):
        result = _evaluate(expr, values)
    return float(result.reshape(-1)[0])


def evaluate_score(expr: Expr, motion: PhaseMotion) -> float:
    """A score expression's value on one phase's motion (names as ``SCORE_NAMES``). An
    expression that does not come to one value, or names something else, raises ValueError."""
    return _one_value(expr, SCORE_NAMES, motion.values())


def evaluate_total(expr: Expr, scores: Mapping[str, float]) -> float:
    """The total expression's value, its names being phases with these scores."""
    axes = {name: frozenset() for name in scores}
    values = {name: np.array([[float(score)]]) for name, score in scores.items()}
    return _one_value(expr, axes, values)


def score_script(
    script: CompositeScript, motions: Mapping[str, PhaseMotion]
) -> tuple[dict[str, float], float]:
    """Every phase's score (phase name -> score, in the script's order) and the total, from each
    phase's motion (phase name -> PhaseMotion; a missing phase raises KeyError)."""
    missing = [phase.name for phase in script.phases if phase.name not in motions]
    if missing:
        raise KeyError(f"no motion for the phases {missing}")
    scores = {
        phase.name: evaluate_score(phase.score, motions[phase.name]) for phase in script.phases
    }
    return scores, evaluate_total(script.total, scores)
