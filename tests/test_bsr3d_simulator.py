"""The 3-D BSR simulator (``mosys.kernels.bsr3d_simulate``): momentum through deformations,
free rigid-body motion (conservation, the intermediate-axis instability), contact with the floor
(coming to rest without sinking, the paper's friction), and agreement with the 2-D simulator for
a figure that stays in a vertical plane."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.bsr.figure import load_bsr_figure
from mosys.bsr.start import standing_state as standing_state_2d
from mosys.kernels import bsr3d_contact as contact
from mosys.kernels import bsr3d_simulate as sim
from mosys.kernels import bsr_simulate as planar
from mosys.kernels import rotation3d
from mosys.parsing.tokens import Token

NAN = float("nan")


def rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def figure_arrays(rods, floor=0.0, gravity=9.81) -> sim.FigureArrays3D:
    """A figure from rods (parent, hinge m, offset deg, splay deg, length m, mass kg, (θ range),
    (ψ range) deg); each rod's endpoints its own (distal ends; and proximal of the root)."""
    n = len(rods)
    parent = np.array([r[0] for r in rods], np.int64)
    joint = np.array([-1 if r[0] < 0 else 2 * (i - 1) for i, r in enumerate(rods)], np.int64)
    rest = np.array([rz(math.radians(r[2])) @ ry(math.radians(r[3])) for r in rods])
    length = np.array([r[4] for r in rods], float)
    mass = np.array([r[5] for r in rods], float)
    limits = [angle for r in rods[1:] for angle in (r[6], r[7])]
    ends = [(0, 0)] + [(k, 1) for k in range(n)]
    return sim.FigureArrays3D(
        parent,
        np.array([r[1] for r in rods], float),
        rest,
        length,
        mass,
        np.full(n, 0.5),
        mass * length**2 / 12.0,
        joint,
        np.array(ends, np.int64),
        np.radians([low for low, _ in limits]),
        np.radians([high for _, high in limits]),
        gravity,
        floor,
        float(length.sum()),
    )


# a dog-like figure out of its plane: a spine and four splayed legs, a tail up and to the side
DOG = [
    (-1, 0.0, 0.0, 0.0, 1.0, 20.0, None, None),
    (0, 1.0, -90.0, 15.0, 0.6, 3.0, (-60, 60), (-30, 30)),
    (0, 1.0, -90.0, -15.0, 0.6, 3.0, (-60, 60), (-30, 30)),
    (0, 0.0, -90.0, 15.0, 0.6, 3.0, (-60, 60), (-30, 30)),
    (0, 0.0, -90.0, -15.0, 0.6, 3.0, (-60, 60), (-30, 30)),
    (0, 0.0, 150.0, 30.0, 0.5, 2.0, (-45, 45), (-45, 45)),
]


class Stepper:
    """A figure stepped from Python, one kernel step at a time, with its work space."""

    def __init__(self, figure: sim.FigureArrays3D, state: np.ndarray):
        self.figure = figure
        self.state = np.asarray(state, float).copy()
        self.work = sim.new_step_work(figure.parent.shape[0], figure.endpoints.shape[0])
        sim.start_step_work(figure, self.state, self.work)

    @property
    def angles(self) -> np.ndarray:
        j = self.figure.joint_min.shape[0]
        return self.state[sim.JOINTS : sim.JOINTS + j]

    def body(self) -> np.ndarray:
        """Refresh the body-frame quantities of the current pose; its inertia tensor (3, 3)."""
        j = self.figure.joint_min.shape[0]
        w = self.work
        sim.body_frame(
            *self.figure[:9],
            self.state[sim.JOINTS : sim.JOINTS + j],
            self.state[sim.JOINTS + j :],
            w.rod_ends,
            w.end_offset,
            w.end_velocity,
            w.frames,
            w.scratch,
            w.matrices[1],
            w.vectors[0, :3],
        )
        return self.work.matrices[1].copy()

    def rotation(self) -> np.ndarray:
        out = np.empty((3, 3))
        rotation3d.rotation_of(self.state[sim.QW : sim.QW + 4], out)
        return out

    def step(self, target: np.ndarray, tau: float, dt: float) -> None:
        sim.step(self.figure, self.state, target, tau, dt, self.work, True)

    def world_ends(self) -> np.ndarray:
        """(N, 2, 3) every rod's ends in the world now, m."""
        return self.work.rod_ends.copy()


