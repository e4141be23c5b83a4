"""The 1995 paper's search for 3-D figures (§4): binding a spec to a 3-D figure, the relevance
heuristic that contains a point of the sense trajectory, the enriched first population, chained
starts, and determinism whatever the threads."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numba
import numpy as np
import pytest

from mosys.bsr.figure3d import load_bsr_figure3d
from mosys.bsr.search import _Population, run_search
from mosys.bsr.search3d import ChainStart, bind_search3d
from mosys.kernels.bsr_controller import active_rule, rule_weights
from mosys.parsing.bsr import parse_bsr_text
from mosys.parsing.tokens import SpecError, Token

SPEC = """\
figure cujo
controller time rules=3 period=0.4
simulate duration=0.5 dt=0.01 tau_min=0.03
search controllers=4 generations=3 reseed=2
seeds 1
start spine=0
fitness distance=1 sideways=-1 fall=-5
fall below=0.5
"""
CUJO = load_bsr_figure3d("specs/figures", "test.bsr", Token("cujo", 1, 1))


def bound_search(text: str = SPEC, chain: ChainStart | None = None):
    return bind_search3d(parse_bsr_text(text, "test.bsr"), CUJO, chain=chain)


@pytest.mark.parametrize(
    "text, message",
    [
        (
            SPEC.replace("sideways=-1", "rotations=1"),
            "test.bsr:7:20: expected a fitness term of figure 'cujo' (distance, sideways, ",
        ),
        (
            SPEC + "perturb angle=2\n",
            "test.bsr:9:1: expected no 'perturb' line for a 3-D figure (not built), "
            "found 'perturb'",
        ),
        (
            SPEC.replace("spine=0", "hip=3"),
            "test.bsr:6:7: expected a coordinate of figure 'cujo' (spine, x, head, head_turn, ",
        ),
    ],
)
def test_a_3d_spec_names_what_its_figure_has(text, message):
    with pytest.raises(SpecError) as error:
        bound_search(text)
    assert str(error.value).startswith(message)


@pytest.mark.parametrize(
    "start, message",
    [
        ("head=20", "test.bsr:6:15: expected an angle of head within its range, -15 to 15 deg, "),
        ("head_turn=5", "test.bsr:6:15: expected head_turn at its fixed angle, 0 deg, found "),
    ],
)
def test_a_start_angle_outside_its_joints_range_is_refused(start, message):
    """It was clipped to the range without a word (a 60 deg start of a 25 deg leg stood at 25)."""
    with pytest.raises(SpecError) as error:
        bound_search(SPEC.replace("spine=0", f"spine=0 {start}"))
    assert str(error.value).startswith(message), str(error.value)
    bound_search(SPEC.replace("spine=0", "spine=0 head=15 head_turn=0"))  # the ends are in it


@pytest.mark.parametrize(
    "dropped, fitness, message",
    [
        (
            "feet ",
            "foot_steps=0.2",
            "test.bsr:7:40: expected a term of a figure with feet for foot_steps (a 'feet' line "
            "in its .fig; 'cujo' has none), found 'foot_steps=0.2'",
        ),
        (
            "terrain ",
            "",
            "test.bsr:1:8: expected a figure on a floor for a BSR search (a 'terrain floor' "
            "line: the fitness terms and senses measure the figure against the ground; 'cujo' "
            "has none and would fall for ever), found 'cujo'",
        ),
    ],
)
def test_a_search_needing_what_its_figure_lacks_is_refused(tmp_path, dropped, fitness, message):
    """Feet terms of a figure without feet were silently 0, and a figure with no floor fell
    for ever, both with exit 0."""
    text = Path("specs/figures/cujo.fig").read_text(encoding="utf-8")
    kept = [line for line in text.splitlines() if not line.startswith(dropped)]
    (tmp_path / "cujo.fig").write_text("\n".join(kept) + "\n", encoding="utf-8")
    figure = load_bsr_figure3d(tmp_path, "test.bsr", Token("cujo", 1, 8))
    spec = SPEC.replace("fall=-5", f"fall=-5 {fitness}".rstrip())
    with pytest.raises(SpecError) as error:
        bind_search3d(parse_bsr_text(spec, "test.bsr"), figure)
    assert str(error.value) == message


def test_a_new_sense_rule_contains_a_point_of_the_parents_sense_trajectory():
    spec = SPEC.replace("controller time rules=3 period=0.4", "controller sense rules=3")
    bound = bound_search(spec)
    rng = np.random.default_rng(4)
    population = _Population(bound, rng)
    senses = rng.uniform(0.0, 1.0, (30, len(CUJO.sense_names)))
    for _ in range(20):
        population.draw_rule(0, 1, rng, senses)
        center, side = population.center[0], population.side[0]
        inside = np.all(np.abs(senses - center[1]) < side[1] / 2.0, axis=1)
        assert inside.any()
        point = senses[np.flatnonzero(inside)[0]]
        # the rule fires there (alone, it would be the active one)
        assert active_rule(point, center[1:2], side[1:2], rule_weights(side[1:2]), -1) == 0


@pytest.mark.slow  # a minute and more: a whole sense-based search
def test_a_sense_based_search_enriches_a_first_set_and_keeps_its_best():
    """§4.2: three rounds of the relevance mutation enrich "the first set of 100 motion
    controllers"; the best C of them go on (here a first set of 8 for C = 4, to be quick)."""
    spec = SPEC.replace("controller time rules=3 period=0.4", "controller sense rules=3")
    sense = bound_search(spec)
    assert (sense.enrich_rounds, sense.first_set, sense.first_size) == (3, 100, 100)
    time = bound_search(SPEC)
    assert (time.enrich_rounds, time.first_size) == (0, 4)  # time-based: C
    outcome = run_search(dataclasses.replace(sense, first_set=8), 1)
    # 8 controllers, three rounds of 8 more, then C = 4 per generation
    assert list(outcome.evaluations) == [32, 36, 40, 44]


