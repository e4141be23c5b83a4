"""The .comp grammar and its expressions (the 1995 paper's Table 4): the example, evaluation on
a hand-made motion, whole-message errors, hypothesis round trips against an independent
reference evaluator, and fuzzing."""

from __future__ import annotations

import hashlib
import math
import string
from pathlib import Path

import numpy as np
import pytest
from conftest import SpecLines, parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations

import mosys.parsing.composite
from mosys.composite.evaluate import (
    PhaseMotion,
    evaluate_score,
    evaluate_total,
    falloff,
    score_script,
)
from mosys.parsing.composite import (
    MAX_DEPTH,
    parse_composite_script,
    parse_composite_text,
    render_composite_script,
    render_expression,
)
from mosys.parsing.composite_script import (
    FUNCTIONS,
    Binary,
    Call,
    CompositeScript,
    Name,
    Number,
    Phase,
    SearchSettings,
    Unary,
)
from mosys.parsing.tokens import MAX_INT64, SpecError, Token

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = """\
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
"""
EXAMPLE_SHA256 = hashlib.sha256(EXAMPLE.encode()).hexdigest()
MINIMAL = """\
figure starman
phase only controller=starman_shuffle
score only = dcm_x
total = only
"""


replace_line = SpecLines(EXAMPLE).replace
drop_line = SpecLines(EXAMPLE).drop
insert_line = SpecLines(EXAMPLE).insert


def held(seconds: float) -> Binary:
    """``dtime ?= seconds``."""
    return Binary("?=", Name("dtime"), Number(seconds))


TABLE_4 = CompositeScript(
    path="specs/composite/starman_show.comp",
    figure="starman",
    phases=(
        Phase(
            "cartwheel",
            "starman_cartwheel_robust",
            Binary("*", Name("dcm_x"), held(215.0)),
            ticks=215,
        ),
        Phase(
            "jump",
            "starman_jump_robust",
            Binary("*", Call("max_t", Call("min_i", Name("y_i"))), held(150.0)),
            ticks=150,
        ),
        Phase(
            "shuffle", "starman_shuffle_robust", Binary("*", Name("dcm_x"), held(100.0)), ticks=100
        ),
    ),
    total=Binary(
        "*",
        Binary(
            "*",
            Binary("+", Number(1.0), Name("cartwheel")),
            Binary("+", Number(1.0), Name("jump")),
        ),
        Binary("+", Number(1.0), Name("shuffle")),
    ),
    search=SearchSettings(q=16, g=16, h=4, seed=1),
)


def test_table_4():
    script = parse_composite_text(EXAMPLE, "specs/composite/starman_show.comp")
    assert script == TABLE_4
    assert script.spec_sha256 == EXAMPLE_SHA256
    assert (script.name, script.phase_names) == ("starman_show", ("cartwheel", "jump", "shuffle"))
    assert script.guessed_ticks == (215, 150, 100)
    assert script.search.simulations == 1024
    assert script.tokens == {
        "figure": Token("starman", 2, 8),
        "phase.cartwheel": Token("cartwheel", 3, 7),
        "phase.cartwheel.controller": Token("starman_cartwheel_robust", 3, 28),
        "phase.cartwheel.ticks": Token("215", 3, 59),
        "phase.jump": Token("jump", 4, 7),
        "phase.jump.controller": Token("starman_jump_robust", 4, 23),
        "phase.jump.ticks": Token("150", 4, 49),
        "phase.shuffle": Token("shuffle", 5, 7),
        "phase.shuffle.controller": Token("starman_shuffle_robust", 5, 26),
        "phase.shuffle.ticks": Token("100", 5, 55),
        "score.cartwheel": Token("cartwheel", 6, 7),
        "score.jump": Token("jump", 7, 7),
        "score.shuffle": Token("shuffle", 8, 7),
        "total": Token("total", 9, 1),
    }
    # every node keeps its token: 'score jump = max_t(min_i(y_i(t))) * (dtime ?= 150)'
    jump = script.phases[1].score
    assert jump.token == Token("*", 7, 35)
    assert jump.left.token == Token("max_t", 7, 14)
    assert jump.left.argument.token == Token("min_i", 7, 20)
    assert jump.left.argument.argument.token == Token("y_i", 7, 26)
    assert jump.right.token == Token("?=", 7, 44)
    assert jump.right.left.token == Token("dtime", 7, 38)
    assert jump.right.right.token == Token("150", 7, 47)
    assert script.total.right.left.token == Token("1.0", 9, 45)
    assert script.phases[0].token == Token("cartwheel", 3, 7)


def test_the_module_docstring_shows_the_example():
    doc = mosys.parsing.composite.__doc__
    assert "".join(f"    {line}\n" for line in EXAMPLE.splitlines()) in doc


def test_the_spec_in_the_repository_is_table_4(tmp_path):
    path = ROOT / "specs" / "composite" / "starman_show.comp"
    script = parse_composite_script(path)
    assert script == parse_composite_text(EXAMPLE, str(path))
    assert script.spec_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    missing = tmp_path / "missing.comp"
    with pytest.raises(SpecError) as error:
        parse_composite_script(missing)
    assert str(error.value) == f"{missing}:1:1: expected an existing spec file, found no such file"


