"""The DP's integrator and sweeps: the crossing found on a step's cubic, the sweep orders, the
answers against a fine reference, threads and the per-model kernel cache."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import SPECS
from hypothesis import example, given, settings
from hypothesis import strategies as st

from mosys.io.controller_table import read_controller_table
from mosys.kernels.dp import sweep_order
from mosys.kernels.dp_exits import first_crossing, hermite
from mosys.parsing.controller import parse_controller_spec, parse_controller_text
from mosys.ssc.generate import generate_controller

finite = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(finite, finite, finite, finite, st.floats(0.01, 5.0), st.floats(0.01, 5.0))
# ending on the bound, tangent to it: the chord's first guess rounded to an ulp past s = 1
@example(0.0, 2.377056175564622, -0.9734591014168164, 0.0, 1.0, 2.377056175564622)
def test_first_crossing_is_the_first_time_the_cubic_reaches_a_bound(x0, x1, d0, d1, below, above):
    """From x0 inside (low, high): the cubic stays strictly inside before the returned s and is
    on a bound at it; 2.0 only when it never leaves [low, high] on [0, 1]."""
    low, high = x0 - below, x0 + above
    s = first_crossing(x0, x1, d0, d1, low, high)
    samples = np.linspace(0.0, 1.0, 4001)
    values = np.array([hermite(x0, x1, d0, d1, t) for t in samples])
    scale = 1.0 + abs(x0) + abs(x1) + abs(d0) + abs(d1)
    if s == 2.0:
        assert np.all(values > low - 1e-9 * scale) and np.all(values < high + 1e-9 * scale)
        return
    assert 0.0 < s <= 1.0
    at = hermite(x0, x1, d0, d1, s)
    assert min(abs(at - low), abs(at - high)) < 1e-9 * scale
    before = values[samples < s - 1e-6]
    assert np.all(before > low - 1e-9 * scale) and np.all(before < high + 1e-9 * scale)


def test_first_crossing_finds_an_excursion_between_two_inside_ends():
    """Both ends inside, but the cubic bulges out in between (a chord would miss it)."""
    s = first_crossing(0.0, 0.0, 4.0, -4.0, -1.0, 0.5)
    assert 0.0 < s < 0.5
    assert hermite(0.0, 0.0, 4.0, -4.0, s) == pytest.approx(0.5, abs=1e-9)


def test_first_crossing_looks_past_control_points_that_reach_a_bound():
    """The Bézier control points (0, 1, 1, 0) pass the bound 0.9, but the cubic only reaches
    0.75: the shortcut for control points clear of both bounds must not be the only check."""
    assert first_crossing(0.0, 0.0, 3.0, -3.0, -1.0, 0.9) == 2.0
    assert first_crossing(0.0, 0.0, 3.0, -3.0, -1.0, 0.7) < 0.5


@pytest.mark.parametrize("counts", [(5,), (3, 4), (2, 3, 4)])
def test_each_sweep_order_visits_every_node_once_in_its_directions(counts):
    """Sweep k runs the grid in C order with the axes of bit set in k mod 2**d reversed."""
    counts = np.array(counts, dtype=np.int64)
    order = np.empty(np.prod(counts), dtype=np.int64)
    for sweep in range(2 * (1 << len(counts))):
        sweep_order(counts, sweep, order)
        assert np.array_equal(order, expected_order(counts, sweep))


def expected_order(counts, sweep: int) -> np.ndarray:
    """The nodes of a grid of ``counts`` in C order with the axes of bit set in sweep mod 2**d
    reversed."""
    flipped = np.arange(np.prod(counts)).reshape(counts)
    for axis in range(len(counts)):
        if (sweep % (1 << len(counts))) >> axis & 1:
            flipped = np.flip(flipped, axis)
    return flipped.ravel()


@settings(max_examples=200, deadline=None)
@given(
    counts=st.lists(st.integers(1, 5), min_size=1, max_size=5),
    sweep=st.integers(0, 100),
    data=st.data(),
)
def test_a_sweep_order_shorter_than_the_grid_gets_its_first_nodes_and_no_more(counts, sweep, data):
    """Any grid and sweep (hypothesis); an ``out`` shorter than the grid (``load_kernels`` passes
    an empty one to compile the kernel) gets the order's first nodes, nothing past it."""
    expected = expected_order(counts, sweep)
    length = data.draw(st.integers(0, expected.size), label="length")
    buffer = np.full(expected.size + 3, -7, dtype=np.int64)
    sweep_order(np.array(counts, dtype=np.int64), sweep, buffer[:length])
    assert np.array_equal(buffer[:length], expected[:length])
    assert (buffer[length:] == -7).all()


