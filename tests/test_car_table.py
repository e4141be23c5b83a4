"""The car table (``mosys car-table``): its start-grid columns from a start grid of known
outcomes (``start_grid_columns``), and the whole row and its files from a small hand-made
controller table, start grid and two Figure 19 trajectories."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from mosys.errors import InputError
from mosys.io.controller_table import ControllerTable, write_controller_table
from mosys.io.start_grid import OUTSIDE_DOMAIN, StartGrid, write_start_grid
from mosys.io.trajectory import Trajectory, write_trajectory
from mosys.paper_tables.car import start_grid_columns, write_car_table
from mosys.ssc.parking import NO_WAY, NOT_FREE, TOLERANCE

STATE_ORDER = ("x", "y", "heading", "steer", "speed")


def start_grid(parked_seconds=(8.0, 10.0, 12.0, 6.0)) -> StartGrid:
    """Ten starts: four that park (``parked_seconds`` s from a cost-to-go of 8, 8, 8 s and an
    unknown one: ratios 1.0, 1.25, 1.5 and NaN), one that collides, two that time out, and three
    not run: two not free, one without a path."""
    parks = len(parked_seconds)
    outcomes = ["parked"] * parks + ["collided", "late", "late"]
    excluded = [""] * len(outcomes) + [NOT_FREE, NOT_FREE, NO_WAY]
    n = len(excluded)
    parked = np.array([o == "parked" for o in outcomes] + [False] * 3)
    return StartGrid(
        start=np.column_stack([np.arange(n, dtype=float), np.full((n, 4), 1.0)]),
        state_order=STATE_ORDER,
        parked=parked,
        collided=np.array([o == "collided" for o in outcomes] + [False] * 3),
        parking_seconds=np.array([*parked_seconds] + [math.nan] * (n - parks)),
        excluded=np.array(excluded, dtype=object),
        cost_to_go=np.array([8.0, 8.0, 8.0, math.inf][:parks] + [9.0] * 3 + [math.inf] * 3),
        path_length=np.array([6.0] * 7 + [math.nan, math.nan, math.inf]),
        attrs={"parking_tolerance": json.dumps(TOLERANCE), "controller": "park"},
    )


GRID_COLUMNS = {
    "grid_starts": 10,
    "grid_counted": 7,
    "grid_excluded_not_free": 2,
    "grid_excluded_not_free_why": "",  # a grid without the details (a file before 2026-12-06)
    "grid_excluded_no_path": 1,
    "grid_parked": 4,
    "grid_success_rate": 0.571,  # 4 of the 7 counted starts, not of all 10
    "grid_collisions": 1,
    "mean_parking_s": 9.0,
    "consistency_median": 1.25,  # of the known ratios 1, 1.25, 1.5
    "consistency_p90": 1.45,  # 1.25 + 0.8 × (1.5 - 1.25)
    "consistency_within_25pct": 0.5,  # 1 and 1.25 (the band's edge) of the four
}
NO_ARRIVAL = dict.fromkeys(
    ("arrival_consistency_median", "arrival_consistency_p90", "arrival_consistency_within_25pct"),
    "nan",
)


def test_start_grid_columns():
    columns = start_grid_columns(start_grid())
    assert {k: "nan" if k in NO_ARRIVAL and math.isnan(v) else v for k, v in columns.items()} == (
        GRID_COLUMNS | NO_ARRIVAL
    )


def test_start_grid_columns_against_the_whole_arrival_box():
    """The ratios against ``arrival_cost_to_go`` (10, 8, 12 s and unknown: 0.8, 1.25, 1.0 and
    NaN) beside those against the cost-to-go."""
    grid = dataclasses.replace(
        start_grid(), arrival_cost_to_go=np.array([10.0, 8.0, 12.0, math.inf] + [9.0] * 6)
    )
    columns = start_grid_columns(grid)
    assert {k: columns[k] for k in GRID_COLUMNS} == GRID_COLUMNS
    assert {k: columns[k] for k in NO_ARRIVAL} == {
        "arrival_consistency_median": 1.0,
        "arrival_consistency_p90": 1.2,  # 1.0 + 0.8 × (1.25 - 1.0)
        "arrival_consistency_within_25pct": 0.75,  # 0.8, 1.25 and 1.0 of the four
    }


def test_the_starts_that_are_not_free_are_counted_by_why():
    """Commonest first, ties by name; the other starts' details are not counted."""
    grid = start_grid()
    details = ["overlaps curb", "overlaps curb and front_car", OUTSIDE_DOMAIN]
    grid = dataclasses.replace(
        grid,
        excluded=np.array([""] * 4 + [NOT_FREE] * 5 + [NO_WAY], dtype=object),
        excluded_detail=np.array([""] * 4 + [details[0]] * 2 + details + [""], dtype=object),
    )
    assert start_grid_columns(grid)["grid_excluded_not_free_why"] == (
        "overlaps curb: 3; overlaps curb and front_car: 1; reference point outside the domain: 1"
    )


