"""The .bsr grammar: the documented example, whole-message errors, hypothesis round trips and
fuzzing."""

from __future__ import annotations

import dataclasses
import hashlib
import string

import pytest
from conftest import SpecLines, parses_or_spec_error
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spec_fuzz import token_mutations

from mosys.parsing.bsr import (
    DEFAULT_FALL_BELOW,
    DEFAULT_SENSE_FILTER,
    FITNESS_TERMS,
    FITNESS_TERMS_3D,
    BsrSpec,
    Endpoint,
    Perturbation,
    parse_bsr_spec,
    parse_bsr_text,
    render_bsr_spec,
)
from mosys.parsing.tokens import SpecError, Token

EXAMPLE = """\
# luxo_hop: a sense-based controller that carries Luxo as far as it can
figure luxo                                  # the figure: specs/figures/luxo.fig
controller sense rules=8                     # R = 8 stimulus-response rules
simulate duration=4 dt=0.001                 # T = 4 s in steps of 1 ms (4000 steps)
search controllers=40 generations=200 reseed=25 reinitialize=0.25
seeds 1 2 3                                  # three independent searches
start x=0 base=0 hip=0 elbow=120             # the nominal start pose: m, degrees
perturb angle=2 joints=5 speed=0.05 spin=10  # half-widths: deg, deg, m/s, deg/s
fitness distance=1 max_height=0.5 fall=-10   # fitness term -> weight
fall upper.distal lower.distal               # the endpoints that must not touch the ground
"""
EXAMPLE_SHA256 = hashlib.sha256(EXAMPLE.encode()).hexdigest()
MINIMAL = """\
figure link1
controller time rules=3
simulate duration=2 dt=0.01
search controllers=2 generations=1 reseed=1
seeds 0
fitness rotations=1
"""


replace_line = SpecLines(EXAMPLE).replace
drop_line = SpecLines(EXAMPLE).drop


def test_example():
    spec = parse_bsr_text(EXAMPLE, "specs/bsr/luxo_hop.bsr")
    assert spec == BsrSpec(
        path="specs/bsr/luxo_hop.bsr",
        figure="luxo",
        kind="sense",
        rules=8,
        period=None,
        duration=4.0,
        dt=0.001,
        controllers=40,
        generations=200,
        reseed=25,
        reinitialize=0.25,
        seeds=(1, 2, 3),
        start={"x": 0.0, "base": 0.0, "hip": 0.0, "elbow": 120.0},
        perturbation=Perturbation(angle=2.0, joints=5.0, speed=0.05, spin=10.0),
        weights={"distance": 1.0, "max_height": 0.5, "fall": -10.0},
        fall=(Endpoint("upper", "distal"), Endpoint("lower", "distal")),
        spec_sha256=EXAMPLE_SHA256,
    )
    assert (spec.name, spec.steps) == ("luxo_hop", 4000)
    assert list(spec.start) == ["x", "base", "hip", "elbow"]  # file order
    assert spec.tokens == {
        "figure": Token("luxo", 2, 8),
        "start.x": Token("x=0", 7, 7),
        "start.base": Token("base=0", 7, 11),
        "start.hip": Token("hip=0", 7, 18),
        "start.elbow": Token("elbow=120", 7, 24),
        "fitness.distance": Token("distance=1", 9, 9),
        "fitness.max_height": Token("max_height=0.5", 9, 20),
        "fitness.fall": Token("fall=-10", 9, 35),
        "fall.0": Token("upper.distal", 10, 6),
        "fall.1": Token("lower.distal", 10, 19),
        "perturb": Token("perturb", 8, 1),
        "seeds": Token("seeds", 6, 1),
    }
    assert spec.fall[1].token == Token("lower.distal", 10, 19)


def test_defaults_and_a_time_controller():
    spec = parse_bsr_text(MINIMAL, "m.bsr")
    assert (spec.kind, spec.rules, spec.period) == ("time", 3, None)
    assert (spec.reinitialize, spec.start, spec.perturbation, spec.fall) == (
        0.5,
        {},
        Perturbation(),
        (),
    )
    assert not spec.perturbation.any
    assert spec.weights == {"rotations": 1.0}
    assert spec.steps == 200
    assert spec.tokens == {
        "figure": Token("link1", 1, 8),
        "fitness.rotations": Token("rotations=1", 6, 9),
        "seeds": Token("seeds", 5, 1),
    }
    assert render_bsr_spec(spec) == MINIMAL
    periodic = parse_bsr_text(
        MINIMAL.replace("rules=3", "period=0.5 rules=3") + "perturb spin=1e-3\n"
    )
    assert periodic.period == 0.5
    assert periodic.perturbation == Perturbation(spin=0.001)
    assert periodic.perturbation.any