def test_a_segment_too_stiff_to_follow_stops_trying(tmp_path):
    """Luxo pressing into a joint limit or the ground shakes at the integrator's stability limit
    and never leaves its cell: such a segment gives up after the steps a tenth of ``dt`` would
    take for MAX_SEGMENT_SECONDS (400 at 50 ms; before, 25 of Luxo's segments took 500 to
    22,087 steps each to be discarded at 2 s), discarded (cost inf); none that leaves its cell
    comes near that."""
    from mosys.dynamics.compile import compile_figure
    from mosys.dynamics.load import load_dynamics
    from mosys.kernels.dp_exits import (
        MAX_SEGMENT_SECONDS,
        STIFF_STEP_FRACTION,
        exit_transitions_template,
    )
    from mosys.kernels.specialise import specialise
    from mosys.ssc.exits import Transitions, exit_transition_arguments
    from mosys.ssc.problem import build_problem

    compile_figure(SPECS / "figures" / "luxo_grounded.fig", tmp_path / "luxo_grounded.py")
    dynamics = load_dynamics(tmp_path / "luxo_grounded.py")
    spec = parse_controller_spec(SPECS / "controllers" / "luxo" / "land.ssc")
    problem = build_problem(spec, dynamics)
    before, obstacles, arrival = exit_transition_arguments(problem, dynamics, spec.dt)
    transitions = Transitions.empty(
        problem.node_valid, problem.control_samples.shape[0], len(problem.grid.names)
    )
    count = np.zeros(transitions.segment_cost.shape, dtype=np.int64)
    size = problem.base_state.shape[0]
    specialise(exit_transitions_template, dynamics, parallel=True)(
        *before,
        np.flatnonzero(transitions.row_of >= 0),
        transitions.row_of,
        *obstacles,
        *arrival,
        *transitions.outputs(),
        True,  # recording: count each segment's accepted steps (record_count - 1)
        np.zeros_like(count),
        count,
        np.zeros((0, size + 1)),
        np.zeros(size, dtype=np.bool_),
    )
    steps = count - 1
    cap = MAX_SEGMENT_SECONDS / (STIFF_STEP_FRACTION * spec.dt)
    assert cap == pytest.approx(400)
    assert steps.max() <= cap
    assert np.all(np.isinf(transitions.segment_cost[steps > cap / 2]))
    assert (steps > cap / 2).sum() >= 10  # the stiff ones are there, and stopped
    assert steps[np.isfinite(transitions.segment_cost)].max() < cap / 2


@pytest.fixture(scope="module")
def figure_12_tables(link1, tmp_path_factory):
    """Controller A (the Figure 12 grid) as shipped, and with a step cap 500 times shorter."""
    directory = tmp_path_factory.mktemp("accuracy")
    text = (SPECS / "controllers" / "pendulum" / "A.ssc").read_text()
    shipped = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")
    fine = parse_controller_text(text + "\ndt 0.0001\n", "A_fine.ssc")
    generate_controller(shipped, link1, directory / "A.h5", quiet=True)
    generate_controller(fine, link1, directory / "A_fine.h5", quiet=True)
    return read_controller_table(directory / "A.h5"), read_controller_table(directory / "A_fine.h5")


def test_cost_to_go_agrees_with_a_fine_step_reference(figure_12_tables):
    """Every node within 1 % or 2 ms of the solve whose steps are at most 0.1 ms (the issue's
    bound is a 10x shorter step; this one is 500x), and the same nodes reachable."""
    shipped, fine = figure_12_tables
    assert shipped.attrs["dt"] == 0.05
    assert np.array_equal(np.isfinite(shipped.value), np.isfinite(fine.value))
    reachable = np.isfinite(fine.value)
    error = np.abs(shipped.value[reachable] - fine.value[reachable])
    assert np.all(error <= np.maximum(0.01 * fine.value[reachable], 0.002))


def test_kernels_load_outside_the_dp_timings(figure_12_tables):
    shipped, _ = figure_12_tables
    attrs = shipped.attrs
    assert attrs["kernel_load_seconds"] >= 0.0
    assert attrs["transition_seconds"] + attrs["iteration_seconds"] <= attrs["generation_seconds"]


GENERATE_IN_A_NEW_PROCESS = """
import sys
from mosys.dynamics.load import load_dynamics
from mosys.kernels.dp_exits import exit_transitions_template
from mosys.kernels.specialise import specialise
from mosys.parsing.controller import parse_controller_spec
from mosys.ssc.generate import generate_controller
dynamics = load_dynamics(sys.argv[1])
generate_controller(parse_controller_spec(sys.argv[2]), dynamics, sys.argv[3], quiet=True)
stats = specialise(exit_transitions_template, dynamics, parallel=True).stats
print(sum(stats.cache_hits.values()), sum(stats.cache_misses.values()))
"""


def generate_in_a_new_process(dynamics, out, threads: int) -> tuple[int, int]:
    """Controller A generated by a new process on ``threads`` numba threads with the dynamics
    module at path ``dynamics``; the exit kernel's numba cache hits and misses."""
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            GENERATE_IN_A_NEW_PROCESS,
            str(dynamics),
            str(SPECS / "controllers" / "pendulum" / "A.ssc"),
            str(out),
        ],
        env=dict(os.environ, NUMBA_NUM_THREADS=str(threads)),
        check=True,
        capture_output=True,
        text=True,
    )
    hits, misses = (int(word) for word in done.stdout.split())
    return hits, misses


def test_tables_are_bit_identical_on_one_and_two_threads_and_the_kernel_is_cached(tmp_path):
    """The model-specialised exit kernel is compiled once per model and machine: a second
    process loads it from numba's cache."""
    from mosys.dynamics.compile import compile_figure

    dynamics = tmp_path / "link1.py"
    compile_figure(SPECS / "figures" / "link1.fig", dynamics)
    generate_in_a_new_process(dynamics, tmp_path / "warm.h5", 1)
    one = generate_in_a_new_process(dynamics, tmp_path / "one.h5", 1)
    generate_in_a_new_process(dynamics, tmp_path / "two.h5", 2)
    assert one == (1, 0)
    first = read_controller_table(tmp_path / "one.h5")
    second = read_controller_table(tmp_path / "two.h5")
    assert np.array_equal(first.value, second.value)
    assert np.array_equal(first.torque, second.torque)