def test_render_table_4():
    text = render_composite_script(parse_composite_text(EXAMPLE))
    assert text == (
        "figure starman\n"
        "phase cartwheel controller=starman_cartwheel_robust ticks=215\n"
        "phase jump controller=starman_jump_robust ticks=150\n"
        "phase shuffle controller=starman_shuffle_robust ticks=100\n"
        "score cartwheel = dcm_x * (dtime ?= 215)\n"
        "score jump = max_t(min_i(y_i)) * (dtime ?= 150)\n"
        "score shuffle = dcm_x * (dtime ?= 100)\n"
        "total = (1 + cartwheel) * (1 + jump) * (1 + shuffle)\n"
        "search q=16 g=16 h=4 seed=1\n"
    )
    assert parse_composite_text(text, "specs/composite/starman_show.comp") == TABLE_4


def test_defaults_free_whitespace_and_seeds():
    script = parse_composite_text(MINIMAL, "m.comp")
    assert script.search == SearchSettings(16, 16, 4, 1)
    assert script.phases == (Phase("only", "starman_shuffle", Name("dcm_x")),)
    assert (script.phases[0].seed, script.guessed_ticks) == (None, None)
    text = MINIMAL.replace("dcm_x", "max_t ( min_i(y_i ( t )))/-2") + "search h=2 seed=0\n"
    text = text.replace("score only =", "score only=").replace("phase only", "phase only seed=3")
    script = parse_composite_text(text)
    assert script.phases[0].seed == 3
    assert script.phases[0].score == Binary(
        "/", Call("max_t", Call("min_i", Name("y_i"))), Unary("-", Number(2.0))
    )
    assert script.search == SearchSettings(16, 16, 2, 0)


# --- evaluation on a hand-made motion -------------------------------------------------------

# three samples, two endpoints
COM = [[0.0, 1.0], [0.5, 1.2], [2.0, 0.9]]
ENDS = [
    [[0.0, 0.0], [1.0, 0.5]],
    [[0.2, 0.3], [1.1, 0.8]],
    [[0.4, 0.1], [1.3, 0.2]],
]
MOTION = PhaseMotion(np.array(COM), np.array(ENDS), 120)


def score_of(text: str, motion: PhaseMotion = MOTION) -> float:
    script = parse_composite_text(f"figure f\nphase p controller=c\nscore p = {text}\ntotal = p\n")
    return evaluate_score(script.phases[0].score, motion)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("dcm_x", 2.0),
        ("dcm_y", 0.9 - 1.0),
        ("dtime", 120.0),
        ("max_t(min_i(y_i))", 0.3),  # per sample 0, 0.3, 0.1
        ("max_t(min_i(y_i(t)))", 0.3),
        ("min_i(max_t(y_i))", 0.3),  # per endpoint 0.3, 0.8
        ("max_i(min_t(y_i))", 0.2),  # per endpoint 0, 0.2
        ("min_t(min_i(x_i))", 0.0),
        ("max_t(max_i(x_i))", 1.3),
        ("max_t(cm_y)", 1.2),
        ("min_t(cm_x(t))", 0.0),
        ("max_t(cm_y - min_i(y_i))", 1.0),  # 1 - 0, 1.2 - 0.3, 0.9 - 0.1
        ("max_t(max_i(y_i - cm_y))", -0.4),  # endpoints below the centre of mass
        ("max_t(max_i(y_i)) - min_t(min_i(y_i))", 0.8),
        ("-dcm_x * 2 - 1", -5.0),
        ("1 - 2 - 3", -4.0),  # left associative
        ("2 * 3 + 4 * 5", 26.0),
        ("12 / 3 / 2", 2.0),
        ("-(1 + 2) * 3", -9.0),
        ("dtime ?= 120", 1.0),  # equal: 1
        ("dtime ?= 100", math.exp(-1.0)),  # w = 0.2 x 100 = 20, 120 is one w away
        ("80 ?= 100", math.exp(-1.0)),
        ("0.1 ?= 0", math.exp(-0.25)),  # w at least 0.2
        ("0 ?= -5", math.exp(-25.0)),  # w = 0.2 x |-5| = 1
        ("1 + 2 ?= 3", 1.0),  # ?= binds loosest
        ("(dtime ?= 100) * 2", 2 * math.exp(-1.0)),
        ("1 / 0", math.inf),
        ("-1 / 0", -math.inf),
    ],
)
def test_score_values(text, value):
    assert score_of(text) == pytest.approx(value, rel=1e-12, abs=1e-15)


def test_falloff_width_is_20_percent_of_the_target():
    assert falloff(np.array(159.0 + 31.8), np.array(159.0)) == pytest.approx(math.exp(-1.0))
    assert falloff(np.array(159.0 - 2 * 31.8), np.array(159.0)) == pytest.approx(math.exp(-4.0))
    assert falloff(np.array(159.0), np.array(159.0)) == 1.0
    assert math.isnan(score_of("0 / 0"))


