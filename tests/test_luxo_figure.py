"""Luxo's figure: the spec compiles to the paper's five degrees of freedom;
with gravity, contacts and joint stops off and no torques, the free lamp conserves energy and
momentum; dropped onto the floor without torques it comes to rest without sinking in."""

from __future__ import annotations

import dataclasses
import json
import math
from itertools import pairwise
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from integrators import conservation_drift, settle

from mosys.dynamics.compile import compile_figure
from mosys.dynamics.load import load_dynamics
from mosys.parsing.figure import Terrain, parse_figure_spec, render_figure_spec

LUXO = Path(__file__).resolve().parents[1] / "specs" / "figures" / "luxo.fig"
STANDING = np.array([0.0, 0.0, 0.0, 0.0, math.radians(120.0)])  # x, y, base, hip, elbow
PENETRATION_TOLERANCE = 0.01  # m: the deepest any contact point may sink in (README)

pytestmark = pytest.mark.slow  # every test compiles the lamp: seconds of numba compiling


@pytest.fixture(scope="module")
def luxo(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    out = tmp_path_factory.mktemp("luxo") / "luxo.py"
    compile_figure(LUXO, out)
    return load_dynamics(out)


@pytest.fixture(scope="module")
def free_luxo(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """The same lamp with gravity, contacts, terrain and joint stops taken out."""
    figure = parse_figure_spec(LUXO)
    free = dataclasses.replace(figure, gravity=0.0, limits=(), contacts=(), terrain=Terrain())
    directory = tmp_path_factory.mktemp("free_luxo")
    spec = directory / "free_luxo.fig"
    spec.write_text(render_figure_spec(free))
    compile_figure(spec, directory / "free_luxo.py")
    return load_dynamics(directory / "free_luxo.py")


def ground_height(terrain: list[list[float]], x: float) -> float:
    """The terrain polyline's height at x, m (the last vertex at that x, after a riser)."""
    height = terrain[0][1]
    for (x0, y0), (x1, y1) in pairwise(terrain):
        if x0 <= x <= x1 and x1 > x0:
            height = y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return height


def test_luxo_has_the_papers_five_degrees_of_freedom(luxo: ModuleType) -> None:
    assert luxo.ROOT_KIND == "free"
    assert luxo.Q_NAMES == ("x", "y", "base", "hip", "elbow")
    assert len(luxo.STATE_NAMES) == 10
    assert luxo.INPUT_NAMES == ("", "", "", "hip_torque", "elbow_torque")
    assert luxo.ROD_NAMES == ("base", "lower", "upper")
    assert sum(luxo.ROD_MASS) == pytest.approx(1.3)
    # the base's two edges and the head touch the ground
    points = luxo.contact_points(STANDING)
    np.testing.assert_allclose(points[0], [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(points[1], [0.16, 0.0], atol=1e-12)
    np.testing.assert_allclose(points[2], luxo.endpoints(STANDING)[2, 1], atol=1e-12)
    terrain = json.loads(luxo.TERRAIN_JSON)
    assert ground_height(terrain, 0.5) == 0.0  # the floor
    assert ground_height(terrain, -0.8) == -0.3  # the ditch ahead (Luxo faces -x)
    assert ground_height(terrain, -1.0) == -0.15  # the ledge beyond it, below the step
    assert ground_height(terrain, -2.0) == 0.0


def test_standing_pose_balances_over_the_base(luxo: ModuleType) -> None:
    x, y = luxo.center_of_mass(STANDING)
    assert 0.0 < x < 0.16 and y > 0.05  # over the base
    head = luxo.endpoints(STANDING)[2, 1]
    assert head[1] > 0.05  # the head is off the floor


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_free_lamp_conserves_energy_and_momentum(free_luxo: ModuleType, seed: int) -> None:
    rng = np.random.default_rng(seed)
    q = np.concatenate([rng.uniform(-1, 1, 2), rng.uniform(-math.pi, math.pi, 3)])
    qd = rng.uniform(-3, 3, 5)
    start = free_luxo.momentum(q, qd)
    assert math.hypot(start[0], start[1]) > 0.1 and abs(start[2]) > 0.01
    worst = conservation_drift(
        free_luxo.qdd_into, free_luxo.energy, free_luxo.momentum, q, qd, 1e-3, 3000
    )
    assert np.all(worst < 1e-6), worst
    assert abs(qd[3:]).max() > 0.1  # the joints really moved


def test_dropped_lamp_rests_on_the_floor_without_sinking(luxo: ModuleType) -> None:
    """No torques: the arms fold onto their stops and the head comes down; the lamp bounces and
    settles on the floor; no contact point sinks deeper than the tolerance."""
    q = STANDING + np.array([0.3, 0.05, 0.0, 0.0, 0.0])
    qd = np.zeros(5)
    deepest = 0.0
    for _ in range(3000):  # 3 s in chunks of 1 ms, the depth checked after each
        settle(luxo.qdd_into, q, qd, 1e-4, 10)
        deepest = min(deepest, luxo.contact_points(q)[:, 1].min())
    assert abs(qd).max() < 1e-2, qd
    assert deepest > -PENETRATION_TOLERANCE, deepest
    forces = luxo.contact_forces(q, qd)
    np.testing.assert_allclose(forces.sum(axis=0)[1], 1.3 * luxo.GRAVITY, rtol=1e-2)


def test_depth_in_the_ground_is_to_the_nearest_point_of_the_terrain() -> None:
    """As the contact model measures it: a point touching the ditch's wall just below the
    floor's edge is 0.1 mm in, not the 9.8 cm down to the floor of the ditch above which it
    sits; a point on the ditch's floor, 2 cm down, 2 cm in; the air, 0."""
    from mosys.animation.motion_measures import ground_depth

    terrain = [
        [-1000.0, 0.0],
        [-0.9, 0.0],
        [-0.9, -0.3],
        [-0.65, -0.3],
        [-0.65, 0.0],
        [1000.0, 0.0],
    ]
    points = np.array([[-0.6499, -0.2], [-0.8, -0.32], [0.3, 0.1], [0.3, -0.004]])
    np.testing.assert_allclose(ground_depth(terrain, points), [0.0001, 0.02, 0.0, 0.004], atol=1e-9)
