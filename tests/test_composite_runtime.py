"""Concatenated controllers (§3): state and senses carry over at a switch."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from mosys.bsr.figure import bsr_figure
from mosys.bsr.search import record_run
from mosys.bsr.start import standing_state
from mosys.composite.concatenation import run_concatenation
from mosys.io.bsr_result import BsrController
from mosys.parsing.figure import parse_figure_spec

ROOT = Path(__file__).resolve().parents[1]
STARMAN = bsr_figure(parse_figure_spec(ROOT / "specs/figures/starman.fig"))


def held(pose_degrees, tau=0.2) -> BsrController:
    """A controller that holds one pose for ever (one time-based rule)."""
    return BsrController(
        kind="time",
        target=np.radians(np.asarray(pose_degrees, np.float64)).reshape(1, -1),
        tau=np.array([tau]),
        center=np.zeros((1, 0)),
        side=np.zeros((1, 0)),
        segment=np.array([1e9]),
        period=1e9,
    )


def test_splitting_a_run_in_two_phases_changes_nothing():
    start = standing_state(STARMAN, math.pi / 2 + 0.1, np.radians([45, -45, 20, -20]))
    squat = held([120, -120, 60, -60])
    whole = record_run(STARMAN, squat, start, 150, 0.01)
    split = run_concatenation(STARMAN, [squat, squat], [70, 80], start, 0.01)
    np.testing.assert_array_equal(split.rod_ends, whole.rod_ends)
    np.testing.assert_array_equal(split.com, whole.com)
    assert list(split.starts) == [0, 70, 150]
    assert np.all(split.phase[:70] == 0) and np.all(split.phase[70:] == 1)  # 70: the switch
    assert split.com[split.phase_samples(1)].shape == (81, 2)


def test_the_next_controller_takes_over_where_the_last_left_off():
    start = standing_state(STARMAN, math.pi / 2, np.radians([45, -45, 20, -20]))
    up, down = held([0, 0, 0, 0]), held([150, -150, 100, -100])
    motion = run_concatenation(STARMAN, [up, down], [100, 100], start, 0.01)
    first = record_run(STARMAN, up, start, 100, 0.01)
    np.testing.assert_array_equal(motion.rod_ends[:101], first.rod_ends)
    second = record_run(
        STARMAN,
        down,
        first.final_state,
        100,
        0.01,
        start_force=first.final_force,
        carry_over=True,
    )
    np.testing.assert_array_equal(motion.rod_ends[100:], second.rod_ends)
    assert not np.allclose(motion.rod_ends[100], motion.rod_ends[-1])