def test_table_4_scores():
    cartwheel = PhaseMotion(np.array(COM), np.array(ENDS), 215)
    shuffle = PhaseMotion(np.array(COM) + [0.0, 0.0], np.array(ENDS), 120)
    jump = PhaseMotion(np.array(COM), np.array(ENDS), 150)
    scores, total = score_script(
        TABLE_4, {"cartwheel": cartwheel, "jump": jump, "shuffle": shuffle}
    )
    expected = {
        "cartwheel": 2.0,  # dcm_x = 2 at exactly 215 ticks
        "jump": 0.3,  # the lowest endpoint rises to 0.3 m, exactly 150 ticks
        "shuffle": 2.0 * math.exp(-1.0),  # 120 ticks, one w = 20 ticks off 100
    }
    assert list(scores) == ["cartwheel", "jump", "shuffle"]
    assert scores == pytest.approx(expected, rel=1e-12)
    assert total == pytest.approx(3.0 * 1.3 * (1.0 + 2.0 * math.exp(-1.0)), rel=1e-12)
    assert evaluate_total(TABLE_4.total, {"cartwheel": 1, "jump": 0.5, "shuffle": 2}) == 9.0
    with pytest.raises(KeyError) as error:
        score_script(TABLE_4, {"cartwheel": cartwheel, "jump": jump})
    assert error.value.args == ("no motion for the phases ['shuffle']",)


def test_phase_motion_checks_its_arrays():
    rod_ends = np.array(ENDS).reshape(3, 1, 2, 2)  # one rod: its proximal, then distal end
    motion = PhaseMotion.from_rod_ends(np.array(COM), rod_ends, 120)
    np.testing.assert_array_equal(motion.endpoints, np.array(ENDS))
    assert not motion.com.flags.writeable
    with pytest.raises(ValueError) as error:
        PhaseMotion(np.zeros((3, 3)), np.array(ENDS), 1)
    assert str(error.value) == "com must have shape (samples >= 1, 2), not (3, 3)"
    with pytest.raises(ValueError) as error:
        PhaseMotion(np.array(COM), np.array(ENDS)[:2], 1)
    assert str(error.value) == "endpoints has 2 samples and com 3: they differ"
    with pytest.raises(ValueError) as error:
        PhaseMotion(np.array(COM), np.array(ENDS), -1)
    assert str(error.value) == "ticks must be a whole number >= 0, not -1"
    one = PhaseMotion(np.array(COM)[:1], np.array(ENDS)[:1], 0)  # a phase of 0 ticks
    assert score_of("dcm_x + max_t(min_i(y_i))", one) == 0.0


def test_expressions_built_in_code_are_checked():
    with pytest.raises(ValueError) as error:
        evaluate_score(Name("y_i"), MOTION)
    assert str(error.value) == (
        "the expression keeps the axes ['i', 't']: reduce them to one value "
        "(min_i/max_i, min_t/max_t)"
    )
    with pytest.raises(ValueError) as error:
        evaluate_score(Name("foo"), MOTION)
    assert (
        str(error.value) == "unknown name 'foo' (known: dcm_x, dcm_y, dtime, x_i, y_i, cm_x, cm_y)"
    )
    with pytest.raises(ValueError) as error:
        evaluate_score(Call("max_t", Call("min_i", Name("cm_y"))), MOTION)
    assert str(error.value) == "min_i reduces axis 'i', which its argument lacks"
    with pytest.raises(ValueError) as error:
        evaluate_total(Name("cm_x"), {"a": 1.0})
    assert str(error.value) == "unknown name 'cm_x' (known: a)"
    with pytest.raises(ValueError) as error:
        Binary("**", Number(1), Number(2))
    assert str(error.value) == "binary operator '**' is not one of ('+', '-', '*', '/', '?=')"
    with pytest.raises(ValueError) as error:
        Call("mean_t", Name("y_i"))
    assert (
        str(error.value) == "function 'mean_t' is not one of ('max_t', 'min_t', 'max_i', 'min_i')"
    )
    # a negative number renders as a minus sign: the same value
    assert render_expression(Binary("*", Number(-2.0), Name("a"))) == "-2 * a"
    assert render_expression(Unary("-", Number(-2.0))) == "--2"


# --- errors: the whole message --------------------------------------------------------------