def state_of(
    figure,
    centre=(0.0, 1.0, 0.0),
    angles=None,
    quaternion=(1.0, 0, 0, 0),
    momentum=(0, 0, 0),
    velocity=(0, 0, 0),
):
    j = figure.joint_min.shape[0]
    state = np.zeros(sim.JOINTS + 2 * j)
    state[0:3] = centre
    state[3:6] = velocity
    state[sim.QW : sim.QW + 4] = np.asarray(quaternion, float) / np.linalg.norm(quaternion)
    state[sim.LX : sim.LX + 3] = momentum
    if angles is not None:
        state[sim.JOINTS : sim.JOINTS + j] = angles
    return state


def rod_momenta(figure, ends, dt):
    """Linear momentum (3,) and angular momentum about the centre of mass (3,) of the figure
    from its rod ends at three consecutive samples (N, 2, 3) each (central differences)."""
    before, now, after = ends
    mass = figure.mass[:, None]
    com_frac = figure.com[:, None]

    def centres(e):
        return e[:, 0] + com_frac * (e[:, 1] - e[:, 0])

    centre = centres(now)
    velocity = (centres(after) - centres(before)) / (2 * dt)
    total = figure.mass.sum()
    c = (mass * centre).sum(axis=0) / total
    v = (mass * velocity).sum(axis=0) / total
    linear = total * v
    angular = (mass * np.cross(centre - c, velocity - v)).sum(axis=0)
    for k in range(figure.parent.shape[0]):
        u_now = (now[k, 1] - now[k, 0]) / figure.length[k]
        u_rate = ((after[k, 1] - after[k, 0]) - (before[k, 1] - before[k, 0])) / (
            2 * dt * figure.length[k]
        )
        angular += figure.inertia[k] * np.cross(u_now, u_rate)
    return linear, angular


def test_a_deformation_in_the_air_leaves_linear_and_angular_momentum_unchanged():
    figure = figure_arrays(DOG, floor=NAN, gravity=0.0)
    stepper = Stepper(
        figure, state_of(figure, momentum=(1.0, -2.0, 3.0), velocity=(0.5, 0.2, -0.1))
    )
    rng = np.random.default_rng(3)
    dt = 1e-4
    momenta = []
    for _ in range(4):
        target = rng.uniform(figure.joint_min, figure.joint_max)
        ends = []
        for n in range(400):
            stepper.step(target, 0.05, dt)
            ends.append(stepper.world_ends())
            if n % 100 == 50:
                momenta.append(rod_momenta(figure, ends[-3:], dt))
    linear = np.array([m[0] for m in momenta])
    angular = np.array([m[1] for m in momenta])
    expected = figure.mass.sum() * np.array([0.5, 0.2, -0.1])
    np.testing.assert_allclose(linear, np.tile(expected, (len(momenta), 1)), atol=2e-3)
    np.testing.assert_allclose(angular, np.tile([1.0, -2.0, 3.0], (len(momenta), 1)), atol=2e-3)
    # and the pose really changed (the test is not vacuous)
    assert np.ptp(stepper.angles) > 0.3


def rigid_run(figure, state, seconds, dt):
    """Step a figure that holds its pose (its target is its pose) in free flight; the body-frame
    angular velocity (steps, 3) rad/s and the kinetic energy of rotation (steps,) J."""
    stepper = Stepper(figure, state)
    target = stepper.angles.copy()
    tensor = stepper.body()
    spins, energies, momenta = [], [], []
    for _ in range(int(round(seconds / dt))):
        stepper.step(target, 0.1, dt)
        rotation = stepper.rotation()
        momentum = stepper.state[sim.LX : sim.LX + 3]
        spin = np.linalg.solve(tensor, rotation.T @ momentum)
        spins.append(spin)
        energies.append(0.5 * spin @ tensor @ spin)
        momenta.append(momentum.copy())
    return np.array(spins), np.array(energies), np.array(momenta), tensor


def principal(figure):
    """The principal axes (columns, ascending moments) of the figure at rest."""
    stepper = Stepper(figure, state_of(figure))
    moments, axes = np.linalg.eigh(stepper.body())
    return moments, axes