def test_a_fall_line_without_a_fall_weight_is_allowed():
    spec = parse_bsr_text(MINIMAL + "fall torso.proximal\n")
    assert spec.fall == (Endpoint("torso", "proximal"),)
    assert "fall" not in spec.weights


def test_file(tmp_path):
    path = tmp_path / "luxo_hop.bsr"
    path.write_text(EXAMPLE)
    spec = parse_bsr_spec(path)
    assert (spec.path, spec.name, spec.spec_sha256) == (str(path), "luxo_hop", EXAMPLE_SHA256)
    missing = tmp_path / "missing.bsr"
    with pytest.raises(SpecError) as error:
        parse_bsr_spec(missing)
    assert str(error.value) == f"{missing}:1:1: expected an existing spec file, found no such file"
    path.write_text(EXAMPLE.replace("dt=0.001", "dt=-1"))
    with pytest.raises(SpecError) as error:
        parse_bsr_spec(path)
    assert str(error.value) == f"{path}:4:24: expected a number > 0 for dt= (s), found '-1'"


def test_render_example():
    spec = parse_bsr_text(EXAMPLE, "x.bsr")
    text = render_bsr_spec(spec)
    assert text == (
        "figure luxo\n"
        "controller sense rules=8\n"
        "simulate duration=4 dt=0.001\n"
        "search controllers=40 generations=200 reseed=25 reinitialize=0.25\n"
        "seeds 1 2 3\n"
        "start x=0 base=0 hip=0 elbow=120\n"
        "perturb angle=2 joints=5 speed=0.05 spin=10\n"
        "fitness distance=1 max_height=0.5 fall=-10\n"
        "fall upper.distal lower.distal\n"
    )
    assert parse_bsr_text(text, "x.bsr", EXAMPLE_SHA256) == spec


# --- errors: the whole message --------------------------------------------------------------