KEYWORDS = "'figure', 'phase', 'score', 'total', 'search'"
SCORE_NAMES = "dcm_x, dcm_y, dtime, x_i, y_i, cm_x, cm_y"
PHASES = "cartwheel, jump, shuffle"
FUNCTION_NAMES = "max_t, min_t, max_i, min_i"
ONE_VALUE = (
    "an expression with one value (reduce x_i/y_i with min_i/max_i and over time with min_t/max_t)"
)
OPERATORS = "an operator (+ - * / ?=)"
DEEP = "(" * (MAX_DEPTH + 1) + "1" + ")" * (MAX_DEPTH + 1)
LONG = "1" + "+1" * MAX_DEPTH
ERRORS = [
    # lines
    ("", "x.comp:1:1: expected a 'figure' line, found end of file"),
    (
        replace_line(2, "figures starman"),
        f"x.comp:2:1: expected one of {KEYWORDS}, found 'figures'",
    ),
    (drop_line(2), "x.comp:10:1: expected a 'figure' line, found end of file"),
    ("figure starman\ntotal = 1\n", "x.comp:3:1: expected a 'phase' line, found end of file"),
    (drop_line(8), "x.comp:10:1: expected a 'score shuffle = ...' line, found end of file"),
    (drop_line(6), "x.comp:10:1: expected a 'score cartwheel = ...' line, found end of file"),
    (drop_line(9), "x.comp:10:1: expected a 'total = ...' line, found end of file"),
    (
        EXAMPLE + "figure beryl\n",
        "x.comp:11:1: expected one 'figure' line only (the first is line 2), found 'figure'",
    ),
    (
        EXAMPLE + "total = 1\n",
        "x.comp:11:1: expected one 'total' line only (the first is line 9), found 'total'",
    ),
    (
        EXAMPLE + "search q=4\n",
        "x.comp:11:1: expected one 'search' line only (the first is line 10), found 'search'",
    ),
    (
        EXAMPLE + "phase encore controller=starman_shuffle_robust ticks=10\n",
        "x.comp:11:1: expected no 'phase' line after the 'total' line (line 9), found 'phase'",
    ),
    (
        drop_line(9).replace("score shuffle", "total = 1\nscore shuffle"),
        "x.comp:9:1: expected no 'score' line after the 'total' line (line 8), found 'score'",
    ),
    # figure
    (replace_line(2, "figure"), "x.comp:2:7: expected a name for the figure, found end of line"),
    (replace_line(2, "figure starman beryl"), "x.comp:2:16: expected end of line, found 'beryl'"),
    # phase
    (
        replace_line(4, "phase jump controler=starman_jump_robust ticks=90"),
        "x.comp:4:12: expected one of 'controller=', 'seed=', 'ticks=', "
        "found 'controler=starman_jump_robust'",
    ),
    (
        replace_line(4, "phase jump ticks=90"),
        "x.comp:4:20: expected 'controller=' (a name for controller= (a BSR search)), "
        "found end of line",
    ),
    (
        replace_line(4, "phase jump controller=results/bsr/starman_jump_robust ticks=90"),
        "x.comp:4:23: expected a name for controller= (a BSR search), "
        "found 'results/bsr/starman_jump_robust'",
    ),
    (
        replace_line(4, "phase jump controller= ticks=90"),
        "x.comp:4:23: expected a name for controller= (a BSR search), found end of line",
    ),
    (
        replace_line(4, "phase jump controller=starman_jump_robust ticks=90 seed=-1"),
        "x.comp:4:57: expected a whole number >= 0 for seed=, found '-1'",
    ),
    (
        replace_line(4, "phase jump controller=starman_jump_robust ticks=0"),
        "x.comp:4:49: expected a whole number >= 1 for ticks=, found '0'",
    ),
    (
        replace_line(4, "phase jump controller=starman_jump_robust ticks=1.5"),
        "x.comp:4:49: expected a whole number for ticks=, found '1.5'",
    ),
    (
        replace_line(4, "phase jump controller=starman_jump_robust ticks=90 ticks=91"),
        "x.comp:4:52: expected 'ticks=' only once, found 'ticks=91'",
    ),
    (
        replace_line(4, "phase controller=starman_jump_robust"),
        "x.comp:4:7: expected a name for the phase, found 'controller=starman_jump_robust'",
    ),
    (replace_line(4, "phase"), "x.comp:4:6: expected a name for the phase, found end of line"),
    (
        replace_line(4, "phase cartwheel controller=starman_jump_robust ticks=90"),
        "x.comp:4:7: expected a phase name not yet used ('cartwheel' is the phase of line 3), "
        "found 'cartwheel'",
    ),
    (
        replace_line(4, "phase max_t controller=starman_jump_robust ticks=90"),
        f"x.comp:4:7: expected a phase name that is not a function ({FUNCTION_NAMES}), "
        "found 'max_t'",
    ),
    (
        replace_line(4, "phase jump controller=starman_jump_robust"),
        "x.comp:4:42: expected 'ticks=' (as on every phase: the first, 'cartwheel' on line 3, "
        "has it), found end of line",
    ),
    (
        MINIMAL.replace("score", "phase two controller=c ticks=5\nscore"),
        "x.comp:3:24: expected end of line (ticks= is on every phase or none: the first, 'only' "
        "on line 2, has none), found 'ticks=5'",
    ),
    # score: the phase
    (
        replace_line(7, "score jmup = max_t(min_i(y_i)) * (dtime ?= 100)"),
        f"x.comp:7:7: expected a phase declared above, one of {PHASES}, found 'jmup'",
    ),
    (
        replace_line(7, "score 2 = 1"),
        f"x.comp:7:7: expected a phase declared above, one of {PHASES}, found '2'",
    ),
    (
        replace_line(7, "score"),
        f"x.comp:7:6: expected a phase declared above, one of {PHASES}, found end of line",
    ),
    (
        insert_line(3, "score cartwheel = dcm_x"),
        "x.comp:3:7: expected a phase declared above (there is no 'phase' line yet), "
        "found 'cartwheel'",
    ),
    (
        insert_line(7, "score cartwheel = dcm_x"),
        "x.comp:7:7: expected one 'score cartwheel' line only (the first is line 6), "
        "found 'cartwheel'",
    ),
    (
        replace_line(7, "score jump max_t(min_i(y_i))"),
        "x.comp:7:12: expected '=' after 'score jump', found 'max_t'",
    ),
    (
        replace_line(7, "score jump"),
        "x.comp:7:11: expected '=' after 'score jump', found end of line",
    ),
    (
        replace_line(7, "score jump ?= 1"),
        "x.comp:7:12: expected '=' after 'score jump', found '?='",
    ),
    # score: the expression
    (
        replace_line(6, "score cartwheel = dcm_x * (dtime ?= 159"),
        "x.comp:6:40: expected ')' to close the '(' at column 27, found end of line",
    ),
    (
        replace_line(6, "score cartwheel = dcm_x * (dtime ?= 159))"),
        "x.comp:6:41: expected end of line (this ')' closes no '('), found ')'",
    ),
    (
        replace_line(6, "score cartwheel = dcm_x) * (dtime ?= 159)"),
        "x.comp:6:24: expected end of line (this ')' closes no '('), found ')'",
    ),
    (
        replace_line(7, "score jump = max_t(min_i(y_i) * (dtime ?= 100)"),
        "x.comp:7:47: expected ')' to close 'max_t(' at column 19, found end of line",
    ),
    (
        replace_line(6, "score cartwheel = (dcm_x dtime)"),
        f"x.comp:6:26: expected {OPERATORS} or ')' to close the '(' at column 19, found 'dtime'",
    ),
    (
        replace_line(7, "score jump = max_t(min_i(y_i), 2)"),
        "x.comp:7:30: expected ')' to close 'max_t(' at column 19 (max_t takes one argument), "
        "found ','",
    ),
    (
        replace_line(7, "score jump = mean_t(min_i(y_i)) * (dtime ?= 100)"),
        f"x.comp:7:14: expected a function before '(' (one of {FUNCTION_NAMES}), found 'mean_t'",
    ),
    (
        replace_line(6, "score cartwheel = dcm_x(t)"),
        f"x.comp:6:19: expected a function before '(' (one of {FUNCTION_NAMES}), found 'dcm_x'",
    ),
    (
        replace_line(6, "score cartwheel = dcm_z * (dtime ?= 159)"),
        f"x.comp:6:19: expected one of {SCORE_NAMES}, found 'dcm_z'",
    ),
    (
        replace_line(6, "score cartwheel = jump"),
        f"x.comp:6:19: expected one of {SCORE_NAMES}, found 'jump'",
    ),
    (
        replace_line(7, "score jump = max_t"),
        "x.comp:7:19: expected '(' after max_t, found end of line",
    ),
    (
        replace_line(7, "score jump = max_t y_i"),
        "x.comp:7:20: expected '(' after max_t, found 'y_i'",
    ),
    (
        replace_line(7, "score jump = max_t(min_i(y_i(s)))"),
        "x.comp:7:30: expected 't' as in 'y_i(t)', found 's'",
    ),
    (
        replace_line(7, "score jump = max_t(min_i(y_i(t x)))"),
        "x.comp:7:32: expected ')' as in 'y_i(t)', found 'x'",
    ),
    (
        replace_line(7, "score jump = min_i(y_i) * (dtime ?= 100)"),
        f"x.comp:7:14: expected {ONE_VALUE}, found 'min_i(y_i) * (dtime ?= 100)'",
    ),
    (
        replace_line(7, "score jump =   y_i(t)   # the heights"),
        f"x.comp:7:16: expected {ONE_VALUE}, found 'y_i(t)'",
    ),
    (
        replace_line(7, "score jump = 1 + (cm_y)"),
        f"x.comp:7:14: expected {ONE_VALUE}, found '1 + (cm_y)'",
    ),
    (
        replace_line(7, "score jump = max_t(max_i(cm_y))"),
        "x.comp:7:26: expected an argument with rod endpoints (x_i or y_i, not yet reduced by "
        "min_i/max_i) for max_i, found 'cm_y'",
    ),
    (
        replace_line(7, "score jump = max_t(max_t(y_i))"),
        "x.comp:7:20: expected an argument with samples over time (x_i, y_i, cm_x or cm_y, not "
        "yet reduced by min_t/max_t) for max_t, found 'max_t(y_i)'",
    ),
    (
        replace_line(7, "score jump = min_t(dtime)"),
        "x.comp:7:20: expected an argument with samples over time (x_i, y_i, cm_x or cm_y, not "
        "yet reduced by min_t/max_t) for min_t, found 'dtime'",
    ),
    (
        replace_line(6, "score cartwheel = dcm_x ?= 1 ?= 2"),
        "x.comp:6:30: expected no second '?=' (a ?= b ?= c is ambiguous: add parentheses), "
        "found '?='",
    ),
    (
        replace_line(6, "score cartwheel = (dcm_x ?= 1 ?= 2)"),
        "x.comp:6:31: expected no second '?=' (a ?= b ?= c is ambiguous: add parentheses), "
        "found '?='",
    ),
    (
        replace_line(7, "score jump ="),
        "x.comp:7:13: expected a number, a name, '(' or '-', found end of line",
    ),
    (
        replace_line(7, "score jump = 1 +"),
        "x.comp:7:17: expected a number, a name, '(' or '-', found end of line",
    ),
    (
        replace_line(7, "score jump = * 2"),
        "x.comp:7:14: expected a number, a name, '(' or '-', found '*'",
    ),
    (
        replace_line(7, "score jump = +2"),
        "x.comp:7:14: expected a number, a name, '(' or '-', found '+'",
    ),
    (
        replace_line(7, "score jump = ()"),
        "x.comp:7:15: expected a number, a name, '(' or '-', found ')'",
    ),
    (
        replace_line(7, "score jump = dtime == 90"),
        "x.comp:7:20: expected an operator (+ - * / ?=) or end of line, found '='",
    ),
    (
        replace_line(7, "score jump = 2 $ 3"),
        "x.comp:7:16: expected a number, a name, an operator (+ - * / ?=), '=' or a parenthesis, "
        "found '$'",
    ),
    (
        replace_line(7, "score jump = dtime ? 90"),
        "x.comp:7:20: expected a number, a name, an operator (+ - * / ?=), '=' or a parenthesis, "
        "found '?'",
    ),
    (replace_line(7, "score jump = 1e999"), "x.comp:7:14: expected a finite number, found '1e999'"),
    (
        replace_line(7, "score jump = 2dtime"),
        f"x.comp:7:15: expected {OPERATORS} or end of line, found 'dtime'",
    ),
    (
        replace_line(7, "score jump = 1..2"),
        f"x.comp:7:16: expected {OPERATORS} or end of line, found '.2'",
    ),
    (
        replace_line(7, f"score jump = {DEEP}"),
        f"x.comp:7:{14 + MAX_DEPTH}: expected an expression nested at most {MAX_DEPTH} deep, "
        "found '('",
    ),
    (
        replace_line(7, "score jump = " + "-" * (MAX_DEPTH + 1) + "1"),
        f"x.comp:7:{14 + MAX_DEPTH}: expected an expression nested at most {MAX_DEPTH} deep, "
        "found '-'",
    ),
    (
        replace_line(7, f"score jump = {LONG}"),
        f"x.comp:7:{13 + 2 * MAX_DEPTH}: expected an expression nested at most {MAX_DEPTH} deep, "
        "found '+'",
    ),
    # total
    (
        replace_line(9, "total = (1.0 + cartwheel) * (1.0 + jumps)"),
        f"x.comp:9:36: expected a phase name, one of {PHASES}, found 'jumps'",
    ),
    (
        replace_line(9, "total = dcm_x"),
        f"x.comp:9:9: expected a phase name, one of {PHASES}, found 'dcm_x'",
    ),
    (
        replace_line(9, "total = max_t(jump)"),
        "x.comp:9:15: expected an argument with samples over time (x_i, y_i, cm_x or cm_y, not "
        "yet reduced by min_t/max_t) for max_t, found 'jump'",
    ),
    (
        replace_line(9, "total = jump(t)"),
        f"x.comp:9:9: expected a function before '(' (one of {FUNCTION_NAMES}), found 'jump'",
    ),
    (replace_line(9, "total (1 + jump)"), "x.comp:9:7: expected '=' after 'total', found '('"),
    (replace_line(9, "total"), "x.comp:9:6: expected '=' after 'total', found end of line"),
    (
        replace_line(9, "total= 1"),
        f"x.comp:9:1: expected one of {KEYWORDS}, found 'total='",
    ),
    # search
    (
        replace_line(10, "search"),
        "x.comp:10:7: expected one of 'q=', 'g=', 'h=', 'seed=', found end of line",
    ),
    (
        replace_line(10, "search q=0"),
        "x.comp:10:10: expected a whole number >= 1 for q=, found '0'",
    ),
    (
        replace_line(10, "search Q=16"),
        "x.comp:10:8: expected one of 'q=', 'g=', 'h=', 'seed=', found 'Q=16'",
    ),
    (
        replace_line(10, "search q=16 seed=-1"),
        "x.comp:10:18: expected a whole number >= 0 for seed=, found '-1'",
    ),
    # counts the kernels index, and seeds the result file stores as int64 (the verb fuzz wrote
    # seed=100000000000000000000: it searched, then failed to store it)
    (
        replace_line(10, "search g=2147483648"),
        "x.comp:10:10: expected a whole number from 1 to 2147483647 for g=, found '2147483648'",
    ),
    (
        replace_line(10, f"search seed={MAX_INT64 + 1}"),
        f"x.comp:10:13: expected a whole number from 0 to {MAX_INT64} for seed=, found "
        f"'{MAX_INT64 + 1}'",
    ),
    (
        replace_line(3, f"phase cartwheel controller=starman_cartwheel_robust ticks={2**63}"),
        f"x.comp:3:59: expected a whole number from 1 to {MAX_INT64} for ticks=, found '{2**63}'",
    ),
    (
        replace_line(3, f"phase cartwheel controller=starman_cartwheel_robust seed={2**64}"),
        f"x.comp:3:58: expected a whole number from 0 to {MAX_INT64} for seed=, found '{2**64}'",
    ),
    # a NUL, even in a comment: the result file keeps the text (HDF5 strings cannot hold one)
    (
        EXAMPLE.replace("a jump and", "a jump\x00 and"),
        "x.comp:1:62: expected text without NUL characters, found '\\x00'",
    ),
]