def test_a_tumbling_rigid_figure_conserves_angular_momentum_and_energy():
    figure = figure_arrays(DOG, floor=NAN, gravity=9.81)
    moments, axes = principal(figure)
    spin = axes @ np.array([2.0, 0.5, 1.0])
    momentum = (
        np.linalg.inv(np.linalg.inv(axes.T) @ np.diag(1 / moments) @ np.linalg.inv(axes)) @ spin
    )
    spins, energies, momenta, _ = rigid_run(figure, state_of(figure, momentum=momentum), 5.0, 1e-3)
    np.testing.assert_allclose(momenta, np.tile(momentum, (len(momenta), 1)), rtol=0, atol=1e-12)
    assert np.ptp(energies) / energies[0] < 1e-4
    # it does tumble: the body-frame spin changes direction
    assert np.ptp(spins, axis=0).max() > 0.5


@pytest.mark.parametrize("axis, stable", [(0, True), (1, False), (2, True)])
def test_rotation_about_the_intermediate_axis_is_unstable(axis, stable):
    figure = figure_arrays(DOG, floor=NAN, gravity=0.0)
    moments, axes = principal(figure)
    assert moments[0] < moments[1] < moments[2]
    body_spin = np.full(3, 0.01)
    body_spin[axis] = 3.0
    momentum = axes @ (moments * body_spin)  # body frame = world at the start
    spins, _, _, tensor = rigid_run(figure, state_of(figure, momentum=momentum), 20.0, 2e-3)
    along = spins @ axes[:, axis]
    if stable:
        assert along.min() > 0.95 * 3.0
    else:
        assert along.min() < -0.9 * 3.0  # it turned over


def test_a_dropped_figure_comes_to_rest_on_the_floor_without_sinking():
    figure = figure_arrays(DOG)
    tilt = (math.cos(0.2), 0.1, 0.05, 0.15)
    stepper = Stepper(
        figure, state_of(figure, centre=(0.0, 1.5, 0.0), quaternion=tilt, momentum=(2, 1, -3))
    )
    target = stepper.angles.copy()
    lowest = []
    for _ in range(3000):
        stepper.step(target, 0.05, 1e-3)
        lowest.append(stepper.world_ends()[:, :, 1].min())
    assert min(lowest) >= -1e-9
    before = stepper.world_ends()
    speed = np.linalg.norm(stepper.state[3:6])
    for _ in range(500):
        stepper.step(target, 0.05, 1e-3)
    assert speed < 1e-3
    assert np.abs(stepper.world_ends() - before).max() < 1e-3
    assert stepper.world_ends()[:, :, 1].min() == pytest.approx(0.0, abs=1e-6)


@settings(max_examples=90, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["fall", "spin", "deformation", "all"]))
def test_no_endpoint_falls_further_in_a_step_than_the_largest_fall(seed: int, moving: str):
    """The step passes over endpoints higher than ``largest_fall`` (plus the contact tolerance)
    without computing their motion: that bound must hold for every endpoint of any pose, fall,
    spin and deformation rate, each alone (so that each term is needed) and all together (the
    dog, its joints moving up to tens of rad/s)."""
    rng = np.random.default_rng(seed)
    figure = figure_arrays(DOG)
    j = figure.joint_min.shape[0]
    state = state_of(
        figure,
        angles=rng.uniform(figure.joint_min, figure.joint_max),
        quaternion=rng.normal(size=4),
        velocity=(0.0, -abs(rng.normal(0.0, 3.0)), 0.0) if moving in ("fall", "all") else (0, 0, 0),
    )
    if moving in ("deformation", "all"):
        state[sim.JOINTS + j :] = rng.normal(0.0, 20.0, j)
    body_rate = rng.normal(0.0, 5.0, 3) if moving in ("spin", "all") else np.zeros(3)
    stepper = Stepper(figure, state)
    stepper.body()
    w = stepper.work
    rotation = stepper.rotation()
    dt = 0.01
    fall = sim.largest_fall(stepper.state, body_rate, w.end_velocity, figure.reach, dt)
    falls = [
        -min(
            sim.endpoint_motion(
                stepper.state, rotation, body_rate, w.end_offset, w.end_velocity, e
            )[4],
            0.0,
        )
        * dt
        for e in range(figure.endpoints.shape[0])
    ]
    assert max(falls) <= fall * (1.0 + 1e-12)
    assert max(falls) > 0.0 or moving == "deformation"  # (every endpoint can rise then)