KEYWORDS = (
    "'figure', 'controller', 'simulate', 'search', 'seeds', 'start', 'perturb', 'fitness', 'fall', "
    "'chain'"
)
TERMS = (
    "TERM=WEIGHT, TERM a 2-D figure's fitness term (distance, max_height, contact_distance, "
    "rotations, fall) or a 3-D figure's (distance, sideways, heading_change, max_height, fall, "
    "heading_deviation, feet_distance, foot_steps, min_height, heading_sine, final_spin, "
    "net_rotation)"
)
FALL_LINE = (
    "a 'fall' line naming the endpoints whose ground contact the fall term measures "
    "(e.g. 'fall upper.distal')"
)
ERRORS = [
    # lines
    ("", "x.bsr:1:1: expected a 'figure' line, found end of file"),
    (
        replace_line(3, "controler sense rules=8"),
        f"x.bsr:3:1: expected one of {KEYWORDS}, found 'controler'",
    ),
    (drop_line(2), "x.bsr:10:1: expected a 'figure' line, found end of file"),
    (drop_line(3), "x.bsr:10:1: expected a 'controller' line, found end of file"),
    (drop_line(4), "x.bsr:10:1: expected a 'simulate' line, found end of file"),
    (drop_line(5), "x.bsr:10:1: expected a 'search' line, found end of file"),
    (drop_line(6), "x.bsr:10:1: expected a 'seeds' line, found end of file"),
    (drop_line(9), "x.bsr:10:1: expected a 'fitness' line, found end of file"),
    (
        EXAMPLE + "controller time rules=4\n",
        "x.bsr:11:1: expected one 'controller' line only (the first is line 3), found 'controller'",
    ),
    (
        EXAMPLE + "fall lower.proximal\n",
        "x.bsr:11:1: expected one 'fall' line only (the first is line 10), found 'fall'",
    ),
    (  # it said 'found end of line' at the start of a line that has one
        EXAMPLE + "chain walk\n",
        "x.bsr:7:1: expected no 'start' line in a search that continues 'walk' (it starts where "
        "that search's best motion ends), found 'start'",
    ),
    # figure
    (replace_line(2, "figure"), "x.bsr:2:7: expected a name for the figure, found end of line"),
    (
        replace_line(2, "figure luxo.fig"),
        "x.bsr:2:8: expected a name for the figure, found 'luxo.fig'",
    ),
    (replace_line(2, "figure luxo lamp"), "x.bsr:2:13: expected end of line, found 'lamp'"),
    # controller
    (
        replace_line(3, "controller random rules=8"),
        "x.bsr:3:12: expected a controller kind 'sense' or 'time', found 'random'",
    ),
    (
        replace_line(3, "controller rules=8"),
        "x.bsr:3:12: expected a controller kind 'sense' or 'time', found 'rules=8'",
    ),
    (
        replace_line(3, "controller"),
        "x.bsr:3:11: expected a controller kind 'sense' or 'time', found end of line",
    ),
    (
        replace_line(3, "controller sense"),
        "x.bsr:3:17: expected 'rules=' (a whole number >= 1 for rules=), found end of line",
    ),
    (
        replace_line(3, "controller sense rules=0"),
        "x.bsr:3:24: expected a whole number >= 1 for rules=, found '0'",
    ),
    (
        replace_line(3, "controller sense rules=2.5"),
        "x.bsr:3:24: expected a whole number for rules=, found '2.5'",
    ),
    (
        replace_line(3, "controller sense rules=8 period=2"),
        "x.bsr:3:26: expected end of line (period= is for a 'time' controller only), "
        "found 'period=2'",
    ),
    (
        replace_line(3, "controller time rules=8 period=0"),
        "x.bsr:3:32: expected a number > 0 for period= (s), found '0'",
    ),
    (
        replace_line(3, "controller time rules=8 period="),
        "x.bsr:3:32: expected a number > 0 for period= (s), found end of line",
    ),
    (
        replace_line(3, "controller time rules=8 tper=1"),
        "x.bsr:3:25: expected one of 'rules=', 'period=', 'filter=', found 'tper=1'",
    ),
    # simulate
    (
        replace_line(4, "simulate duration=4 dt=0.01 tau_min=0.01"),
        "x.bsr:4:37: expected a number from 2 dt (0.02) to below T/4 (1) for tau_min= (s), "
        "found '0.01'",
    ),
    (
        replace_line(4, "simulate duration=4 dt=0.003"),
        "x.bsr:4:24: expected a dt= (s) that divides duration=4 into whole steps "
        "(4 / 0.003 = 1333.33), found '0.003'",
    ),
    (
        replace_line(4, "simulate duration=4 dt=0.5"),
        "x.bsr:4:24: expected a number < 0.5 for dt= (s), so that Table 2's time-constant range "
        "[2 dt, T/4] is not empty, found '0.5'",
    ),
    (
        replace_line(4, "simulate duration=4 dt=8"),
        "x.bsr:4:24: expected a dt= (s) that divides duration=4 into whole steps "
        "(4 / 8 = 0.5), found '8'",
    ),
    (
        replace_line(4, "simulate duration=1e300 dt=1e-300"),
        "x.bsr:4:28: expected a dt= (s) that divides duration=1e+300 into whole steps "
        "(1e+300 / 1e-300 = not finite), found '1e-300'",
    ),
    (
        replace_line(4, "simulate duration=4"),
        "x.bsr:4:20: expected 'dt=' (a number > 0 for dt= (s)), found end of line",
    ),
    (
        replace_line(4, "simulate duration=-4 dt=0.001"),
        "x.bsr:4:19: expected a number > 0 for duration= (s), found '-4'",
    ),
    (
        replace_line(4, "simulate duration=4 dt=nan"),
        "x.bsr:4:24: expected a number for dt= (s), found 'nan'",
    ),
    (
        replace_line(4, "simulate 4 0.001"),
        "x.bsr:4:10: expected one of 'duration=', 'dt=', 'tau_min=', found '4'",
    ),
    # search
    (
        replace_line(5, "search controllers=40 generations=200 reseed=25 reinitialize=1.5"),
        "x.bsr:5:62: expected a number from 0 to 1 for reinitialize=, found '1.5'",
    ),
    (
        replace_line(5, "search controllers=1 generations=200 reseed=25"),
        "x.bsr:5:20: expected a whole number >= 2 for controllers=, found '1'",
    ),
    (
        replace_line(5, "search controllers=40 reseed=25"),
        "x.bsr:5:32: expected 'generations=' (a whole number >= 1 for generations=), "
        "found end of line",
    ),
    (
        replace_line(5, "search controllers=40 generations=200 reseed=25 reseed=5"),
        "x.bsr:5:49: expected 'reseed=' only once, found 'reseed=5'",
    ),
    # seeds
    (
        replace_line(6, "seeds 1 2 1"),
        "x.bsr:6:11: expected distinct seeds (1 is already at column 7), found '1'",
    ),
    (
        replace_line(6, "seeds"),
        "x.bsr:6:6: expected a whole number >= 0 for a seed, found end of line",
    ),
    (
        replace_line(6, "seeds 1 -2"),
        "x.bsr:6:9: expected a whole number >= 0 for a seed, found '-2'",
    ),
    (replace_line(6, "seeds 1 two"), "x.bsr:6:9: expected a whole number for a seed, found 'two'"),
    # start
    (
        replace_line(7, "start"),
        "x.bsr:7:6: expected a start coordinate 'name=value' (m for x and y, degrees for "
        "angles), found end of line",
    ),
    (
        replace_line(7, "start hip 0"),
        "x.bsr:7:7: expected a start coordinate 'name=value' (m for x and y, degrees for "
        "angles), found 'hip'",
    ),
    (replace_line(7, "start 1x=0"), "x.bsr:7:7: expected a coordinate name before '=', found '1x'"),
    (replace_line(7, "start hip=0 hip=1"), "x.bsr:7:13: expected 'hip=' only once, found 'hip=1'"),
    (replace_line(7, "start hip=up"), "x.bsr:7:11: expected a number for start hip=, found 'up'"),
    # perturb
    (
        replace_line(8, "perturb"),
        "x.bsr:8:8: expected one of 'angle=', 'joints=', 'speed=', 'spin=', found end of line",
    ),
    (
        replace_line(8, "perturb angle=-2"),
        "x.bsr:8:15: expected a number >= 0 for angle= (deg), found '-2'",
    ),
    (
        replace_line(8, "perturb velocity=1"),
        "x.bsr:8:9: expected one of 'angle=', 'joints=', 'speed=', 'spin=', found 'velocity=1'",
    ),
    # fitness
    (
        replace_line(9, "fitness distance=1 height=0.5"),
        f"x.bsr:9:20: expected {TERMS}, found 'height=0.5'",
    ),
    (
        replace_line(9, "fitness distance=far"),
        "x.bsr:9:18: expected a number for distance= (weight), found 'far'",
    ),
    (
        replace_line(9, "fitness distance=1e999"),
        "x.bsr:9:18: expected a finite number for distance= (weight), found '1e999'",
    ),
    (  # a fitness that overflowed, or learning curves no plot could scale
        replace_line(9, "fitness distance=1 max_height=-1.7e308"),
        "x.bsr:9:31: expected a number from -1e+06 to 1e+06 for max_height= (weight), found "
        "'-1.7e308'",
    ),
    (replace_line(9, "fitness"), f"x.bsr:9:8: expected {TERMS}, found end of line"),
    (
        replace_line(9, "fitness fall=1 fall=2"),
        "x.bsr:9:16: expected 'fall=' only once, found 'fall=2'",
    ),
    (drop_line(10), f"x.bsr:9:35: expected {FALL_LINE}, found 'fall=-10'"),
    # fall
    (
        replace_line(10, "fall torso.middle"),
        "x.bsr:10:12: expected 'proximal' or 'distal' after 'torso.', found 'middle'",
    ),
    (
        replace_line(10, "fall torso"),
        "x.bsr:10:6: expected an endpoint 'rod.proximal' or 'rod.distal' (or below=FRACTION, "
        "3-D), found 'torso'",
    ),
    (
        replace_line(10, "fall"),
        "x.bsr:10:5: expected an endpoint 'rod.proximal' or 'rod.distal' (or below=FRACTION, "
        "3-D), found end of line",
    ),
    (replace_line(10, "fall .distal"), "x.bsr:10:6: expected a rod name before '.', found ''"),
    (
        replace_line(10, "fall upper.distal.x"),
        "x.bsr:10:12: expected 'proximal' or 'distal' after 'upper.', found 'distal.x'",
    ),
    (
        replace_line(10, "fall upper.distal lower.distal upper.distal"),
        "x.bsr:10:32: expected each endpoint once ('upper.distal' is at column 6), "
        "found 'upper.distal'",
    ),
]


