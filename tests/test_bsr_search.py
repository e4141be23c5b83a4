"""The serial search of Figure 3: Table 2's initial values, the relevance heuristic, creep inside
the ranges, reseeding, determinism whatever the number of threads, the result file contract, and
binding errors that name the spec's word."""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numba
import numpy as np
import pytest
from contract_check import bsr_result_problems

from mosys.bsr.figure import bsr_figure
from mosys.bsr.result_file import search_to_file
from mosys.bsr.search import CORNER_INSIDE, _Population, bind_search, run_search
from mosys.bsr.start import perturbed_state
from mosys.io.bsr_result import read_bsr_result
from mosys.kernels.bsr_controller import SIDE_MAX, SIDE_MIN, active_rule, rule_weights
from mosys.parsing.bsr import parse_bsr_text
from mosys.parsing.figure import parse_figure_spec
from mosys.parsing.tokens import SpecError

ROOT = Path(__file__).resolve().parents[1]
STARMAN = bsr_figure(parse_figure_spec(ROOT / "specs/figures/starman.fig"))
SPEC = """\
figure starman
controller sense rules=6
simulate duration=2 dt=0.01 tau_min=0.15
search controllers=6 generations=30 reseed=10
seeds 7 8
start torso=90 arm_a=45 arm_b=-45 leg_a=20 leg_b=-20
fitness distance=1 contact_distance=1
"""


def bound_search(text: str = SPEC, generations: int | None = None):
    return bind_search(parse_bsr_text(text, "test.bsr"), STARMAN, generations)


def test_initial_rules_follow_table_2():
    population = _Population(bound_search(), np.random.default_rng(0))
    figure = STARMAN
    assert np.all(population.target >= figure.joint_min) and np.all(
        population.target <= figure.joint_max
    )
    assert np.all(population.tau >= 0.15) and np.all(population.tau <= 2 / 4)
    assert np.all(population.side >= SIDE_MIN) and np.all(population.side <= SIDE_MAX)
    assert np.all(population.center >= -0.5) and np.all(population.center <= 1.5)
    # log-uniform sides: about half of them below the geometric mean of the range
    below = np.mean(population.side < math.sqrt(SIDE_MIN * SIDE_MAX))
    assert 0.4 < below < 0.6


@pytest.mark.parametrize("kind", ["sense", "time"])
@pytest.mark.parametrize("seed", [0, 1, 12345])
def test_the_first_rules_drawn_at_once_are_those_drawn_rule_by_rule(kind, seed):
    """``draw_first_rules`` draws every number in one call; the rules are bit for bit those of
    ``draw_rule`` called rule after rule from the same generator (a seed's search is unchanged)."""
    text = SPEC.replace("controller sense rules=6", f"controller {kind} rules=6")
    at_once = _Population(bound_search(text), np.random.default_rng(seed))
    by_rule = _Population(bound_search(text), np.random.default_rng(0))
    rng = np.random.default_rng(seed)
    for k in range(by_rule.tau.shape[0]):
        for i in range(by_rule.tau.shape[1]):
            by_rule.draw_rule(k, i, rng, None)
    for name in ("target", "tau", "center", "side", "segment"):
        assert np.array_equal(getattr(at_once, name), getattr(by_rule, name)), name


def test_a_reinitialised_rule_fires_at_a_corner_on_the_sense_trajectory():
    population = _Population(bound_search(), np.random.default_rng(1))
    senses = np.random.default_rng(2).uniform(0, 1, (201, len(STARMAN.sense_names)))
    population.draw_rule(3, 2, np.random.default_rng(3), senses)
    half = population.side[3, 2] / 2 * CORNER_INSIDE
    low = population.center[3, 2] - half
    high = population.center[3, 2] + half
    on_corner = [np.allclose(np.where(np.isclose(low, row), low, high), row) for row in senses]
    assert any(on_corner)
    row = senses[on_corner.index(True)]
    weights = rule_weights(population.side[3])
    assert active_rule(row, population.center[3], population.side[3], weights, -1) == 2


def test_creep_stays_inside_the_ranges():
    bound = bound_search()
    population = _Population(bound, np.random.default_rng(4))
    rng = np.random.default_rng(5)
    for _ in range(200):
        population.creep_rule(0, 0, rng)
    assert np.all(population.target[0, 0] >= STARMAN.joint_min)
    assert np.all(population.target[0, 0] <= STARMAN.joint_max)
    assert bound.tau_range[0] <= population.tau[0, 0] <= bound.tau_range[1]
    assert np.all((population.side[0, 0] >= SIDE_MIN) & (population.side[0, 0] <= SIDE_MAX))


@pytest.mark.parametrize("generations", [20, pytest.param(150, marks=pytest.mark.slow)])
def test_the_learning_curve_climbs_and_the_best_is_rerun_from_the_nominal_start(generations):
    outcome = run_search(bound_search(generations=generations), 7)
    assert outcome.evaluations[0] == 6 and outcome.evaluations[-1] == 6 * (generations + 1)
    assert np.all(np.diff(outcome.best_fitness) >= 0)
    assert outcome.best_fitness[-1] > outcome.best_fitness[0]
    # no perturbation: the best's fitness is the fitness of its nominal run
    assert outcome.nominal_fitness == pytest.approx(outcome.fitness, abs=1e-12)


def test_a_seed_gives_the_same_result_with_one_thread_or_two():
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = run_search(bound_search(), 8)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = run_search(bound_search(), 8)
    finally:
        numba.set_num_threads(threads)
    np.testing.assert_array_equal(one.best_fitness, two.best_fitness)
    np.testing.assert_array_equal(one.controller.center, two.controller.center)
    np.testing.assert_array_equal(one.rod_ends, two.rod_ends)
    other = run_search(bound_search(), 7)
    assert not np.array_equal(other.best_fitness, one.best_fitness)