def planar_copy(figure2d) -> sim.FigureArrays3D:
    """The 3-D arrays of a 2-D BSR figure: every joint's ψ fixed at 0, rest = Rz(offset)."""
    j = figure2d.joint_min.shape[0]
    rest = np.array(
        [
            rz(o) if p >= 0 else np.eye(3)
            for o, p in zip(figure2d.offset, figure2d.parent, strict=True)
        ]
    )
    joint_min = np.zeros(2 * j)
    joint_max = np.zeros(2 * j)
    joint_min[0::2] = figure2d.joint_min
    joint_max[0::2] = figure2d.joint_max
    return sim.FigureArrays3D(
        figure2d.parent,
        figure2d.hinge,
        rest,
        figure2d.length,
        figure2d.mass,
        figure2d.com,
        figure2d.inertia,
        np.where(figure2d.joint >= 0, 2 * figure2d.joint, -1),
        figure2d.endpoints,
        joint_min,
        joint_max,
        figure2d.gravity,
        figure2d.floor,
        figure2d.reach,
    )


def test_a_figure_in_a_vertical_plane_moves_as_the_2d_simulator_moves_it():
    """Star-Man (2-D) kicking and waving on the floor for 4 s, stepped by both simulators."""
    figure = load_bsr_figure("specs/figures", "x.bsr", Token("starman", 1, 1))
    arrays = figure.arrays
    spatial = planar_copy(arrays)
    j = len(figure.joint_names)
    start = standing_state_2d(figure, math.pi / 2, np.radians([45, -45, 20, -20]))
    state3 = np.zeros(sim.JOINTS + 4 * j)
    state3[[0, 1, 3, 4]] = start[[0, 1, 2, 3]]
    state3[sim.QW] = math.cos(start[4] / 2)
    state3[sim.QW + 3] = math.sin(start[4] / 2)
    state3[sim.LX + 2] = start[5]
    state3[sim.JOINTS : sim.JOINTS + 2 * j : 2] = start[6 : 6 + j]
    stepper = Stepper(spatial, state3)
    n, e = arrays.parent.shape[0], arrays.endpoints.shape[0]
    rod_ends = np.empty((n, 2, 2))
    offsets, velocities = np.empty((e, 2)), np.empty((e, 2))
    scratch = np.empty((n, 8))
    _, inertia, spin = planar.figure_body_frame(
        arrays, start[6 : 6 + j], start[6 + j :], rod_ends, offsets, velocities, scratch
    )
    previous = np.array([spin / inertia])
    state2 = start.copy()
    rng = np.random.default_rng(1)
    targets = rng.uniform(arrays.joint_min, arrays.joint_max, (8, j))
    taus = rng.uniform(0.1, 0.3, 8)
    worst = 0.0
    for step in range(400):
        k = step // 50
        planar.step(
            *arrays[:11],
            arrays.gravity,
            arrays.floor,
            state2,
            targets[k],
            taus[k],
            0.01,
            previous,
            rod_ends,
            offsets,
            velocities,
            np.zeros(e),
            scratch,
            np.empty((3, 2, 2)),
            np.empty((e, 2)),
        )
        target3 = np.zeros(2 * j)
        target3[0::2] = targets[k]
        stepper.step(target3, taus[k], 0.01)
        worst = max(worst, np.abs(stepper.world_ends()[:, :, :2] - rod_ends).max())
        assert np.abs(stepper.world_ends()[:, :, 2]).max() == 0.0
    assert worst < 1e-9
    assert np.ptp(state2[0]) >= 0  # ran
    assert abs(state2[0] - start[0]) > 0.05  # the figure really moved along the floor


def contact_case(u, r, inverse_mass=1 / 42.1, spin_inertia=(3.0, 4.0, 2.5), world_inverse=None):
    """The impulses (count, 3) the floor gives points with velocities u and offsets r (count,
    3) from the centre of mass of a body of that mass and (diagonal) inertia (or inverse world
    inertia tensor (3, 3)), the points' velocities after them, and whether the impulses follow
    the friction rule (False: the floor's frictionless last resort)."""
    count = len(u)
    m = contact.MAX_CONTACTS
    uu, rr = np.zeros((m, 3)), np.zeros((m, 3))
    uu[:count], rr[:count] = u, r
    if world_inverse is None:
        world_inverse = np.diag(1.0 / np.asarray(spin_inertia))
    impulse = np.zeros((m, 3))
    responses = np.zeros((m, m, 3, 3))
    frictional = contact.contact_impulses(
        uu,
        rr,
        count,
        inverse_mass,
        world_inverse,
        impulse,
        responses,
        np.zeros((m + 4, m + 4)),
        np.zeros((3, m, m)),
        np.zeros((3, m)),
        np.arange(m),
        np.zeros(m),
        np.zeros((m, m, 9)),
        np.zeros((m, 3, 3)),
    )
    after = uu[:count].copy()
    for i in range(count):
        for j in range(count):
            after[i] += responses[i, j] @ impulse[j]
    return impulse[:count], after, frictional