def test_start_grid_columns_when_no_start_parks():
    columns = start_grid_columns(start_grid(parked_seconds=()))
    assert columns["grid_counted"] == 3 and columns["grid_parked"] == 0
    assert columns["grid_success_rate"] == 0.0
    for name in ("mean_parking_s", "consistency_median", "consistency_p90"):
        assert math.isnan(columns[name]), name
    assert math.isnan(columns["consistency_within_25pct"])


def write_table(path: Path) -> Path:
    """A 2-D controller table over x and heading, one node unreachable, with the attributes the
    car table reads."""
    axes = (np.array([0.0, 1.0, 2.0]), np.array([-90.0, 0.0, 90.0]))
    value = np.arange(9.0).reshape(3, 3)
    value[2, 2] = math.inf
    write_controller_table(
        path,
        ControllerTable(
            state_order=("x", "heading"),
            control_names=("steer_rate", "wheel_accel"),
            axes=axes,
            axis_units=("m", "deg"),
            wrap=(False, True),
            torque=np.zeros((3, 3, 2)),
            value=value,
            control_min=np.array([-1.0, -1.0]),
            control_max=np.array([1.0, 1.0]),
            effort_weight=np.array([0.0, 0.0]),
            dest={"x": 1.0, "heading": 0.0},
            figure="car",
            attrs={
                "table_states": 8,
                "removed_nodes": 1,
                "control_samples": np.array([5, 3]),
                "generation_seconds": 1.23456,
                "peak_rss_bytes": 3 * 2**20,
                "iterations": 17,
                "residual": 0.001,
            },
        ),
    )
    return path


def write_run(
    path: Path, parked: bool, collision_index: int, controllers: tuple[str, ...] = ("park",)
) -> Path:
    t = np.array([0.0, 0.1])
    write_trajectory(
        path,
        Trajectory(
            t=t,
            state=np.zeros((2, 5)),
            control=np.zeros((2, 2)),
            controller=np.zeros(2, dtype=np.int64),
            state_order=STATE_ORDER,
            control_names=("steer_rate", "wheel_accel"),
            controllers=controllers,
            attrs={"parked": parked, "collision_index": collision_index},
            motion=None,
        ),
    )
    return path


def test_write_car_table(tmp_path):
    table = write_table(tmp_path / "park.h5")
    grid = tmp_path / "start_grid.h5"
    write_start_grid(grid, start_grid())
    runs = [
        str(write_run(tmp_path / "park_1.h5", True, -1)),
        str(write_run(tmp_path / "park_2.h5", False, 1)),
    ]
    csv, md = tmp_path / "car.csv", tmp_path / "car.md"
    frame = write_car_table(str(table), str(grid), runs, str(csv), str(md), "paper")
    row = frame.iloc[0].to_dict()
    assert {name: row[name] for name in GRID_COLUMNS} == pytest.approx(GRID_COLUMNS)
    assert row["controller"] == "park" and row["grid"] == "x 3 x heading 3"
    assert row["reachable_states"] == 8 and row["controls"] == "steer_rate 5 x wheel_accel 3"
    assert row["figure19_parked"] == "1 of 2" and row["figure19_collisions"] == 1
    assert row["budget"] == "paper"
    assert list(pd.read_csv(csv).columns) == list(frame.columns)
    text = md.read_text()
    assert "the success rate counts only the others (grid_counted)" in text
    assert (
        "Consistency: parking time / the table's cost-to-go at the start, for each counted "
        "start that parked; its median, 90th percentile and the share within 25 % "
        "(|ratio - 1| <= 0.25)"
    ) in text
    assert "arrival_consistency: the same against the table's cost-to-go to the whole" in text
    rows = {line.split("|")[1].strip() for line in text.splitlines() if line.startswith("|")}
    assert {"consistency_within_25pct", "arrival_consistency_within_25pct"} <= rows


def test_a_start_grid_or_a_run_of_another_controller_is_refused(tmp_path):
    """A scene's table beside another scene's start grid gave that grid's figures under the
    table's name, exit 0; so would another controller's runs."""
    table = write_table(tmp_path / "garage.h5")
    grid = tmp_path / "start_grid.h5"
    write_start_grid(grid, start_grid())  # of controller park
    run = str(write_run(tmp_path / "park_1.h5", True, -1))
    csv, md = tmp_path / "car.csv", tmp_path / "car.md"
    with pytest.raises(InputError) as error:
        write_car_table(str(table), str(grid), [run], str(csv), str(md), "paper")
    assert str(error.value) == (
        f"{grid}: a start grid of controller park, not of garage, the table's"
    )
    park = write_table(tmp_path / "park.h5")
    other = str(write_run(tmp_path / "far_1.h5", True, -1, controllers=("farside",)))
    with pytest.raises(InputError) as error:
        write_car_table(str(park), str(grid), [run, other], str(csv), str(md), "paper")
    assert str(error.value) == f"{other}: a run of controller farside, not of park, the table's"
    assert not csv.exists() and not md.exists()
