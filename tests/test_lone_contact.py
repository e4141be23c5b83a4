"""Lone contacts (issue 21): one endpoint alone on the floor must not slide (the 1995 paper's
§2.1.1 friction), found in synthetic motions of a three-rod figure: a body and two legs hung on
one hip."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.bsr.lone_contact import (
    CONTACT_HEIGHT,
    MAX_EXCURSION,
    MIN_DURATION,
    LoneContact,
    distinct_endpoints,
    lone_contacts,
    sliding,
)
from mosys.errors import InputError
from mosys.kernels.bsr_simulate import CONTACT_TOLERANCE

DT = 1e-3  # s
T = np.arange(201) * DT  # 0.2 s
UP = 0.05  # m: a foot clear of the floor
BODY, LEG_A, LEG_B = 0, 1, 2
DISTAL = 1


def figure(foot_a: np.ndarray, foot_b: np.ndarray) -> np.ndarray:
    """Endpoints (N, 3, 2, 2) m of the body (hip to head) and two legs (hip to foot) with the
    feet at foot_a, foot_b (N, 2) m and the hip 0.9 m up between them."""
    hip = np.column_stack([(foot_a[:, 0] + foot_b[:, 0]) / 2, np.full(len(foot_a), 0.9)])
    head = hip + [0.0, 0.6]
    return np.stack(
        [np.stack([hip, head], 1), np.stack([hip, foot_a], 1), np.stack([hip, foot_b], 1)], 1
    )


def foot(x: float | np.ndarray, y: float | np.ndarray) -> np.ndarray:
    """A foot's path (N, 2) m over T from x and y, each a number or (N,) m."""
    return np.column_stack(np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), T)[:2])


def one_foot_down(slide: float = 0.0) -> np.ndarray:
    """Foot a on the floor the whole time, sliding ``slide`` m forward at a steady speed; foot b
    up."""
    return figure(foot(slide * T / T[-1], 0.0), foot(0.3, UP))


def test_standing_still_on_one_foot_is_one_lone_contact_that_does_not_slide():
    contacts = lone_contacts(T, one_foot_down())
    assert contacts == [LoneContact(LEG_A, DISTAL, 0.0, T[-1], 0.0)]
    assert sliding(contacts) == []


def test_a_foot_sliding_a_centimetre_is_flagged():
    contacts = lone_contacts(T, one_foot_down(slide=0.01))
    assert len(contacts) == 1
    assert contacts[0].excursion == pytest.approx(0.01)
    assert sliding(contacts) == contacts


def test_sliding_just_under_the_limit_passes():
    assert sliding(lone_contacts(T, one_foot_down(slide=0.99 * MAX_EXCURSION))) == []


def test_two_feet_down_is_no_lone_contact():
    assert lone_contacts(T, figure(foot(0.0, 0.0), foot(0.3, 0.001))) == []


def test_a_foot_hovering_five_millimetres_up_is_not_down():
    assert lone_contacts(T, figure(foot(0.0, 0.005), foot(0.3, UP))) == []


@pytest.mark.parametrize(("height", "found"), [(0.0009, 1), (0.0011, 0), (0.0018, 0)])
def test_down_is_the_simulators_contact_tolerance(height, found):
    """Within 1 mm a sliding foot is a lone contact that slides; above it, it is in the air for
    the simulator (no force on it), as a CI-budget cartwheel's hand hovering 1.8 mm up was."""
    assert CONTACT_HEIGHT == CONTACT_TOLERANCE
    motion = figure(foot(0.02 * T / T[-1], height), foot(0.3, UP))
    assert len(sliding(lone_contacts(T, motion))) == found


def test_the_other_foot_hovering_five_millimetres_up_is_not_clear():
    assert lone_contacts(T, figure(foot(0.0, 0.0), foot(0.3, 0.005))) == []


@pytest.mark.parametrize(("lifted_ms", "found"), [(15, 0), (19, 0), (20, 1), (30, 1)])
def test_a_stretch_counts_from_twenty_milliseconds(lifted_ms, found):
    # foot a stays down; foot b is up (so a is alone) for samples 50 .. 50 + lifted_ms
    lifted = (np.arange(T.size) >= 50) & (np.arange(T.size) <= 50 + lifted_ms)
    contacts = lone_contacts(T, figure(foot(0.0, 0.0), foot(0.3, np.where(lifted, UP, 0.0))))
    assert len(contacts) == found
    for contact in contacts:
        assert (contact.t_start, contact.duration) == pytest.approx((0.05, lifted_ms * DT))
        assert contact.duration >= MIN_DURATION - 1e-9