def test_several_contacts_share_friction_in_the_ratio_of_their_normal_impulses():
    u = [[0.3, -0.5, 0.1], [0.2, -0.4, -0.2], [0.25, -0.6, 0.05]]
    r = [[0.4, -0.6, 0.3], [0.4, -0.6, -0.3], [-0.5, -0.6, 0.0]]
    impulse, after, frictional = contact_case(np.array(u), np.array(r))
    assert frictional
    normal = impulse[:, 1]
    assert (normal > 0).all()
    # none sinks (but for the compliance that splits three contacts' load: 1e-6 of a response)
    np.testing.assert_allclose(after[:, 1], 0.0, atol=1e-5)
    shares = normal / normal.sum()
    # neither slides nor spins on the floor on the whole
    np.testing.assert_allclose(shares @ after[:, [0, 2]], 0.0, atol=1e-9)
    twist = shares @ (np.array(r)[:, 2] * after[:, 0] - np.array(r)[:, 0] * after[:, 2])
    assert twist == pytest.approx(0.0, abs=1e-9)


def test_where_no_impulses_of_the_friction_rule_push_the_floor_still_holds_the_figure():
    """Two feet of a biped spreading its legs, its weight nearer one: shared friction needs a
    pulling normal impulse, and stopping either foot dead sinks the other. The floor gave no
    impulse at all; the figure sank, was lifted out by its position alone and gathered a fall's
    velocity (Rex stood 3.2 s so, reached -31 m/s, and was thrown by one 1,247 N s impulse).
    Now the normal impulses alone: both push, neither foot sinks, no friction for the step."""
    u = np.array([[0.0, -0.0971, 0.379], [0.0, -0.0971, -0.379]])
    r = np.array([[0.0, -0.6944, -0.098], [0.0, -0.6944, 0.198]])
    world_inverse = np.array([[0.671, 0.0, 0.0], [0.0, 4.2194, -0.32167], [0.0, -0.32167, 0.827]])
    impulse, after, frictional = contact_case(u, r, 1 / 18.0, world_inverse=world_inverse)
    assert not frictional
    assert (impulse[:, 1] > 0.5).all()
    np.testing.assert_array_equal(impulse[:, [0, 2]], 0.0)
    np.testing.assert_allclose(after[:, 1], 0.0, atol=1e-12)


def test_a_lone_point_that_stopping_dead_would_pull_is_stopped_horizontally_and_rises():
    """A lone point sliding fast whose full stop would tip the body up off it: the horizontal
    stop alone (no frictionless push, which the step's pin then turned into a hidden sliding
    velocity), after which it slides no more and does not sink."""
    u = np.array([[-3.0, -0.05, 1.0]])
    r = np.array([[0.6, -0.3, 0.2]])
    impulse, after, frictional = contact_case(u, r, 1 / 20.0, spin_inertia=(2.0, 2.0, 2.0))
    assert frictional
    assert impulse[0, 1] == 0.0 and np.abs(impulse[0, [0, 2]]).max() > 1.0
    np.testing.assert_allclose(after[0, [0, 2]], 0.0, atol=1e-12)
    assert after[0, 1] >= 0.0


