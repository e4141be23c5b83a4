"""Issue 27 for the BSR simulators, 2-D and 3-D: a run stops where the figure's state is not
sound (NaN, inf or beyond ±STATE_LIMIT: ``kernels.soundness.state_is_sound``) and returns
``blown_up(step)``; a search then aborts with NonFiniteStateError at the spec's ``simulate``
line (``mosys bsr-search``: exit 2, one line, no traceback, no output file), and a composite
motion at the line of the phase that was running."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import SPECS
from test_hostile_inputs import assert_refused, edited, mosys_command, where

from mosys.bsr.figure import bsr_figure
from mosys.bsr.figure3d import load_bsr_figure3d
from mosys.bsr.search import (
    RecordedRun,
    _Population,
    bind_search,
    controller_arrays,
    population_arrays,
    record_run,
    run_search,
)
from mosys.bsr.search3d import ChainStart, bind_search3d
from mosys.bsr.start import standing_state
from mosys.composite.session import CompositeSession
from mosys.errors import NonFiniteStateError
from mosys.kernels import bsr3d_controller, bsr3d_population, bsr_controller
from mosys.kernels.bsr3d_simulate import VY as VY_3D
from mosys.kernels.bsr_simulate import VY
from mosys.kernels.soundness import STATE_LIMIT, blown_up, state_is_sound, steps_before_blow_up
from mosys.parsing.bsr import FITNESS_TERMS, FITNESS_TERMS_3D, parse_bsr_text
from mosys.parsing.composite import parse_composite_text
from mosys.parsing.figure import parse_figure_spec
from mosys.parsing.tokens import Token

STARMAN = bsr_figure(parse_figure_spec(SPECS / "figures/starman.fig"))
CUJO = load_bsr_figure3d(SPECS / "figures", "test.bsr", Token("cujo", 1, 1))
PLANAR_SPEC = """\
figure starman
controller sense rules=3
simulate duration=0.5 dt=0.01
search controllers=3 generations=2 reseed=1
seeds 1
start torso=90 arm_a=45 arm_b=-45 leg_a=20 leg_b=-20
fitness distance=1 max_height=1
"""
SPATIAL_SPEC = """\
figure cujo
controller sense rules=3
simulate duration=0.5 dt=0.01 tau_min=0.03
search controllers=3 generations=2 reseed=1
seeds 1
start spine=0
fitness distance=1 sideways=-1 fall=-5
fall below=0.5
"""
STEPS = 50
DT = 0.01
# a dt= the parser takes (T / dt = 100 steps, tau from 2 dt to T / 4) under which the figure's
# velocity g dt, and then its position, overflow after the first step: 2-D and 3-D alike
HUGE_DT = "simulate duration=1e300 dt=1e298"
UNSOUND = [math.nan, math.inf, -1e300, 1.5 * STATE_LIMIT]


def planar():
    """The 2-D setup of PLANAR_SPEC, its first drawn controller, the nominal start (S,)."""
    setup = bind_search(parse_bsr_text(PLANAR_SPEC, "test.bsr"), STARMAN)
    controller = _Population(setup, np.random.default_rng(1)).controller(0)
    start = standing_state(STARMAN, setup.root_angle, setup.joints, setup.x)
    return setup, controller, start


def spatial():
    """The 3-D setup of SPATIAL_SPEC, its first drawn controller, the nominal start (S,)."""
    setup = bind_search3d(parse_bsr_text(SPATIAL_SPEC, "test.bsr"), CUJO)
    controller = _Population(setup, np.random.default_rng(1)).controller(0)
    return setup, controller, setup.simulation.start.copy()


def run_planar(start: np.ndarray, dt: float = DT) -> tuple[int, RecordedRun]:
    """The 2-D kernel's run of planar()'s controller from ``start``: (its return, its record)."""
    setup, controller, _ = planar()
    run = RecordedRun.empty(len(FITNESS_TERMS), STEPS, STARMAN, 2, start)
    taken = bsr_controller.run_controller(
        STARMAN.arrays,
        controller_arrays(controller),
        start,
        np.zeros(STARMAN.endpoints.shape[0]),
        False,
        STEPS,
        dt,
        setup.fall_endpoints,
        run.record(len(STARMAN.sense_names)),
    )
    return taken, run


def run_spatial(start: np.ndarray, dt: float = DT) -> tuple[int, RecordedRun]:
    """The 3-D kernel's run of spatial()'s controller from ``start``: (its return, its record)."""
    setup, controller, _ = spatial()
    run = RecordedRun.empty(len(FITNESS_TERMS_3D), STEPS, CUJO, 3, start)
    taken = bsr3d_controller.run_controller(
        CUJO.arrays,
        controller_arrays(controller),
        setup.simulation.task,
        start,
        np.zeros(CUJO.endpoints.shape[0]),
        False,
        STEPS,
        dt,
        run.record(len(CUJO.sense_names)),
    )
    return taken, run


RUNS = {"2-D": (planar, run_planar), "3-D": (spatial, run_spatial)}
VERTICAL_VELOCITY = {"2-D": VY, "3-D": VY_3D}  # the centre of mass's, in each state layout


# --- the kernels ------------------------------------------------------------------------------


@pytest.mark.parametrize("family", RUNS)
def test_a_sound_run_takes_every_step(family):
    make, run = RUNS[family]
    taken, record = run(make()[2])
    assert taken == STEPS
    assert np.isfinite(record.terms).all()
    assert state_is_sound(record.final_state)
    assert np.isfinite(record.com).all() and np.isfinite(record.rod_ends).all()


@pytest.mark.parametrize("value", UNSOUND)
@pytest.mark.parametrize("family", RUNS)
def test_an_unsound_start_stops_the_run_at_step_0(family, value):
    make, run = RUNS[family]
    start = make()[2]
    start[VERTICAL_VELOCITY[family]] = value
    taken, record = run(start)
    assert taken == blown_up(0) == -1 and steps_before_blow_up(taken) == 0
    assert np.isnan(record.terms).all()  # no fitness
    np.testing.assert_array_equal(record.final_state, start)  # the unsound state, as it came
    assert not record.com[1:].any()  # nothing stepped


@pytest.mark.parametrize("family", RUNS)
def test_a_huge_dt_stops_the_run_where_the_state_blows_up(family):
    make, run = RUNS[family]
    taken, record = run(make()[2], dt=1e298)
    stopped = steps_before_blow_up(taken)
    assert taken < 0 and stopped >= 1  # the start is sound: it blew up stepping
    assert not state_is_sound(record.final_state)
    assert np.isnan(record.terms).all()
    assert np.isfinite(record.com[:stopped]).all()  # the samples before it, sound


@pytest.mark.parametrize("family", RUNS)
def test_one_unsound_start_in_a_population_leaves_the_others_bit_for_bit(family):
    make, run = RUNS[family]
    setup, _, start = make()
    population = _Population(setup, np.random.default_rng(1))  # controller 0: make()'s
    c = setup.spec.controllers
    starts = np.repeat(start[None, :], c, axis=0)
    starts[1, 0] = math.nan
    steps = setup.spec.steps
    terms = np.zeros((c, len(setup.simulation.term_names)))
    taken = np.zeros(c, np.int64)
    final = np.empty_like(starts)
    senses = np.zeros((c, steps + 1, len(setup.figure.sense_names)))
    rules = np.zeros((c, steps + 1), np.int64)
    arrays = population_arrays(setup, population)
    if family == "2-D":
        bsr_controller.run_population(
            STARMAN.arrays, arrays, starts, steps, DT, setup.fall_endpoints, senses, rules,
            terms, taken, final,
        )  # fmt: skip
    else:
        bsr3d_population.run_population(
            CUJO.arrays, arrays, setup.simulation.task, starts, steps, DT, senses, rules, terms,
            taken, final,
        )  # fmt: skip
    assert taken.tolist() == [steps, -1, steps]
    assert np.isnan(terms[1]).all() and np.isnan(final[1, 0])
    alone = setup.simulation.record(setup, population.controller(0))
    np.testing.assert_array_equal(terms[0], alone.terms)
    np.testing.assert_array_equal(final[0], alone.final_state)


def test_a_recorded_run_from_an_unsound_start_raises_with_the_time_and_state():
    setup, controller, start = planar()
    start[VY] = math.inf
    with pytest.raises(NonFiniteStateError) as raised:
        record_run(STARMAN, controller, start, STEPS, DT)
    assert raised.value.t == 0.0
    np.testing.assert_array_equal(raised.value.state, start)
    assert str(raised.value) == (
        "the figure's state became non-finite at t = 0 s: cm_x=0 m, cm_y=0.911817 m, cm_vx=0 m/s, "
        "cm_vy=inf m/s, torso=90 deg, L=0 kg·m²/s, arm_a=45 deg, arm_b=-45 deg, leg_a=20 deg, "
        "leg_b=-20 deg, arm_a'=0 deg/s, arm_b'=0 deg/s, leg_a'=0 deg/s, leg_b'=0 deg/s; the "
        "start is not sound (a huge start or perturb value?)"
    )


# --- the search -------------------------------------------------------------------------------


def test_a_planar_search_from_a_huge_start_stops_at_its_simulate_line():
    text = PLANAR_SPEC.replace("leg_b=-20", "leg_b=-20 x=1e300")
    setup = bind_search(parse_bsr_text(text, "test.bsr"), STARMAN)
    with pytest.raises(NonFiniteStateError) as raised:
        run_search(setup, 1)
    assert raised.value.t == 0.0 and raised.value.state[0] == 1e300
    assert str(raised.value) == (
        "test.bsr:3:1: the figure's state lies beyond ±1e+150 (SI) at t = 0 s (seed 1, "
        "generation 0): cm_x=1e+300 m, cm_y=0.911817 m, cm_vx=0 m/s, cm_vy=0 m/s, torso=90 deg, "
        "L=0 kg·m²/s, arm_a=45 deg, arm_b=-45 deg, leg_a=20 deg, leg_b=-20 deg, arm_a'=0 deg/s, "
        "arm_b'=0 deg/s, leg_a'=0 deg/s, leg_b'=0 deg/s; the start is not sound (a huge start "
        "or perturb value?)"
    )


def test_a_spatial_search_continuing_a_nan_state_stops_at_its_simulate_line():
    _, _, start = spatial()
    start[VY_3D] = math.nan
    chain = ChainStart("before", 1, start, np.zeros(CUJO.endpoints.shape[0]))
    text = SPATIAL_SPEC.replace("start spine=0\n", "chain before\n")
    setup = bind_search3d(parse_bsr_text(text, "test.bsr"), CUJO, chain=chain)
    with pytest.raises(NonFiniteStateError) as raised:
        run_search(setup, 1)
    message = str(raised.value)
    assert message.startswith(
        "test.bsr:3:1: the figure's state became non-finite at t = 0 s (seed 1, generation 0): "
        "cm_x=0 m, cm_y="
    )
    assert ", cm_vy=nan m/s, " in message and ", q_w=1, " in message
    assert message.endswith("; the start is not sound (a huge start or perturb value?)")


def one_generation(spec: Path, tmp_path: Path):
    """``mosys bsr-search`` of ``spec``, seed 1, one generation, in a subprocess."""
    return mosys_command(
        "bsr-search", str(spec), "--seed", "1", "--figures", str(SPECS / "figures"),
        "--generations", "1", "-o", str(tmp_path / "seed1.h5"), cwd=tmp_path,
    )  # fmt: skip


def test_bsr_search_exits_2_when_the_figure_blows_up(tmp_path: Path) -> None:
    text = edited(
        SPECS / "bsr/starman_jump.bsr", "simulate duration=4 dt=0.01 tau_min=0.2", HUGE_DT
    )
    spec = tmp_path / "jump.bsr"
    spec.write_text(text)
    done = one_generation(spec, tmp_path)
    assert_refused(
        done,
        f"{spec}:{where(text, 'simulate')}: the figure's state became non-finite at t = 1e+298 s "
        "(seed 1, generation 0): cm_x=0 m, cm_y=-inf m, cm_vx=0 m/s, cm_vy=-2.81244e+286 m/s, "
        "torso=-inf deg, L=-5.6547e+286 kg·m²/s, arm_a=44.0877 deg, arm_b=-40.5885 deg, "
        "leg_a=17.8119 deg, leg_b=-17.3573 deg, arm_a'=-1.689e-298 deg/s, "
        "arm_b'=8.16697e-298 deg/s, leg_a'=-4.05076e-298 deg/s, leg_b'=4.89228e-298 deg/s; a "
        "smaller dt= may help",
        tmp_path,
    )


def test_bsr_search_exits_2_when_a_3d_figure_blows_up(tmp_path: Path) -> None:
    text = SPATIAL_SPEC.replace("simulate duration=0.5 dt=0.01 tau_min=0.03", HUGE_DT)
    spec = tmp_path / "walk.bsr"
    spec.write_text(text)
    done = one_generation(spec, tmp_path)
    assert_refused(
        done,
        f"{spec}:3:1: the figure's state became non-finite at t = 1e+298 s (seed 1, generation "
        "0): "
        "cm_x=-inf m, cm_y=-inf m, cm_z=inf m, cm_vx=-3.08359e+291 m/s, cm_vy=-8.417e+292 m/s,"
        " cm_vz=4.68199e+294 m/s, q_w=nan, q_x=nan, q_y=nan, q_z=nan, "
        "L_x=-1.30589e+295 kg·m²/s, L_y=1.84741e+288 kg·m²/s, L_z=-4.73087e+292 kg·m²/s, "
        "head=0.00726047 deg, head_turn=0 deg, tail=-0.291395 deg, tail_swing=0 deg, "
        "front_left=-0.115567 deg, front_left_swing=-0.0156968 deg, front_right=0.201265 deg, "
        "front_right_swing=-0.018589 deg, hind_left=0.0406118 deg, hind_left_swing=-0.0967194 "
        "deg, hind_right=0.2076 deg, hind_right_swing=0.00780881 deg, head'=1.34879e-300 deg/s,"
        " head_turn'=0 deg/s, tail'=-5.4133e-299 deg/s, tail_swing'=0 deg/s, "
        "front_left'=-2.14692e-299 deg/s, front_left_swing'=-2.91603e-300 deg/s, "
        "front_right'=3.73894e-299 deg/s, front_right_swing'=-3.45332e-300 deg/s, "
        "hind_left'=7.54455e-300 deg/s, hind_left_swing'=-1.79678e-299 deg/s, "
        "hind_right'=3.85663e-299 deg/s, hind_right_swing'=1.45066e-300 deg/s; a smaller dt= "
        "may help",
        tmp_path,
    )


# --- a composite motion -----------------------------------------------------------------------

COMPOSITE = """\
figure starman
phase first controller=starman_jump ticks=3
phase second controller=starman_jump ticks=5
score first = dcm_x
score second = dcm_x
total = first + second
"""


@pytest.mark.parametrize("ticks, phase, line", [((3, 5), "first", 2), ((0, 5), "second", 3)])
def test_a_composite_motion_that_blows_up_stops_at_its_phase_line(ticks, phase, line):
    _, controller, start = planar()
    session = CompositeSession(
        script=parse_composite_text(COMPOSITE, "show.comp"),
        figure=STARMAN,
        controllers=(controller, controller),
        seeds=(1, 1),
        controller_files=("seed1.h5", "seed1.h5"),
        start=start,
        dt=1e298,
        default_length=8,
    )
    with pytest.raises(NonFiniteStateError) as raised:
        session.score(ticks)
    message = str(raised.value)
    column = COMPOSITE.split("\n")[line - 1].index("=starman_jump") + 2  # the search's name
    assert message.startswith(f"show.comp:{line}:{column}: the figure's state ")
    during = f" at t = 1e+298 s (phase {phase}, durations {ticks[0]}, 5 ticks): cm_x="
    assert during in message
    assert message.endswith("; a smaller dt= may help")
    assert raised.value.t > 0 and not state_is_sound(raised.value.state)
