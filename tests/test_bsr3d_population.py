"""A 3-D population evaluated four controllers at a time in lockstep (``run_population``,
``run_lockstep``) gives each controller exactly the numbers of its own ``run_controller``: the
same rules, senses, terms, final state and outcome, bit for bit, for a group of four and for the
remainder, time-based and sense-based, with a lane that stops unsound while the others go on."""

from __future__ import annotations

import numpy as np
import pytest

from mosys.bsr.figure3d import load_bsr_figure3d
from mosys.bsr.search3d import bind_search3d
from mosys.kernels.bsr3d_controller import TERM_COUNT, run_controller
from mosys.kernels.bsr3d_population import lockstep_groups, run_population
from mosys.kernels.bsr3d_simulate import VX
from mosys.kernels.bsr_controller import (
    CENTER_MAX,
    CENTER_MIN,
    SIDE_MAX,
    SIDE_MIN,
    ControllerArrays,
    RunRecord,
)
from mosys.kernels.lanes import LANES
from mosys.kernels.soundness import blown_up
from mosys.parsing.bsr import parse_bsr_spec

STEPS = 300
POPULATION = 6  # a group of four in lockstep and two alone


def _population(setup, rng):
    spec, figure = setup.spec, setup.figure
    c, r, j = POPULATION, spec.rules, len(figure.joint_names)
    v = len(figure.sense_names) if spec.kind == "sense" else 0
    ends = np.cumsum(rng.uniform(0.5, 2.0, (c, r)), axis=1)
    ends = ends / ends[:, -1:] * setup.period
    return ControllerArrays(
        spec.kind == "time",
        rng.uniform(figure.joint_min, figure.joint_max, (c, r, j)),
        rng.uniform(0.05, 0.25, (c, r)),
        rng.uniform(CENTER_MIN, CENTER_MAX, (c, r, v)),
        np.exp(rng.uniform(np.log(SIDE_MIN), np.log(SIDE_MAX), (c, r, v))),
        ends,
        setup.period,
    )


@pytest.mark.parametrize("search", ["rex_walk", "bob_walk"])
def test_each_controller_of_a_population_runs_as_it_does_alone_bit_for_bit(search):
    spec = parse_bsr_spec(f"specs/bsr/{search}.bsr")
    figure = load_bsr_figure3d("specs/figures", spec.path, spec.tokens["figure"])
    setup = bind_search3d(spec, figure)
    arrays, task, dt = figure.arrays, setup.simulation.task, spec.dt
    population = _population(setup, np.random.default_rng(5))
    starts = np.repeat(setup.simulation.start[None, :], POPULATION, axis=0)
    starts[1, VX] = np.nan  # a lane of the group stops at once; the others go on
    v = population.center.shape[2]
    n_rods, n_ends = arrays.parent.shape[0], arrays.endpoints.shape[0]
    senses = np.zeros((POPULATION, STEPS + 1, v))
    rules = np.zeros((POPULATION, STEPS + 1), np.int64)
    terms = np.zeros((POPULATION, TERM_COUNT))
    taken = np.zeros(POPULATION, np.int64)
    final = np.empty_like(starts)
    run_population(arrays, population, task, starts, STEPS, dt, senses, rules, terms, taken, final)
    assert taken[1] == blown_up(0)
    assert (np.delete(taken, 1) == STEPS).all()
    for c in range(POPULATION):
        controller = ControllerArrays(
            population.time_based,
            *(part[c] for part in population[1:6]),
            population.period,
        )
        alone = RunRecord(
            np.zeros((STEPS + 1, v)),
            np.zeros(STEPS + 1, np.int64),
            np.zeros(TERM_COUNT),
            np.empty((0, n_rods, 2, 3)),
            np.empty((0, 3)),
            np.empty(starts.shape[1]),
            np.empty(n_ends),
        )
        outcome = run_controller(
            arrays, controller, task, starts[c], np.zeros(n_ends), np.bool_(False), STEPS, dt, alone
        )
        assert outcome == taken[c]
        np.testing.assert_array_equal(alone.rule_out, rules[c])
        np.testing.assert_array_equal(alone.senses_out, senses[c])
        np.testing.assert_array_equal(alone.terms_out, terms[c])
        np.testing.assert_array_equal(alone.final_state, final[c])
    # the runs differ from each other (a test of something)
    assert len({tuple(row) for row in terms[[0, 2, 3, 4, 5]]}) == POPULATION - 1


@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("population", [1, 3, 4, 5, 9, 10, 40, 41])
def test_the_groups_hold_every_controller_once_and_give_each_thread_an_even_share(
    population, threads
):
    groups = lockstep_groups(population, threads)
    members = groups[groups >= 0]
    assert sorted(members.tolist()) == list(range(population))
    assert groups.shape[1] == LANES and groups.shape[0] % threads == 0
    # each group's members fill its first lanes; each thread's block of groups runs about
    # the same number of controllers, in as few groups as the largest share needs
    assert all((row >= 0).tolist() == sorted((row >= 0).tolist(), reverse=True) for row in groups)
    per_thread = (groups >= 0).reshape(threads, -1, LANES).sum(axis=(1, 2))
    assert per_thread.max() - per_thread.min() <= 1
    assert groups.shape[0] // threads == -(-per_thread.max() // LANES)