def test_a_figure_spreading_its_legs_is_held_by_the_floor_at_every_step():
    """The biped of the test above, stepped: both feet stay on the floor and the floor pushes
    at every step, and the stored vertical velocity stays that of a figure standing, not of a
    fall (before: 12 steps with no force and -1.18 m/s, then a 16 N s impulse toppled it)."""
    biped = [
        (-1, 0.0, 0.0, -90.0, 0.3, 10.0, None, None),  # the pelvis, along +z
        (0, 0.0, -90.0, 0.0, 0.8, 3.0, (-60, 60), (-60, 60)),  # the legs, down
        (0, 0.3, -90.0, 0.0, 0.8, 3.0, (-60, 60), (-60, 60)),
        (0, 0.15, 90.0, 0.0, 0.5, 2.0, (-90, 90), (-90, 90)),  # a mast, up
    ]
    figure = figure_arrays(biped)._replace(com=np.array([0.2, 0.5, 0.5, 0.5]))
    # standing: start_step_work leaves the rods' ends in the body frame (not turned here)
    height = -Stepper(figure, state_of(figure)).work.rod_ends[:, :, 1].min()
    stepper = Stepper(figure, state_of(figure, centre=(0.0, height, 0.0)))
    target = np.zeros(figure.joint_min.shape[0])
    target[0], target[2] = math.radians(30), math.radians(-30)  # θ of each leg: spread
    feet = [list(map(tuple, figure.endpoints)).index(foot) for foot in ((1, 1), (2, 1))]
    for _ in range(12):
        stepper.step(target, 0.1, 0.01)
        assert stepper.work.end_force[feet].sum() > 0.0
        assert stepper.world_ends()[[1, 2], 1, 1].max() < 1e-3  # both feet down
        assert stepper.state[sim.VY] > -0.5  # free fall reaches -1.18 m/s in these 12 steps


def test_a_contact_that_barely_touches_does_not_make_friction_explode():
    """Two heels of a walking Rex, one carrying a quarter of the load, the paper's shares do not
    settle with a twist: slide only, and the horizontal impulses stay the size of the normal
    ones (a search once found the 4,000 N s this used to give and flew off at 25 m/s)."""
    u = np.array([[0.0363, -0.1048, 0.018], [-0.0275, -0.095, -0.0347]])
    r = np.array([[-0.0835, -0.6633, -0.1592], [-0.0234, -0.6632, 0.2383]])
    impulse, after, _ = contact_case(u, r)
    assert np.abs(impulse).max() < 10.0
    assert np.abs(after).max() < 0.2


def skew(v: np.ndarray) -> np.ndarray:
    """[v]x: the matrix of the cross product v x ."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def responses_of(r, count, inverse_mass, world_inverse):
    """The kernel's responses (M, M, 3, 3) among the first ``count`` points of r (M, 3)."""
    m = contact.MAX_CONTACTS
    responses, spins = np.zeros((m, m, 3, 3)), np.zeros((m, 3, 3))
    for j in range(count):
        contact.spin_per_impulse(r, j, world_inverse, spins)
    for i in range(count):
        for j in range(count):
            contact.response(r, i, j, inverse_mass, spins, responses)
    return responses


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_a_contacts_response_is_the_rigid_bodys(seed):
    """responses[i, j] (from the spin per impulse made once per point) is the rigid body's
    velocity change at r_i per unit impulse at r_j, E/M - [r_i]x I⁻¹ [r_j]x, written out
    independently here."""
    rng = np.random.default_rng(seed)
    m = contact.MAX_CONTACTS
    r = rng.normal(0.0, 0.5, (m, 3))
    a = rng.normal(size=(3, 3))
    world_inverse = np.linalg.inv(a @ a.T + np.eye(3))
    world_inverse = 0.5 * (world_inverse + world_inverse.T)
    inverse_mass = 1.0 / rng.uniform(1.0, 60.0)
    responses = responses_of(r, m, inverse_mass, world_inverse)
    for i in range(m):
        for j in range(m):
            expected = inverse_mass * np.eye(3) - skew(r[i]) @ world_inverse @ skew(r[j])
            np.testing.assert_allclose(responses[i, j], expected, rtol=0, atol=1e-12)


