"""n-linear interpolation kernels (hypothesis): exact at nodes, bounded by the cell, periodic on
wrap axes."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.kernels.interpolate import falls_short, interpolate_into

settings.register_profile("mosys", deadline=None, max_examples=60)
settings.load_profile("mosys")


@st.composite
def grids(draw):
    d = draw(st.integers(1, 3))
    count = np.array([draw(st.integers(2, 5)) for _ in range(d)], dtype=np.int64)
    axis_min = np.array([draw(st.floats(-10, 10)) for _ in range(d)])
    axis_step = np.array([draw(st.floats(0.1, 5)) for _ in range(d)])
    wrap = np.array([draw(st.booleans()) for _ in range(d)], dtype=np.bool_)
    m = draw(st.integers(1, 2))
    seed = draw(st.integers(0, 2**31))
    table = np.random.default_rng(seed).normal(size=(int(np.prod(count)), m))
    return axis_min, axis_step, count, wrap, table


def interpolate(grid, state):
    axis_min, axis_step, count, wrap, table = grid
    out = np.empty(table.shape[1])
    known = np.ones(table.shape[0], dtype=np.bool_)
    interpolate_into(axis_min, axis_step, count, wrap, table, known, np.asarray(state, float), out)
    return out


@given(grids(), st.data())
def test_node_values_are_exact(grid, data):
    axis_min, axis_step, count, wrap, table = grid
    index = [data.draw(st.integers(0, int(n) - 1)) for n in count]
    state = axis_min + axis_step * np.array(index)
    flat = np.ravel_multi_index(index, tuple(count))
    np.testing.assert_allclose(interpolate(grid, state), table[flat], atol=1e-9)


@given(grids(), st.data())
def test_values_stay_within_the_cell_corners(grid, data):
    axis_min, axis_step, count, wrap, table = grid
    fraction = np.array([data.draw(st.floats(0, 1)) for _ in count])
    low = np.array([data.draw(st.integers(0, int(n) - 2)) for n in count])
    state = axis_min + axis_step * (low + fraction)
    corners = [
        np.ravel_multi_index(tuple(low + np.array(bits)), tuple(count))
        for bits in np.ndindex(*(2,) * len(count))
    ]
    value = interpolate(grid, state)
    assert np.all(value >= table[corners].min(axis=0) - 1e-9)
    assert np.all(value <= table[corners].max(axis=0) + 1e-9)


@given(grids(), st.data())
def test_wrap_axes_are_periodic(grid, data):
    axis_min, axis_step, count, wrap, table = grid
    fraction = np.array([data.draw(st.floats(0, 1)) for _ in count])
    state = axis_min + axis_step * fraction * (count - 1)
    turns = data.draw(st.integers(-3, 3))
    shifted = state + np.where(wrap, turns * count * axis_step, 0.0)
    np.testing.assert_allclose(interpolate(grid, shifted), interpolate(grid, state), atol=1e-7)


def test_wrap_axis_interpolates_across_the_seam():
    """Halfway between the last node and the first (one period on) is their mean."""
    grid = (
        np.array([0.0]),
        np.array([1.0]),
        np.array([4]),
        np.array([True]),
        np.array([[1.0], [2.0], [3.0], [5.0]]),
    )
    assert interpolate(grid, [3.5])[0] == 3.0


def test_a_known_weight_that_rounds_below_its_threshold_still_meets_it():
    """A state at 0.8 of a cell whose lower node is unknown (the car's y axis, 0.9 + 0.125 k):
    its known corner carries 0.8 of the weight, which sums to a hair below 0.8 in floating
    point. A ``known_weight 0.8`` counts it (``falls_short`` allows for rounding: until
    2026-12-03 25 of the car's parked starts had no cost-to-go for it), and not 0.79."""
    axis_min, axis_step, count = np.array([0.9]), np.array([0.125]), np.array([26])
    known = np.ones(26, dtype=np.bool_)
    known[2] = False  # the node at y = 1.15, below 1.25
    out = np.empty(1)
    table = np.arange(26.0)[:, None]
    weight = interpolate_into(
        axis_min, axis_step, count, np.array([False]), table, known, np.array([1.25]), out
    )
    assert 0.8 - 1e-15 < weight < 0.8  # 0.8, rounded below it
    assert not falls_short(weight, 0.8)
    assert out[0] == 3.0  # the known node's value alone
    assert falls_short(0.79, 0.8)
    assert not falls_short(0.0, 0.0)  # no threshold: nothing falls short
