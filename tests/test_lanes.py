"""Four-lane vectors (``mosys.kernels.lanes``) and the lockstep body frame
(``mosys.kernels.bsr3d_lanes``): each operation is its lane-by-lane arithmetic, compiled and in
Python; the body frame of four controllers at once is ``body_frame`` of each, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from mosys.bsr.figure3d import load_bsr_figure3d
from mosys.kernels import bsr3d_simulate as sim
from mosys.kernels.bsr3d_lanes import body_frame_lanes
from mosys.kernels.lanes import LANES, add, divide, load, multiply, splat, store, subtract
from mosys.parsing.tokens import Token

FINITE = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
LANE_VALUES = st.lists(FINITE, min_size=LANES, max_size=LANES)


@njit(cache=True)
def _operations(a, b, out):
    x = load(a, 0)
    y = load(b, 0)
    store(out, 0, add(x, y))
    store(out, LANES, subtract(x, y))
    store(out, 2 * LANES, multiply(x, y))
    store(out, 3 * LANES, divide(x, y))
    store(out, 4 * LANES, splat(a[1]))


def _expected(a, b):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.concatenate([a + b, a - b, a * b, a / b, np.full(LANES, a[1])])


@settings(max_examples=50, deadline=None)
@given(LANE_VALUES, LANE_VALUES)
def test_each_operation_is_its_lane_by_lane_arithmetic_compiled(a, b):
    a, b = np.array(a), np.array(b)
    out = np.zeros(5 * LANES)
    _operations(a, b, out)
    np.testing.assert_array_equal(out, _expected(a, b))


@settings(max_examples=20, deadline=None)
@given(LANE_VALUES, LANE_VALUES)
def test_each_operation_is_its_lane_by_lane_arithmetic_in_python(a, b):
    a, b = np.array(a), np.array(b)
    out = np.zeros(5 * LANES)
    _operations.py_func(a, b, out)
    np.testing.assert_array_equal(out, _expected(a, b))


def test_load_and_store_address_flat_elements_of_a_multidimensional_array():
    @njit
    def shift(array):
        store(array, 2 * LANES, load(array, LANES))

    array = np.arange(3.0 * LANES).reshape(3, LANES)
    shift(array)
    np.testing.assert_array_equal(array[2], array[1])
    np.testing.assert_array_equal(array[0], np.arange(LANES))


@pytest.mark.parametrize("name", ["rex", "cujo", "bob"])
def test_the_body_frame_of_four_controllers_is_body_frame_of_each_bit_for_bit(name):
    figure = load_bsr_figure3d("specs/figures", "test.bsr", Token(name, 1, 1)).arrays
    n, j, e = figure.parent.shape[0], figure.joint_min.shape[0], figure.endpoints.shape[0]
    rng = np.random.default_rng(7)
    theta = rng.uniform(figure.joint_min - 0.3, figure.joint_max + 0.3, (LANES, j))
    rate = rng.normal(0.0, 2.0, (LANES, j))
    trig = np.ones((4, n, LANES))
    trig[1::2] = 0.0
    for k in range(n):
        if figure.joint[k] >= 0:
            angle, psi = theta[:, figure.joint[k]], theta[:, figure.joint[k] + 1]
            trig[:, k] = np.cos(angle), np.sin(angle), np.cos(psi), np.sin(psi)
    shapes = ((n, 2, 3), (e, 3), (e, 3), (n, 3, 3), (5, n, 3), (3, 3), (3,))
    work = tuple(np.zeros((*shape, LANES)) for shape in shapes)
    total = body_frame_lanes(figure, trig, np.ascontiguousarray(rate.T), *work)
    rod_ends, end_offset, end_velocity, frames = work[:4]
    tensor, spin = work[5], work[6]
    for lane in range(LANES):
        expected = (np.zeros((n, 2, 3)), np.zeros((e, 3)), np.zeros((e, 3)), np.zeros((n, 3, 3)))
        expected_tensor, expected_spin = np.zeros((3, 3)), np.zeros(3)
        expected_total = sim.body_frame(
            *figure[:9],
            theta[lane].copy(),
            rate[lane].copy(),
            *expected,
            sim.new_scratch(n),
            expected_tensor,
            expected_spin,
        )
        assert total == expected_total
        for got, want in zip(
            (rod_ends, end_offset, end_velocity, frames, tensor, spin),
            (*expected, expected_tensor, expected_spin),
            strict=True,
        ):
            np.testing.assert_array_equal(got[..., lane], want)