@pytest.mark.parametrize(("text", "message"), ERRORS)
def test_error_messages(text, message):
    with pytest.raises(SpecError) as error:
        parse_composite_text(text, "x.comp")
    assert str(error.value) == message


def test_the_deepest_allowed_expressions_parse():
    nested = "(" * MAX_DEPTH + "1" + ")" * MAX_DEPTH
    script = parse_composite_text(replace_line(7, f"score jump = {nested}"))
    assert script.phases[1].score == Number(1.0)
    long = "1" + "+1" * (MAX_DEPTH - 1)
    script = parse_composite_text(replace_line(7, f"score jump = {long}"))
    assert evaluate_score(script.phases[1].score, MOTION) == MAX_DEPTH


# --- hypothesis: an independent reference evaluator -----------------------------------------

FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SAMPLES, ENDPOINTS = range(len(COM)), range(len(ENDS[0]))
T, I = "t", "i"


def divide(a: float, b: float) -> float:
    """IEEE division, as numpy does it (Python raises at b == 0)."""
    if b != 0:
        return a / b
    if a == 0 or math.isnan(a):
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def reference_falloff(a: float, b: float) -> float:
    width = 0.2 * (abs(b) if abs(b) > 1.0 or math.isnan(b) else 1.0)
    difference = divide(a - b, width)
    return float(np.exp(-(difference * difference)))