def test_the_first_set_keeps_its_best_controllers_in_order():
    population = _Population(bound_search(), np.random.default_rng(5), size=6)
    population.fitness[:] = [0.5, 3.0, -1.0, 2.0, 3.0, 0.0]
    kept = population.take(np.argsort(-population.fitness, kind="stable")[:3])
    assert kept.fitness.tolist() == [3.0, 3.0, 2.0]  # ties keep their order: 1, then 4
    np.testing.assert_array_equal(kept.target, population.target[[1, 4, 3]])
    np.testing.assert_array_equal(kept.senses, population.senses[[1, 4, 3]])


def test_a_search_gives_the_same_result_on_one_thread_and_two():
    results = []
    for threads in (1, 2):
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        outcome = run_search(bound_search(), 3)
        results.append((outcome.best_fitness, outcome.terms, outcome.rod_ends))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for one, two in zip(*results, strict=True):
        assert np.array_equal(one, two)


def test_a_chained_search_starts_from_the_state_it_is_given():
    first = run_search(bound_search(), 1)
    text = SPEC.replace("start spine=0\n", "") + "chain cujo_bound\n"
    chain = ChainStart("cujo_bound", 1, first.final_state, first.final_force)
    continued = run_search(bound_search(text, chain), 1)
    np.testing.assert_allclose(continued.rod_ends[0], first.rod_ends[-1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(continued.com[0], first.com[-1], rtol=0, atol=1e-12)


def test_continuing_a_result_without_a_final_state_is_a_clear_error(tmp_path):
    import h5py

    from mosys.bsr.search3d import chain_start
    from mosys.errors import InputError
    from mosys.io.contracts import CONTRACT

    old = tmp_path / "seed1.h5"
    with h5py.File(old, "w") as h5:  # a result file as mosys wrote them before final_state
        contract = CONTRACT["BSR search result"]
        for group in contract.groups:
            h5.create_group(group)
        for dataset in contract.datasets:
            h5[dataset] = np.zeros(1)
        h5.attrs["best_fitness"] = 1.0
        h5.attrs["seed"] = 1
        h5.attrs["name"] = "cujo_bound"
    with pytest.raises(InputError, match="no best/final_state to continue from"):
        chain_start("cujo_bound", [old])
    with pytest.raises(InputError, match="no result files of search 'cujo_bound'"):
        chain_start("cujo_bound", [])
    with pytest.raises(InputError) as error:  # the chain line names another search
        chain_start("rex_walk", [old])
    assert str(error.value) == (
        f"{old}: a result of search 'cujo_bound', not of 'rex_walk' (the search the spec's "
        "chain line continues)"
    )
    with h5py.File(old, "a") as h5:
        del h5["best/controller"]
    with pytest.raises(InputError) as error:
        chain_start("cujo_bound", [old])
    assert str(error.value) == (
        f"{old}: not a BSR search result (it lacks best/controller; docs/formats/bsr_result.md)"
    )


def test_a_chain_whose_final_state_is_another_figures_is_refused_at_the_chain_line():
    first = run_search(bound_search(), 1)
    text = SPEC.replace("start spine=0\n", "") + "chain cujo_bound\n"
    chain = ChainStart("cujo_bound", 1, first.final_state[:-2], first.final_force)
    with pytest.raises(SpecError) as error:
        bound_search(text, chain)
    size = first.final_state.size
    assert str(error.value).endswith(
        f"expected a search of figure 'cujo' to continue ({size} state values and "
        f"{first.final_force.size} endpoint forces; the final state of 'cujo_bound' has "
        f"{size - 2} and {first.final_force.size}), found 'cujo_bound'"
    )


def test_final_spin_is_the_bodys_rate_at_the_end():
    """``final_spin`` is the rigid body's angular speed I⁻¹ (L - h) at the final state, computed
    here from the state alone (its pose's inertia tensor and the deformation's own spin)."""
    from mosys.kernels import bsr3d_simulate as sim
    from mosys.parsing.bsr import FITNESS_TERMS_3D

    outcome = run_search(bound_search(), 1)
    state = outcome.final_state
    work = sim.new_step_work(CUJO.arrays.parent.shape[0], CUJO.arrays.endpoints.shape[0])
    sim.start_step_work(CUJO.arrays, state, work)
    rotation, tensor_inverse = work.matrices[0], work.matrices[2]
    momentum = state[sim.LX : sim.LX + 3] - rotation @ work.vectors[0, :3]
    rate = rotation @ tensor_inverse @ rotation.T @ momentum
    measured = outcome.terms[FITNESS_TERMS_3D.index("final_spin")]
    assert measured == pytest.approx(np.degrees(np.linalg.norm(rate)), rel=1e-9)
    assert measured > 1.0  # a run of a random controller ends moving


def test_net_rotation_is_the_size_of_the_heading_change():
    """``net_rotation`` (footnote 10's net rotation about the vertical) is |heading_change|,
    whichever way the figure turned."""
    from mosys.parsing.bsr import FITNESS_TERMS_3D

    turns = []
    for seed in (1, 2, 3):
        terms = run_search(bound_search(), seed).terms
        turned = terms[FITNESS_TERMS_3D.index("heading_change")]
        assert terms[FITNESS_TERMS_3D.index("net_rotation")] == abs(turned)
        turns.append(turned)
    assert all(t != 0.0 for t in turns)  # random controllers turn: the term is not all 0


def test_a_heading_rod_standing_upright_at_the_start_is_refused(tmp_path):
    """The heading is the heading rod's horizontal direction: of an upright rod it was
    rounding, and a search weighed its deviation (21 deg of noise) without a word."""
    text = Path("specs/figures/cujo.fig").read_text(encoding="utf-8")
    (tmp_path / "cujo.fig").write_text(
        text.replace("heading spine offset=0", "heading front_left offset=0"), encoding="utf-8"
    )
    figure = load_bsr_figure3d(tmp_path, "test.bsr", Token("cujo", 1, 8))
    splayed = SPEC.replace("spine=0", "spine=0 front_left_swing=5")  # 15 deg from upright
    bind_search3d(parse_bsr_text(splayed, "test.bsr"), figure)
    with pytest.raises(SpecError) as error:
        upright = SPEC.replace("spine=0", "spine=0 front_left_swing=-5")  # 5 deg
        bind_search3d(parse_bsr_text(upright, "test.bsr"), figure)
    assert str(error.value) == (
        "test.bsr:1:8: expected a figure whose heading rod lies nearer the horizontal at the "
        "start ('front_left', its 'heading' line's rod, is 5.0 deg from upright in the start "
        "pose, and its horizontal direction is the heading), found 'cujo'"
    )


def test_a_figure_lying_flat_is_refused_not_divided_by(tmp_path):
    """Its standing centre of mass is on the floor: the senses' scales divided by that height
    and the search died of ZeroDivisionError, exit 1, with a traceback."""
    (tmp_path / "flat.fig").write_text(
        "rod a length=0.6 mass=3\nrod b length=0.6 mass=3\nfree a\nball b on=a\n"
        "limit b lower=-30 upper=30 swing_lower=-30 swing_upper=30\nheading a\nterrain floor\n",
        encoding="utf-8",
    )
    figure = load_bsr_figure3d(tmp_path, "test.bsr", Token("flat", 1, 8))
    spec = SPEC.replace("figure cujo", "figure flat").replace("spine=0", "a=0")
    with pytest.raises(SpecError) as error:
        bind_search3d(parse_bsr_text(spec, "test.bsr"), figure)
    assert str(error.value) == (
        "test.bsr:1:8: expected a figure whose centre of mass stands above the floor at rest "
        "(every angle 0; 'flat' lies flat, its centre of mass 0 m up), found 'flat'"
    )