def test_an_elastic_bounce_never_rests_on_the_floor():
    # foot a falls from 5 cm and bounces back at 1 m/s: fast at every sample near the floor
    y = np.abs(T - 0.1) * 1.0 - 0.0005
    assert lone_contacts(T, figure(foot(0.0, np.maximum(y, 0.0)), foot(0.3, UP))) == []


def test_a_hop_splits_the_stance_and_each_landing_is_measured_alone():
    # down 0-70 ms, a 3 cm hop forward (2 cm high) 70-130 ms, down again from 130 ms
    flight = np.clip((T - 0.07) / 0.06, 0.0, 1.0)
    x = 0.03 * flight
    y = 0.08 * flight * (1.0 - flight)
    contacts = lone_contacts(T, figure(foot(x, y), foot(0.3, UP)))
    assert [(c.rod, c.end) for c in contacts] == [(LEG_A, DISTAL)] * 2
    assert contacts[0].t_end < 0.07 < 0.13 < contacts[1].t_start
    assert [c.excursion for c in contacts] == pytest.approx([0.0, 0.0])


def test_rod_ends_at_one_point_count_once():
    # a foot rod hung on the end of leg a: leg a's distal end and the foot rod's proximal end
    # are one endpoint, down alone
    ends = one_foot_down()
    toe = ends[:, LEG_A, DISTAL] + [0.15, 0.05]
    with_foot = np.concatenate([ends, np.stack([ends[:, LEG_A, DISTAL], toe], 1)[:, None]], 1)
    assert distinct_endpoints(with_foot).tolist() == [[0, 0], [0, 1], [1, 1], [2, 1], [3, 1]]
    assert [(c.rod, c.end) for c in lone_contacts(T, with_foot)] == [(LEG_A, DISTAL)]


def test_bad_shapes_and_times_are_input_errors():
    with pytest.raises(InputError, match="n_rods, 2, 2"):
        lone_contacts(T, np.zeros((T.size, 3, 2, 4)))
    with pytest.raises(InputError, match="increase strictly"):
        lone_contacts(np.zeros(T.size), one_foot_down())


@settings(max_examples=40, deadline=None)
@given(
    shift=st.floats(-100.0, 100.0),
    floor=st.floats(-2.0, 2.0),
    slide=st.floats(0.0, 0.02),
)
def test_moving_the_world_and_adding_a_rod_far_up_change_nothing(shift, floor, slide):
    ends = one_foot_down(slide)
    expected = lone_contacts(T, ends)
    moved = ends + [shift, floor]
    kite = np.broadcast_to([[shift, floor + 3.0], [shift + 1.0, floor + 3.5]], (T.size, 1, 2, 2))
    contacts = lone_contacts(T, np.concatenate([moved, kite], 1), floor=floor)
    assert [(c.rod, c.end, c.t_start, c.t_end) for c in contacts] == [
        (c.rod, c.end, c.t_start, c.t_end) for c in expected
    ]
    assert [c.excursion for c in contacts] == pytest.approx(
        [c.excursion for c in expected], abs=1e-9
    )


@settings(max_examples=30, deadline=None)
@given(slide=st.floats(0.0, 0.02), sideways=st.floats(0.0, 0.02))
def test_a_3d_motion_counts_the_slide_across_as_well_as_along(slide, sideways):
    """The planar motion placed in 3-D (z = 0) has the same lone contacts; a foot that also
    slides across (z) by ``sideways`` has the diagonal of its horizontal extent as excursion."""
    planar = one_foot_down(slide)
    flat = np.concatenate([planar, np.zeros(planar.shape[:3] + (1,))], axis=3)
    assert [(c.rod, c.end, c.t_start, c.t_end, c.excursion) for c in lone_contacts(T, flat)] == [
        (c.rod, c.end, c.t_start, c.t_end, c.excursion) for c in lone_contacts(T, planar)
    ]
    across = flat.copy()
    across[..., 2] += np.linspace(0.0, sideways, T.size)[:, None, None]
    contacts = lone_contacts(T, across)
    assert len(contacts) == len(lone_contacts(T, planar)) > 0
    for contact, flat_contact in zip(contacts, lone_contacts(T, planar), strict=True):
        duration = (flat_contact.t_end - flat_contact.t_start) / (T[-1] - T[0])
        expected = np.hypot(flat_contact.excursion, sideways * duration)
        assert contact.excursion == pytest.approx(expected, rel=1e-6, abs=1e-12)