def extreme(values: list[float], largest: bool) -> float:
    if any(math.isnan(value) for value in values):
        return math.nan
    return max(values) if largest else min(values)


OPERATIONS = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": divide,
    "?=": reference_falloff,
}
# score names: a value at (sample s, endpoint e)
REFERENCE_NAMES = {
    "dcm_x": (frozenset(), lambda s, e: COM[-1][0] - COM[0][0]),
    "dcm_y": (frozenset(), lambda s, e: COM[-1][1] - COM[0][1]),
    "dtime": (frozenset(), lambda s, e: 120.0),
    "x_i": (frozenset({T, I}), lambda s, e: ENDS[s][e][0]),
    "y_i": (frozenset({T, I}), lambda s, e: ENDS[s][e][1]),
    "cm_x": (frozenset({T}), lambda s, e: COM[s][0]),
    "cm_y": (frozenset({T}), lambda s, e: COM[s][1]),
}
NUMBERS = st.one_of(
    st.sampled_from([0.0, 1.0, 0.5, 2.0, 90.0, 120.0, 159.0]),
    st.floats(min_value=0, max_value=1e6),
    st.floats(min_value=0, max_value=1e-3),
)


def reduction(function: str, argument):
    """The reference of ``function(argument)``: extreme over samples or endpoints."""
    largest = function.startswith("max")
    if function.endswith("_t"):
        return lambda s, e: extreme([argument(k, e) for k in SAMPLES], largest)
    return lambda s, e: extreme([argument(s, k) for k in ENDPOINTS], largest)


