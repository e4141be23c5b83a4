"""Luxo's motions table (the 1990 paper's §7): per motion of the show, how far it went, how high,
how far the base turned, whether and how fast it landed and settled, how deep it sank."""

from __future__ import annotations

import dataclasses

import pandas as pd

from mosys.animation.motion_measures import (
    BASE_FLAT_DEG,
    JOINT_DEG,
    REST_RATE,
    REST_SPEED,
    SETTLE_WITHIN,
    measure,
    motions,
)
from mosys.io.atomic import write_text_atomically
from mosys.io.controller_table import read_controller_table
from mosys.io.trajectory import read_trajectory


def motions_frame(trajectory_path: str, landing_table_path: str, budget: str) -> pd.DataFrame:
    """One row per motion of the trajectory; the standing pose is the landing controller's
    destination."""
    trajectory = read_trajectory(trajectory_path)
    standing = read_controller_table(landing_table_path).dest
    rows = []
    for motion in motions(trajectory):
        row = dataclasses.asdict(measure(trajectory, motion, standing))
        rows.append(
            {
                # + 0.0: a value that rounds to -0 is written 0
                key: round(value, 4) + 0.0 if isinstance(value, float) else value
                for key, value in row.items()
            }
        )
    frame = pd.DataFrame(rows)
    frame["budget"] = budget
    return frame


def write_luxo_table(
    trajectory_path: str, landing_table_path: str, csv_path: str, md_path: str, budget: str
) -> pd.DataFrame:
    """Write the motions table as CSV and Markdown (each atomically)."""
    frame = motions_frame(trajectory_path, landing_table_path, budget)
    write_text_atomically(csv_path, frame.to_csv(index=False))
    caption = (
        f"Luxo's show ({trajectory_path}), after van de Panne et al. (1990), §7, one row per "
        "motion (a motor program and the landing that follows). distance: the base centre's "
        "x displacement (Luxo faces -x); peak height: the base centre's highest point above its "
        "start; rotation: the base's net turn (a backflip is -360°). Touch-down: the first "
        "contact after take-off, since the motion began. Settled: base flat within "
        f"{BASE_FLAT_DEG:g}°, joints within {JOINT_DEG:g}° of standing, |vx|, |vy| <= "
        f"{REST_SPEED:g} m/s and angular rates <= {REST_RATE:g} deg/s, to the motion's end; "
        f"landed: touched down and settled within {SETTLE_WITHIN:g} s. Penetration: the "
        "deepest a contact point went into the ground, its distance to the nearest point of "
        "the terrain as the contact model measures it; rod_in_ground_m: the same for any "
        "point of a rod (the rods between the contact points meet no ground: an arm can pass "
        "through a ditch's floor). limb_touched: a contact point off the base (the head) "
        "touched the ground during the motion.\n\n"
    )
    write_text_atomically(md_path, caption + frame.to_markdown(index=False) + "\n")
    return frame