@pytest.mark.parametrize(("text", "message"), ERRORS)
def test_error_messages(text, message):
    with pytest.raises(SpecError) as error:
        parse_bsr_text(text, "x.bsr")
    assert str(error.value) == message


# --- hypothesis -----------------------------------------------------------------------------

WORDS = [
    *("figure", "controller", "simulate", "search", "seeds", "start", "perturb", "fitness"),
    *("fall", "sense", "time", "luxo", "rules=8", "period=1", "period=0", "dt=0.001", "dt=3"),
    *("duration=4", "controllers=2", "generations=1", "reseed=1", "reinitialize=2", "1", "-1"),
    *("hip=0", "angle=1", "distance=1", "fall=-1", "upper.distal", "torso.middle", ".", "="),
    *("x=", "=1", "#", "0", "1e999", "nan", "inf", "rules=99999999999999999999"),
]
garbage = st.one_of(
    st.sampled_from(WORDS),
    st.text(st.characters(codec="utf-8"), min_size=1, max_size=8),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.tuples(st.sampled_from(["dt", "duration", "period", "rules", "distance"]), st.floats()).map(
        lambda pair: f"{pair[0]}={pair[1]!r}"
    ),
)
FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def sound_and_round_trips(spec: BsrSpec) -> None:
    """What a spec the parser accepts satisfies, and it reads back from its rendering."""
    assert spec.steps >= 9 and 2 * spec.dt < spec.duration / 4
    assert ("fall" in spec.weights) <= bool(spec.fall)
    again = parse_bsr_text(render_bsr_spec(spec), "fuzz.bsr", spec.spec_sha256)
    assert again == spec