@st.composite
def typed_expressions(draw, axes: frozenset, depth: int, names: dict):
    """An expression whose value has exactly ``axes``, and its reference (s, e) -> value.
    ``names``: name -> (axes, reference); calls only where some name has an axis."""
    leaves = [name for name, (name_axes, _) in names.items() if name_axes == axes]
    has_axes = any(name_axes for name_axes, _ in names.values())
    reducible = [f for f, axis in FUNCTIONS.items() if axis not in axes and has_axes]
    kinds = (["number"] if not axes else []) + (["name"] if leaves else [])
    if depth > 0:
        kinds += ["unary", "binary"] + (["call"] if reducible else [])
    if not kinds:  # only the endpoint axis: reduce the time axis of x_i or y_i
        kinds = ["call"]
    kind = draw(st.sampled_from(kinds))
    if kind == "number":
        value = draw(NUMBERS)
        return Number(value), lambda s, e: value
    if kind == "name":
        name = draw(st.sampled_from(leaves))
        return Name(name), names[name][1]
    if kind == "unary":
        operand, reference = draw(typed_expressions(axes, depth - 1, names))
        return Unary("-", operand), lambda s, e: -reference(s, e)
    if kind == "binary":
        op = draw(st.sampled_from(list(OPERATIONS)))
        subsets = [frozenset(c) for c in ([], [T], [I], [T, I]) if frozenset(c) <= axes]
        other = draw(st.sampled_from(subsets))
        left_axes, right_axes = draw(st.sampled_from([(axes, other), (other, axes)]))
        left, left_ref = draw(typed_expressions(left_axes, depth - 1, names))
        right, right_ref = draw(typed_expressions(right_axes, depth - 1, names))
        operation = OPERATIONS[op]
        return Binary(op, left, right), lambda s, e: operation(left_ref(s, e), right_ref(s, e))
    function = draw(st.sampled_from(reducible))
    argument, reference = draw(
        typed_expressions(axes | {FUNCTIONS[function]}, max(depth - 1, 0), names)
    )
    return Call(function, argument), reduction(function, reference)


