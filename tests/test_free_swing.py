"""Figure 5 of the 1990 paper: the pendulum swinging freely, computed from the compiled dynamics,
against the pendulum's energy worked out by hand (a uniform rod of mass m and length L pinned
at one end: I = m L² / 3 about the pin, its centre of mass L/2 from the pin)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from conftest import SPECS, assert_png

from mosys.dynamics.compile import compile_figure
from mosys.dynamics.free_swing import free_motion, free_swing
from mosys.plots.free_swing import plot_free_swing

G = 9.81  # m/s², link1.fig
MASS = 1.0  # kg
LENGTH = 1.0  # m


def energy(orbit: np.ndarray) -> np.ndarray:
    """Kinetic plus potential energy (J) of the rod at (angle rad, rate rad/s) samples."""
    inertia = MASS * LENGTH**2 / 3.0
    return 0.5 * inertia * orbit[:, 1] ** 2 + MASS * G * (LENGTH / 2) * np.sin(orbit[:, 0])


def test_the_equilibria_and_the_separatrix_match_the_energy_by_hand(link1):
    swing = free_swing(link1)
    assert swing.hanging == pytest.approx(-math.pi / 2, abs=1e-6)
    assert swing.upright == pytest.approx(math.pi / 2, abs=1e-6)
    # from hanging to upright the centre of mass rises by L: 1/2 I w^2 = m g L
    expected = math.sqrt(2 * MASS * G * LENGTH / (MASS * LENGTH**2 / 3.0))
    assert swing.separatrix_rate == pytest.approx(expected, rel=1e-6)


def test_every_free_orbit_keeps_its_energy_and_the_librations_close(link1):
    swing = free_swing(link1)
    for orbit in swing.librations + swing.rotations + swing.separatrix:
        e = energy(orbit)
        assert np.ptp(e) <= 1e-7 * max(1.0, abs(e[0])), np.ptp(e)
    for orbit in swing.librations:  # swinging: never over the top, back through the start
        assert orbit[:, 0].max() < swing.upright
        assert np.abs(orbit[:, 1]).max() < swing.separatrix_rate
        start = orbit[0]
        returns = np.hypot(*(orbit[100:] - start).T)
        assert returns.min() < 0.02
    for orbit in swing.rotations:  # going over: the angle keeps growing (or falling)
        assert np.ptp(orbit[:, 0]) > 2 * math.pi
        assert (np.sign(orbit[:, 1]) == np.sign(orbit[0, 1])).all()


def test_the_free_swing_plot_is_drawn_and_figures_with_more_joints_are_refused(tmp_path, link1):
    out = tmp_path / "free_swing.png"
    plot_free_swing(link1, out)
    assert_png(out)
    luxo = tmp_path / "luxo.py"
    compile_figure(SPECS / "figures" / "luxo.fig", luxo)
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "mosys.cli",
            "plot",
            "free-swing",
            "--dynamics",
            str(luxo),
            "-o",
            str(tmp_path / "luxo.png"),
        ],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(
        f"mosys: {luxo}: expected a figure with one coordinate, such as the pendulum; this one "
        "has 5 ("
    ), result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "luxo.png").exists()


def test_free_motion_refuses_a_non_finite_swing(link1):
    from mosys.errors import InputError

    with pytest.raises(InputError, match="non-finite"):
        free_motion(link1, 0.0, float("inf"), 0.01)


def test_a_pendulum_with_a_joint_limit_is_refused_saying_why(tmp_path):
    """A limit's spring adds rest angles; the refusal read like a description of the figure."""
    from mosys.dynamics.free_swing import equilibria
    from mosys.dynamics.load import load_dynamics
    from mosys.errors import InputError

    spec = tmp_path / "arm.fig"
    spec.write_text(
        "gravity 9.81\nrod forearm length=0.6 mass=2 com=0.8\n"
        "pin forearm at=0,0 angle=theta rate=theta_dot actuator=motor\n"
        "limit forearm lower=-120 upper=100 stiffness=200 damping=1\n"
    )
    compile_figure(spec, tmp_path / "arm.py")
    with pytest.raises(InputError) as error:
        equilibria(load_dynamics(tmp_path / "arm.py"))
    assert str(error.value) == (
        "expected a figure with one stable and one unstable rest angle, such as the pendulum; "
        "this one has 2 stable and 2 unstable at rest (a joint limit or a contact adds rest "
        "angles, and the free-swing orbits need none)"
    )