@FAST
@given(st.text())
def test_any_text_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_bsr_text, text, "fuzz.bsr", sound_and_round_trips)


@FAST
@given(st.lists(st.lists(garbage, max_size=6).map(" ".join), max_size=10).map("\n".join))
def test_keyword_soup_parses_or_raises_spec_error(text):
    parses_or_spec_error(parse_bsr_text, text, "fuzz.bsr", sound_and_round_trips)


@FAST
@given(token_mutations(st.sampled_from([EXAMPLE, MINIMAL]), garbage))
def test_mutated_specs_parse_or_raise_spec_error(text):
    parses_or_spec_error(parse_bsr_text, text, "fuzz.bsr", sound_and_round_trips)


IDENTIFIERS = st.tuples(
    st.sampled_from(string.ascii_letters + "_"),
    st.text(string.ascii_letters + string.digits + "_", max_size=6),
).map("".join)
NUMBERS = st.floats(allow_nan=False, allow_infinity=False)
POSITIVE = st.floats(min_value=1e-9, max_value=1e6)
NON_NEGATIVE = st.floats(min_value=0, max_value=1e6)
WEIGHTS = st.floats(min_value=-1e6, max_value=1e6)  # parsing.bsr.MAX_WEIGHT
WHOLE = st.integers(1, 10**6)


@st.composite
def bsr_specs(draw) -> BsrSpec:
    kind = draw(st.sampled_from(["sense", "time"]))
    dt = draw(st.floats(min_value=1e-6, max_value=1.0))
    duration = draw(st.integers(9, 10**6)) * dt
    terms = draw(
        st.lists(st.sampled_from(FITNESS_TERMS + FITNESS_TERMS_3D), min_size=1, unique=True)
    )
    endpoints = st.builds(Endpoint, IDENTIFIERS, st.sampled_from(["proximal", "distal"]))
    fall = draw(st.lists(endpoints, min_size=1 if "fall" in terms else 0, max_size=4, unique=True))
    chain = draw(st.just("") | IDENTIFIERS)
    return BsrSpec(
        path="generated.bsr",
        figure=draw(IDENTIFIERS),
        kind=kind,
        rules=draw(WHOLE),
        period=draw(st.none() | POSITIVE) if kind == "time" else None,
        duration=duration,
        dt=dt,
        controllers=draw(st.integers(2, 10**6)),
        generations=draw(WHOLE),
        reseed=draw(WHOLE),
        reinitialize=draw(st.just(0.5) | st.floats(0, 1)),
        seeds=tuple(draw(st.lists(st.integers(0, 2**63 - 1), min_size=1, max_size=5, unique=True))),
        start={} if chain else draw(st.dictionaries(IDENTIFIERS, NUMBERS, max_size=5)),
        perturbation=Perturbation(*(draw(st.just(0.0) | NON_NEGATIVE) for _ in range(4))),
        weights={term: draw(WEIGHTS) for term in terms},
        fall=tuple(fall),
        tau_min=draw(st.none() | st.floats(2 * dt, duration / 4, exclude_max=True)),
        fall_below=draw(st.just(DEFAULT_FALL_BELOW) | st.floats(0, 1)),
        sense_filter=draw(st.just(DEFAULT_SENSE_FILTER) | NON_NEGATIVE)
        if kind == "sense"
        else DEFAULT_SENSE_FILTER,
        chain=chain,
    )