def same(actual: float, expected: float) -> bool:
    if math.isnan(expected):
        return math.isnan(actual)
    return actual == expected or math.isclose(actual, expected, rel_tol=1e-9, abs_tol=1e-12)


@FAST
@given(typed_expressions(frozenset(), 4, REFERENCE_NAMES))
def test_score_expressions_round_trip_and_match_the_reference(generated):
    expression, reference = generated
    text = render_expression(expression)
    script = parse_composite_text(f"figure f\nphase p controller=c\nscore p = {text}\ntotal = p\n")
    parsed = script.phases[0].score
    assert parsed == expression
    assert render_expression(parsed) == text
    assert same(evaluate_score(parsed, MOTION), reference(0, 0))


IDENTIFIERS = st.tuples(
    st.sampled_from(string.ascii_letters + "_"),
    st.text(string.ascii_letters + string.digits + "_", max_size=6),
).map("".join)
PHASE_NAMES = IDENTIFIERS.filter(lambda name: name not in FUNCTIONS)


@st.composite
def composite_scripts(draw) -> tuple[CompositeScript, dict, object]:
    """A script, made-up phase scores, and its total's reference value."""
    names = draw(st.lists(PHASE_NAMES, min_size=1, max_size=4, unique=True))
    with_ticks = draw(st.booleans())
    phases = tuple(
        Phase(
            name,
            draw(IDENTIFIERS),
            draw(typed_expressions(frozenset(), 3, REFERENCE_NAMES))[0],
            seed=draw(st.none() | st.integers(0, MAX_INT64)),
            ticks=draw(st.integers(1, 10**6)) if with_ticks else None,
        )
        for name in names
    )
    scores = {name: draw(st.floats(-1e3, 1e3)) for name in names}
    total_names = {
        name: (frozenset(), lambda s, e, value=value: value) for name, value in scores.items()
    }
    total, reference = draw(typed_expressions(frozenset(), 4, total_names))
    search = SearchSettings(
        *(draw(st.integers(1, 10**6)) for _ in range(3)), draw(st.integers(0, MAX_INT64))
    )
    script = CompositeScript("generated.comp", draw(IDENTIFIERS), phases, total, search)
    return script, scores, reference(0, 0)


@FAST
@given(composite_scripts())
def test_render_then_parse_round_trips(generated):
    script, scores, total = generated
    text = render_composite_script(script)
    parsed = parse_composite_text(text, "generated.comp")
    assert parsed == script
    assert parsed.spec_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert render_composite_script(parsed) == text
    assert same(evaluate_total(parsed.total, scores), total)
    assert set(parsed.tokens) >= {"figure", "total"} | {f"score.{n}" for n in parsed.phase_names}


# --- hypothesis: fuzzing --------------------------------------------------------------------

WORDS = [
    *("figure", "phase", "score", "total", "search", "starman", "cartwheel", "jump", "="),
    *("controller=x", "controller=", "seed=1", "ticks=0", "ticks=90", "q=0", "g=2", "h=", "?="),
    *("dcm_x", "dtime", "y_i", "y_i(t)", "max_t(", "min_i(", "mean_t(", "(", ")", "((", "))"),
    *("*", "/", "-", "+", ",", "1e999", "nan", "inf", "1.", ".5", "?", "==", "#", "max_t"),
    *("ticks=99999999999999999999", "(t)", "x_i", "cm_x", "-(", "1", "0", "*(", "?=("),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.text("()+-*/?=,.tie_0123456789", min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
)


def sound_and_round_trips(script: CompositeScript) -> None:
    """What a script the parser accepts satisfies, and it reads back from its rendering."""
    assert script.phases and all(phase.score is not None for phase in script.phases)
    again = parse_composite_text(render_composite_script(script), "fuzz.comp")
    assert again == script


@FAST
@given(st.text())
def test_any_text_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_composite_text, text, "fuzz.comp", sound_and_round_trips)


@FAST
@given(st.lists(st.lists(garbage, max_size=8).map(" ".join), max_size=10).map("\n".join))
def test_keyword_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_composite_text, text, "fuzz.comp", sound_and_round_trips)


@FAST
@given(token_mutations(st.sampled_from([EXAMPLE, MINIMAL]), garbage))
def test_mutated_table_4_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_composite_text, text, "fuzz.comp", sound_and_round_trips)