def test_perturbed_starts_differ_and_stand_on_the_floor():
    spec = bound_search(
        SPEC.replace("fitness", "perturb angle=5 joints=10 speed=0.2 spin=20\nfitness")
    )
    rng = np.random.default_rng(0)
    starts = [
        perturbed_state(STARMAN, spec.root_angle, spec.joints, 0.0, spec.spec.perturbation, rng)
        for _ in range(20)
    ]
    assert len({tuple(start) for start in starts}) == 20
    outcome = run_search(bind_search(spec.spec, STARMAN, 5), 7)
    assert outcome.rod_ends[0, :, :, 1].min() == pytest.approx(0.0, abs=1e-12)


def test_the_result_file_keeps_the_contract(tmp_path):
    spec_path = tmp_path / "tiny.bsr"
    spec_path.write_text(SPEC)
    output = tmp_path / "tiny" / "seed7.h5"
    search_to_file(spec_path, ROOT / "specs/figures", 7, output, generations=3, budget="test")
    # DESIGN.md's result, read as another tool reads it (tests/contract_check.py): its
    # datasets and attributes, and its terms measured again on the best motion
    assert bsr_result_problems(output, spec_path) == []
    with h5py.File(output) as h5:
        assert h5["learning_curve/evaluations"][-1] == 24
        motion = h5["best/figure_motion"]
        assert motion["endpoints"].shape == (201, 5, 2, 2)
        assert json.loads(motion.attrs["terrain"]) == [[-1000.0, 0.0], [1000.0, 0.0]]
    result = read_bsr_result(output)
    assert result.attrs["budget"] == "test" and result.controller.kind == "sense"


def binding_error(text: str) -> str:
    """The message of the SpecError that binding the spec ``text`` to Star-Man raises."""
    with pytest.raises(SpecError) as error:
        bound_search(text)
    return str(error.value)


def test_a_start_name_the_figure_lacks_is_an_error_at_its_word():
    assert binding_error(SPEC.replace("leg_b=-20", "knee=-20")) == (
        "test.bsr:6:44: expected a coordinate of figure 'starman' (torso, x, arm_a, arm_b, "
        "leg_a, leg_b), found 'knee=-20'"
    )
    assert binding_error(SPEC + "fall torso.distal arm_c.distal\n") == (
        "test.bsr:8:19: expected an endpoint of figure 'starman' (torso.proximal, torso.distal, "
        "arm_a.distal, arm_b.distal, leg_a.distal, leg_b.distal), found 'arm_c.distal'"
    )


def test_a_term_of_the_other_dimension_is_an_error_at_its_word():
    message = binding_error(SPEC.replace("fitness distance=1", "fitness distance=1 sideways=-1"))
    assert "expected a fitness term of figure 'starman' (distance, max_height, " in message
    assert message.endswith("found 'sideways=-1'")


def test_the_3d_options_are_refused_for_a_2d_figure():
    """filter= and a fall line's below= were ignored without a word for a 2-D figure: a fall
    line of below= alone measured nothing, and fall= weighed a term that was always 0."""
    filtered = SPEC.replace("controller sense rules=6", "controller sense rules=6 filter=0.3")
    assert binding_error(filtered) == (
        "test.bsr:2:26: expected no filter= for a 2-D figure (the senses' low-pass filter is "
        "3-D's), found 'filter=0.3'"
    )
    assert binding_error(SPEC + "fall below=0.3\n") == (
        "test.bsr:8:6: expected no below= for a 2-D figure (it has fallen when an endpoint of "
        "its 'fall' line touches the floor; a height is 3-D's), found 'below=0.3'"
    )


def test_a_search_by_hand_records_its_budget_and_threads(tmp_path, capsys):
    """By hand with --generations the file said budget 'paper' (the tables then compared it
    with the paper) and threads 0."""
    from mosys.cli import main

    root = Path(__file__).resolve().parents[1]
    spec = root / "specs" / "bsr" / "starman_shuffle.bsr"
    common = [str(spec), "--seed", "1", "--figures", str(root / "specs" / "figures")]
    runs = {
        "custom.h5": ["--generations", "2"],
        "named.h5": ["--generations", "2", "--budget", "ci", "--threads", "1"],
    }
    try:
        for name, options in runs.items():
            assert main(["bsr-search", *common, *options, "-o", str(tmp_path / name)]) == 0
    finally:
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)  # this process's other tests
    capsys.readouterr()
    with h5py.File(tmp_path / "custom.h5") as custom, h5py.File(tmp_path / "named.h5") as named:
        assert custom.attrs["budget"] == "custom" and custom.attrs["threads"] >= 1
        assert named.attrs["budget"] == "ci" and named.attrs["threads"] == 1


def test_a_seed_the_spec_does_not_list_is_refused_saying_where_the_seeds_are(tmp_path):
    """It was 'S.bsr:1:1: expected seed 3 among the spec's seeds [1, 2], found end of line'."""
    from mosys.errors import InputError

    root = Path(__file__).resolve().parents[1]
    spec = root / "specs" / "bsr" / "starman_shuffle.bsr"
    with pytest.raises(InputError) as error:
        search_to_file(spec, root / "specs" / "figures", 9, tmp_path / "s.h5", generations=1)
    assert str(error.value) == (
        f"{spec}: --seed 9 is not one of its seeds (1, 2, 3, 4, 5, line 8): give one of them, "
        "or add it there"
    )