@FAST
@given(bsr_specs())
def test_render_then_parse_round_trips(spec):
    text = render_bsr_spec(spec)
    digest = hashlib.sha256(text.encode()).hexdigest()
    parsed = parse_bsr_text(text, "generated.bsr")
    assert parsed == dataclasses.replace(spec, spec_sha256=digest)
    assert render_bsr_spec(parsed) == text
    assert set(parsed.tokens) == (
        {"figure", "seeds"}
        | {f"start.{name}" for name in spec.start}
        | {f"fitness.{term}" for term in spec.weights}
        | {f"fall.{i}" for i in range(len(spec.fall))}
        | ({"perturb"} if spec.perturbation.any else set())
        | ({"chain"} if spec.chain else set())
        | ({"filter"} if spec.sense_filter != DEFAULT_SENSE_FILTER else set())
        | ({"fall.below"} if spec.fall_below != DEFAULT_FALL_BELOW else set())
    )
    for i, endpoint in enumerate(parsed.fall):
        assert parsed.tokens[f"fall.{i}"] == endpoint.token
        assert endpoint.token.text == f"{endpoint.rod}.{endpoint.end}"


def test_a_seed_of_thousands_of_digits_is_a_spec_error():
    text = EXAMPLE.replace("seeds 1 2 3", "seeds " + "9" * 5000)
    with pytest.raises(SpecError) as error:
        parse_bsr_text(text, "x.bsr")
    assert str(error.value) == (
        "x.bsr:6:7: expected a whole number of fewer digits for a seed, found "
        f"'{'9' * 200}'... (5,000 characters)"
    )


def test_a_spec_naming_a_figure_unfit_for_bsr_is_refused_at_its_figure_line(tmp_path):
    """A .bsr naming the pendulum: the error pointed at the sound link1.fig, as if it were
    wrong, not at the spec's choice."""
    from pathlib import Path

    from mosys.bsr.figure import load_rod_figure

    figures = Path(__file__).resolve().parents[1] / "specs" / "figures"
    token = Token("link1", 4, 8)
    with pytest.raises(SpecError) as error:
        load_rod_figure(figures, "x.bsr", token)
    assert str(error.value) == (
        f"x.bsr:4:8: expected a BSR figure, found 'link1' ({figures / 'link1.fig'}:11:5: "
        "expected a 'free' root, as BSR figures fly and fall, found 'link')"
    )


def test_a_composite_naming_a_3d_figure_is_refused_at_its_figure_line():
    """It was refused at the sound cujo.fig, naming an internal module (bsr.figure3d)."""
    from pathlib import Path

    from mosys.bsr.figure import load_bsr_figure

    figures = Path(__file__).resolve().parents[1] / "specs" / "figures"
    with pytest.raises(SpecError) as error:
        load_bsr_figure(figures, "x.comp", Token("cujo", 3, 8))
    assert str(error.value) == (
        "x.comp:3:8: expected a planar figure (composite motion is 2-D; 'cujo' is 3-D), "
        "found 'cujo'"
    )


@pytest.mark.parametrize(
    ("kernel", "terms"),
    [
        ("mosys.kernels.bsr_controller", FITNESS_TERMS),
        ("mosys.kernels.bsr3d_controller", FITNESS_TERMS_3D),
    ],
)
def test_the_kernels_term_columns_are_the_parsers_terms_in_order(kernel, terms):
    """The kernels may not import the parser (layers), so each numbers its terms_out columns
    itself; the searches size terms_out by the parser's list, and numba does not check bounds:
    a column the parser's list lacked would be written past the array's end."""
    import importlib

    module = importlib.import_module(kernel)
    assert len(terms) == module.TERM_COUNT
    assert [getattr(module, term.upper()) for term in terms] == list(range(len(terms)))