def plain_shares(u, r, responses, compliance, twisting, iterations):
    """The shared-friction fixed point of ``count`` contacts iterated plainly from even shares
    (at most ``iterations`` times),
    each iteration a dense solve of the whole system written out from the rule itself (unknowns:
    the normal impulses, the slide and, if twisting, the twist; equations: no point sinks, and
    the share-weighted horizontal velocity and twist vanish). The impulses (count, 3), or None if
    a normal impulse pulls on the way or the shares do not settle."""
    count = len(u)
    m = 3 if twisting else 2
    weight = np.full(count, 1.0 / count)

    def impulses(unknowns, weight):
        p = np.zeros((count, 3))
        p[:, 1] = unknowns[:count]
        slide_x, slide_z = unknowns[count], unknowns[count + 1]
        twist = unknowns[count + 2] if twisting else 0.0
        p[:, 0] = weight * (slide_x + twist * r[:, 2])
        p[:, 2] = weight * (slide_z - twist * r[:, 0])
        return p

    def residuals(unknowns, weight):
        p = impulses(unknowns, weight)
        after = u + np.einsum("ijab,jb->ia", responses, p)
        rows = after[:, 1] + compliance * unknowns[:count]
        across = [weight @ after[:, 0], weight @ after[:, 2]]
        if twisting:
            across.append(weight @ (r[:, 2] * after[:, 0] - r[:, 0] * after[:, 2]))
        return np.concatenate([rows, across])

    for _ in range(iterations):
        zero = residuals(np.zeros(count + m), weight)
        matrix = np.column_stack(
            [residuals(np.eye(count + m)[k], weight) - zero for k in range(count + m)]
        )
        unknowns = np.linalg.solve(matrix, -zero)
        normal = unknowns[:count]
        if (normal <= 0).any():
            return None
        updated = normal / normal.sum()
        settled = np.abs(updated - weight).max() <= 1e-12
        weight = updated
        if settled:
            return impulses(unknowns, weight)
    return None


def test_the_shared_friction_solve_finds_the_fixed_point_of_the_dense_plain_iteration():
    """The kernel inverts the system's normal block once (``_normal_block``) and mixes the
    shares (Anderson): where the plain iteration of a dense solve settles with every normal
    impulse pushing, the kernel ends at the same impulses; and for two contacts with no z in r
    or u (iterated plainly, as the 2-D rule is) it agrees on whether they push."""
    rng = np.random.default_rng(7)
    m = contact.MAX_CONTACTS
    compared = dict.fromkeys(range(2, m + 1), 0)
    planar_cases = 0
    in_plane = np.random.default_rng(11)
    for _ in range(400):
        # a body landing on points spread under its centre of mass, sliding and turning a little
        count = int(rng.integers(2, m + 1))
        around = 2.0 * np.pi * (np.arange(count) + rng.uniform(-0.3, 0.3, count)) / count
        reach = rng.uniform(0.2, 0.6, count)
        r = np.column_stack(
            [reach * np.cos(around), rng.uniform(-0.7, -0.5, count), reach * np.sin(around)]
        )
        u = np.column_stack(
            [
                rng.normal(0.0, 0.15, count),
                rng.uniform(-0.6, -0.3, count),
                rng.normal(0.0, 0.15, count),
            ]
        )
        planar = count == 2 and in_plane.uniform() < 0.5  # the 2-D rule's case
        if planar:
            r[:, 2] = 0.0
            u[:, 2] = 0.0
        a = rng.normal(size=(3, 3))
        world_inverse = np.linalg.inv(a @ a.T + np.diag(rng.uniform(0.5, 3.0, 3)))
        world_inverse = 0.5 * (world_inverse + world_inverse.T)
        inverse_mass = 1.0 / rng.uniform(5.0, 60.0)
        uu, rr = np.zeros((m, 3)), np.zeros((m, 3))
        uu[:count], rr[:count] = u, r
        responses = responses_of(rr, count, inverse_mass, world_inverse)
        compliance = contact.COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
        compliance = 0.0 if count < 3 else compliance
        impulse = np.zeros((m, 3))
        active = np.r_[np.ones(count), np.zeros(m - count)]
        system, pairs = np.zeros((m + 4, m + 4)), np.zeros((m, m, 9))
        scale_a = contact._normal_block(uu, rr, active, count, responses, system, compliance, pairs)
        assert scale_a > 0.0
        mixing, weight, share = np.zeros((3, m, m)), np.zeros(m), np.zeros(m)
        code = contact._shared_friction(
            uu, rr, active, count, impulse, system, mixing, weight, share, True, pairs, scale_a
        )
        # two in the plane iterate plainly in the kernel too, and as often; others settle more
        # slowly plainly
        iterations = contact.FIXED_POINT_ITERATIONS if planar else 500
        reference = plain_shares(u, r, responses[:count, :count], compliance, True, iterations)
        if planar:
            assert (code == -1) == (reference is not None)
            planar_cases += 1
        if reference is None:
            continue
        assert code == -1
        np.testing.assert_allclose(impulse[:count], reference, rtol=1e-7, atol=1e-9)
        compared[count] += 1
    # four points under a rigid body nearly always leave one pulling: compared when they do not
    assert compared[2] >= 20 and compared[3] >= 20 and planar_cases >= 20, (compared, planar_cases)
