"""The BSR simulator of §2.1.1: deformation keeps momentum, contacts hold the figure up without
sinking, one contact does not slide, two share friction in the ratio of their normal forces; the
sense-based scoring of §2.1.2 and the time-based segments of §2.3."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mosys.bsr.figure import bsr_figure
from mosys.bsr.search import record_run
from mosys.bsr.start import standing_state
from mosys.io.bsr_result import BsrController
from mosys.kernels.bsr_controller import active_rule, rule_weights, segment_rule
from mosys.kernels.bsr_simulate import contact_impulses
from mosys.parsing.figure import parse_figure_spec, parse_figure_text

ROOT = Path(__file__).resolve().parents[1]
STARMAN = bsr_figure(parse_figure_spec(ROOT / "specs/figures/starman.fig"))
STAR_POSE = np.radians([45.0, -45.0, 20.0, -20.0])


def run(figure, start, target, tau, steps, dt=0.01):
    """One rule held for the whole run; returns rod ends (steps+1, N, 2, 2), com (steps+1, 2)
    and the terms."""
    j = len(figure.joint_names)
    held = BsrController(
        kind="time",
        target=np.asarray(target, np.float64).reshape(1, j),
        tau=np.array([tau]),
        center=np.zeros((1, 0)),
        side=np.zeros((1, 0)),
        segment=np.array([1e9]),
        period=1e9,
    )
    recorded = record_run(figure, held, start, steps, dt)
    return recorded.rod_ends, recorded.com, recorded.terms


def rod_motion(figure, ends, dt):
    """Each rod's centre of mass (steps+1, N, 2), its velocity and its angular velocity, from
    the recorded ends alone (central differences)."""
    fraction = figure.com[None, :, None]
    centres = ends[:, :, 0, :] + fraction * (ends[:, :, 1, :] - ends[:, :, 0, :])
    delta = ends[:, :, 1, :] - ends[:, :, 0, :]
    angles = np.unwrap(np.arctan2(delta[..., 1], delta[..., 0]), axis=0)
    return centres, np.gradient(centres, dt, axis=0), np.gradient(angles, dt, axis=0)


def floating(figure):
    """The figure with no floor (free flight)."""
    text = Path(figure.figure.path).read_text().replace("terrain floor", "")
    return bsr_figure(parse_figure_text(text, figure.figure.path))


def test_a_deformation_in_the_air_leaves_momentum_unchanged():
    figure = floating(STARMAN)
    start = standing_state(figure, math.pi / 2, STAR_POSE, velocity=(0.7, 2.0), spin=1.5)
    dt, steps = 0.001, 600
    target = np.radians([-120.0, 150.0, -90.0, 80.0])
    ends, com, _ = run(figure, start, target, 0.1, steps, dt)
    centres, velocity, spin = rod_motion(figure, ends, dt)
    mass = figure.mass
    # the centre of mass of the recorded rods is the state's, and it flies a parabola
    recorded_com = (mass[None, :, None] * centres).sum(axis=1) / mass.sum()
    np.testing.assert_allclose(recorded_com, com, atol=1e-9)
    t = np.arange(steps + 1) * dt
    np.testing.assert_allclose(com[:, 0], 0.7 * t, atol=1e-9)
    y0 = com[0, 1]
    np.testing.assert_allclose(com[:, 1], y0 + 2.0 * t - 0.5 * 9.81 * t * (t + dt), atol=1e-9)
    # angular momentum about the centre of mass, from the rods' own motion, stays put while
    # the figure changes shape (it starts at I0 * 1.5 rad/s)
    r = centres - com[:, None, :]
    v = velocity - np.gradient(com, dt, axis=0)[:, None, :]
    momentum = (mass * (r[..., 0] * v[..., 1] - r[..., 1] * v[..., 0])).sum(axis=1)
    momentum += (figure.inertia[None, :] * spin).sum(axis=1)
    inner = momentum[2:-2]
    assert np.ptp(inner) < 2e-3 * abs(inner.mean())
    assert abs(inner.mean() - start[5]) < 2e-3 * abs(start[5])
    # the shape did change a lot
    assert np.degrees(abs(np.unwrap(spin * dt).sum())) > 10.0


def test_a_dropped_rigid_figure_comes_to_rest_without_sinking():
    start = standing_state(STARMAN, math.pi / 2 + 0.05, STAR_POSE)
    start[1] += 0.5  # dropped from half a metre above its feet
    ends, com, _ = run(STARMAN, start, STAR_POSE, 0.1, 400)
    assert ends[..., 1].min() >= -1e-9  # never below the floor
    tail = com[-50:]
    assert np.ptp(tail[:, 0]) < 1e-6 and np.ptp(tail[:, 1]) < 1e-6  # at rest
    assert ends[-1, :, :, 1].min() == pytest.approx(0.0, abs=1e-9)  # on the floor, not above


def test_a_single_contact_does_not_slide():
    # legs together: the feet are one point; leaning, the figure topples about it
    pose = np.radians([45.0, -45.0, 0.0, 0.0])
    start = standing_state(STARMAN, math.pi / 2 + 0.2, pose)
    ends, _, _ = run(STARMAN, start, pose, 0.1, 60)
    feet = ends[:, 3, 1, :]
    assert np.ptp(feet[:, 0]) < 1e-9  # the foot stays where it stood
    np.testing.assert_allclose(feet[:, 1], 0.0, atol=1e-9)
    torso = ends[:, 0, 1, :] - ends[:, 0, 0, :]
    assert abs(math.degrees(math.atan2(torso[-1, 1], torso[-1, 0])) - 90.0) > 20.0  # it fell


@pytest.mark.parametrize("dt", [0.01, 0.001])
def test_a_lone_foot_stays_put_while_the_figure_kicks_and_swings_its_arms(dt):
    # standing on leg_a's foot alone for a second while leg_b kicks and both arms swing (the
    # figure sways and turns above the foot: a lone endpoint of a deforming figure, not only of
    # a rigid one)
    poses = np.radians(
        [[60, -60, 0, -40], [160, -20, 0, -100], [20, -160, 0, -10], [100, -100, 0, -70]]
    )
    swinging = BsrController(
        kind="time",
        target=poses,
        tau=np.full(4, 0.1),
        center=np.zeros((4, 0)),
        side=np.zeros((4, 0)),
        segment=np.full(4, 0.125),
        period=0.5,
    )
    start = standing_state(STARMAN, math.pi / 2, poses[0])
    steps = round(1.0 / dt)
    ends = record_run(STARMAN, swinging, start, steps, dt).rod_ends
    foot = ends[:, 3, 1, :]
    np.testing.assert_allclose(foot[:, 1], 0.0, atol=1e-9)  # down the whole second
    others = np.delete(ends[..., 1].reshape(steps + 1, -1), 7, axis=1)  # all but the foot
    assert others.min() > 0.01  # alone on the floor
    assert np.ptp(ends[:, 4, 1, 0]) > 0.2 and np.ptp(ends[:, 1, 1, 0]) > 0.2  # kicks, swings
    assert np.ptp(foot[:, 0]) < 1e-3


def test_two_contacts_share_friction_in_the_ratio_of_their_normal_impulses():
    u = np.array([[0.05, -0.5], [-0.1, -0.4]])  # sinking, sliding towards each other
    r = np.array([[-0.4, -0.9], [0.5, -0.9]])
    impulse = np.zeros((2, 2))
    inverse_mass, inverse_inertia = 1 / 60.0, 1 / 8.0
    contact_impulses(u, r, 2, inverse_mass, inverse_inertia, impulse)
    assert impulse[0, 1] > 0 and impulse[1, 1] > 0
    assert impulse[0, 0] / impulse[1, 0] == pytest.approx(impulse[0, 1] / impulse[1, 1], 1e-9)
    # velocities after: no sinking, and the normal-weighted sliding vanishes
    linear = impulse.sum(axis=0) * inverse_mass
    angular = (r[:, 0] * impulse[:, 1] - r[:, 1] * impulse[:, 0]).sum() * inverse_inertia
    after = u + linear + angular * np.stack([-r[:, 1], r[:, 0]], axis=1)
    np.testing.assert_allclose(after[:, 1], 0.0, atol=1e-12)
    weights = impulse[:, 1] / impulse[:, 1].sum()
    assert abs(weights @ after[:, 0]) < 1e-9


@pytest.mark.parametrize(
    ("u", "r", "pushing"),
    [
        ([[-0.79, -0.27], [-0.24, -0.45]], [[0.25, -0.21], [0.59, -0.31]], [True, True]),
        ([[-0.43, -0.37], [-0.37, -0.15]], [[0.75, -0.54], [0.47, -0.51]], [True, False]),
    ],
)
def test_where_no_impulses_of_the_friction_rule_push_the_normal_ones_alone_hold(u, r, pushing):
    """Two sinking points whose shared friction needs a pulling normal impulse and neither of
    which can be stopped dead alone (one in six random pairs): the floor gave no impulse, and
    the figure sank, was lifted out by its position and kept a fall's velocity. Now normal
    impulses alone (no friction for the step), which leave neither point sinking."""
    u, r = np.array(u), np.array(r)
    inverse_mass, inverse_inertia = 1 / 20.0, 1 / 2.0
    impulse = np.zeros((2, 2))
    contact_impulses(u, r, 2, inverse_mass, inverse_inertia, impulse)
    assert (impulse[:, 1] > 0).tolist() == pushing
    np.testing.assert_array_equal(impulse[:, 0], 0.0)
    for i in range(2):
        after = u[i, 1] + sum(
            (inverse_mass + r[i, 0] * r[j, 0] * inverse_inertia) * impulse[j, 1] for j in range(2)
        )
        assert after == pytest.approx(0.0, abs=1e-12) if pushing[i] else after >= 0.0


def test_a_contact_that_is_leaving_gets_no_impulse():
    impulse = np.ones((2, 2))
    contact_impulses(
        np.array([[0.2, 0.4], [0, 0]]), np.array([[0.1, -0.5], [0, 0]]), 1, 1.0, 1.0, impulse
    )
    assert not impulse.any()


def test_the_smallest_box_that_holds_the_senses_is_active_and_none_keeps_the_last():
    senses = np.array([0.5, 0.5])
    center = np.array([[0.5, 0.5], [0.45, 0.55], [3.0, 3.0]])
    side = np.array([[2.0, 2.0], [0.4, 0.4], [0.4, 0.4]])
    weights = rule_weights(side)
    np.testing.assert_allclose(weights, [2 * math.log(2.0), 2 * math.log(10.0), 2 * math.log(10)])
    # scores: W (1 - max_j (2 (S_j - mu_j) / side_j)^2): rule 0 1.386, rule 1 4.6 * 0.9375
    assert active_rule(senses, center, side, weights, 2) == 1
    far = np.array([-3.0, -3.0])
    assert active_rule(far, center, side, weights, 2) == 2  # no positive score: keep the last


def test_time_segments_repeat_every_period():
    ends = np.array([0.1, 0.4, 0.6])
    rules = [segment_rule(t, ends, 0.6) for t in (0.0, 0.15, 0.45, 0.59, 0.61, 1.25, 1.95)]
    assert rules == [0, 1, 2, 2, 0, 0, 1]


def test_a_lone_point_that_stopping_dead_would_pull_is_stopped_horizontally_and_rises():
    """A point sliding fast whose full stop would tip the body up off it (a pulling normal
    impulse): it used to take a frictionless push, and the step's pin then hid its sliding
    velocity in the figure, to be let out later (up to 180 J of ~670 J gained in a throw). Now
    the horizontal stop alone, after which it does not sink."""
    u = np.array([[-3.0, -0.05], [0.0, 0.0]])
    r = np.array([[0.6, -0.3], [0.0, 0.0]])
    inverse_mass, inverse_inertia = 1 / 20.0, 1 / 2.0
    impulse = np.zeros((2, 2))
    assert contact_impulses(u, r, 1, inverse_mass, inverse_inertia, impulse)
    assert impulse[0, 1] == 0.0 and impulse[0, 0] > 0.0
    angular = -r[0, 1] * impulse[0, 0] * inverse_inertia
    after = u[0] + impulse[0] * inverse_mass + angular * np.array([-r[0, 1], r[0, 0]])
    assert after[0] == pytest.approx(0.0, abs=1e-12)  # no sliding
    assert after[1] >= 0.0  # and it rises


def test_a_rigid_figure_thrown_at_the_floor_never_gains_energy():
    """200 random throws of a rigid Star-Man (pose held, tumbling, thrown down or sideways):
    the energy of the recorded rods (finite differences) never rises above its start by more
    than the differences' own error. Pins that hid a sliding velocity gained up to 28 %."""
    rng = np.random.default_rng(7)
    dt, steps, g = 0.01, 150, 9.81
    mass = STARMAN.mass
    worst = 0.0
    for _ in range(200):
        pose = rng.uniform(STARMAN.joint_min, STARMAN.joint_max)
        start = standing_state(
            STARMAN,
            rng.uniform(0.0, 2 * math.pi),
            pose,
            velocity=(rng.uniform(-3.0, 3.0), rng.uniform(-5.0, 1.0)),
            spin=rng.uniform(-10.0, 10.0),
        )
        start[1] += rng.uniform(0.0, 1.0)
        ends, _, _ = run(STARMAN, start, start[6 : 6 + len(pose)], 0.05, steps, dt)
        centres, velocity, spin = rod_motion(STARMAN, ends, dt)
        energy = (
            0.5 * (mass * (velocity**2).sum(axis=2)).sum(axis=1)
            + 0.5 * (STARMAN.inertia * spin**2).sum(axis=1)
            + g * (mass * centres[..., 1]).sum(axis=1)
        )
        # from the second sample (the first difference is one-sided)
        worst = max(worst, (energy[2:].max() - energy[1]) / abs(energy[1]))
    assert worst < 0.01
