"""The car controller's table (the 1990 paper's §6): its grid and states after collision removal
beside the paper's 13,250, generation time and peak memory, and how well it parks, from the
Figure 19 starts and from the start grid."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from mosys.errors import InputError
from mosys.io.atomic import write_text_atomically
from mosys.io.controller_table import read_controller_table
from mosys.io.start_grid import (
    CONSISTENCY_BAND,
    NO_WAY,
    NOT_FREE,
    StartGrid,
    consistency_summary,
    read_start_grid,
)
from mosys.io.trajectory import read_trajectory

PAPER_STATES = 13250  # the paper's car controller, after removing collision states


def start_grid_columns(grid: StartGrid) -> dict:
    """The start grid's columns of the car table: its starts, those that count (not excluded),
    the excluded ones by reason (``NOT_FREE``, ``NO_WAY``), the counted ones that parked
    (``StartGrid.succeeded``: never with a collision), the success rate over the counted starts,
    the collisions, the mean parking time (s) of the parked starts and the consistency of the
    table (``StartGrid.consistency``: parking time / cost-to-go at the start): its median, its
    90th percentile (linear interpolation) and the share of parked starts within
    CONSISTENCY_BAND of 1; the same against the cost-to-go to the whole arrival box
    (``arrival_consistency_*``, ``StartGrid.arrival_consistency``). NaN where no start parked
    or the grid has no such cost-to-go."""
    parked = grid.succeeded
    arrival = grid.arrival_consistency
    return {
        "grid_starts": int(grid.start.shape[0]),
        "grid_counted": int(grid.counted.sum()),
        "grid_excluded_not_free": int(np.sum(grid.excluded == NOT_FREE)),
        "grid_excluded_not_free_why": not_free_breakdown(grid),
        "grid_excluded_no_path": int(np.sum(grid.excluded == NO_WAY)),
        "grid_parked": int(parked.sum()),
        "grid_success_rate": round(grid.success_rate, 3),
        "grid_collisions": int(grid.collided.sum()),
        "mean_parking_s": round(float(grid.parking_seconds[parked].mean()), 2)
        if parked.any()
        else np.nan,
        **consistency_columns("consistency", grid.consistency if parked.any() else None),
        **consistency_columns("arrival_consistency", arrival if parked.any() else None),
    }


def not_free_breakdown(grid: StartGrid) -> str:
    """The ``NOT_FREE`` starts counted by what makes them so (``StartGrid.excluded_detail``),
    commonest first, e.g. 'overlaps front_car: 435; overlaps curb and front_car: 387'; "" for
    a grid without the details or with no such start."""
    if grid.excluded_detail is None:
        return ""
    details, counts = np.unique(
        grid.excluded_detail[grid.excluded == NOT_FREE].astype(str), return_counts=True
    )
    order = sorted(range(len(details)), key=lambda k: (-counts[k], details[k]))
    return "; ".join(f"{details[k]}: {counts[k]}" for k in order)


def consistency_columns(prefix: str, ratios: np.ndarray | None) -> dict:
    """``prefix``_median, _p90 and _within_25pct of consistency ratios (p,)
    (``consistency_summary``), rounded; NaN for None."""
    names = (f"{prefix}_median", f"{prefix}_p90", f"{prefix}_within_25pct")
    if ratios is None:
        return dict.fromkeys(names, np.nan)
    return dict(zip(names, (round(v, 3) for v in consistency_summary(ratios)), strict=True))


def parking_run(path: str | Path, controller: str) -> dict:
    """The root attributes of a car script's trajectory, with its parking outcome
    (``ssc.parking.ParkingOutcome.attributes``); InputError naming the file for another
    trajectory, or for a run that ``controller`` (a table's stem) did not drive."""
    trajectory = read_trajectory(path)
    attrs = trajectory.attrs
    if "parked" not in attrs or "collision_index" not in attrs:
        raise InputError(f"{path}: not a parking run (a trajectory with no parking outcome)")
    if controller not in trajectory.controllers:
        raise InputError(
            f"{path}: a run of controller {', '.join(trajectory.controllers)}, not of "
            f"{controller}, the table's"
        )
    return attrs


def car_row(
    table_path: str, grid: StartGrid, trajectory_paths: list[str], budget: str
) -> pd.DataFrame:
    """One row: the controller table, its start grid and its Figure 19 trajectories."""
    table = read_controller_table(table_path)
    attrs = table.attrs
    name = Path(table_path).stem
    figure19 = [parking_run(path, name) for path in trajectory_paths]
    row = {
        "controller": name,
        "grid": " x ".join(
            f"{name} {len(axis)}" for name, axis in zip(table.state_order, table.axes, strict=True)
        ),
        "grid_nodes": int(table.value.size),
        "table_states": int(attrs["table_states"]),
        "paper_states": PAPER_STATES,
        "removed_nodes": int(attrs["removed_nodes"]),
        "reachable_states": int(np.isfinite(table.value).sum()),
        "controls": " x ".join(
            f"{name} {int(n)}"
            for name, n in zip(table.control_names, attrs["control_samples"], strict=True)
        ),
        "generation_s": round(float(attrs["generation_seconds"]), 3),
        "peak_rss_MiB": round(int(attrs["peak_rss_bytes"]) / 2**20, 1),
        "iterations": int(attrs["iterations"]),
        "residual_s": float(attrs["residual"]),
        "figure19_parked": f"{sum(bool(a['parked']) for a in figure19)} of {len(figure19)}",
        "figure19_collisions": sum(int(a["collision_index"]) >= 0 for a in figure19),
        **start_grid_columns(grid),
        "budget": budget,
    }
    return pd.DataFrame([row])


def write_car_table(
    table_path: str,
    start_grid_path: str,
    trajectory_paths: list[str],
    csv_path: str,
    md_path: str,
    budget: str,
) -> pd.DataFrame:
    """Write the car table as CSV and Markdown (each atomically). InputError for a start grid
    or a run of another controller than the table's (a scene's table beside another's grid gave
    that grid's figures under its name)."""
    grid = read_start_grid(start_grid_path)
    controller = Path(table_path).stem
    if str(grid.attrs.get("controller")) != controller:
        raise InputError(
            f"{start_grid_path}: a start grid of controller {grid.attrs.get('controller')}, not "
            f"of {controller}, the table's"
        )
    frame = car_row(table_path, grid, trajectory_paths, budget)
    tolerance = json.loads(grid.attrs["parking_tolerance"])
    write_text_atomically(csv_path, frame.to_csv(index=False))
    caption = (
        "The self-parking car of van de Panne et al. (1990), §6, regenerated by mosys. States: "
        "grid nodes left after removing those in collision or outside the domain (the paper: "
        f"{PAPER_STATES:,}). Parked: within {tolerance['position_m']} m and "
        f"{tolerance['heading_deg']}° of the destination and at rest "
        f"(|speed| <= {tolerance['speed_m_s']} m/s) to the end of the run, with no collision "
        "at any instant. Start grid: a start that cannot park at all is excluded, and the "
        "success rate counts only the others (grid_counted): grid_excluded_not_free, the start "
        "pose overlaps an obstacle or lies outside the domain (grid_excluded_not_free_why: how "
        "many starts lie outside the domain and how many overlap which obstacles); "
        "grid_excluded_no_path, a search "
        "over poses (the steer's largest angle, forward and back) finds no collision-free path "
        "to the destination. Consistency: parking time / the table's cost-to-go at the start, "
        "for each counted start that parked; its median, 90th percentile and the share within "
        f"{100 * CONSISTENCY_BAND:.0f} % (|ratio - 1| <= {CONSISTENCY_BAND}); "
        "arrival_consistency: the same against the table's cost-to-go to the whole arrival box "
        "(/arrival_value: the runtime descends the cost-to-go to the box scaled by the table's "
        "aim; NaN for a table without /arrival_value, one whose policy line does not ask for "
        "it, as park.ssc's does not); mean_parking_s over the same starts; NaN where no start "
        "parked.\n\n"
    )
    write_text_atomically(md_path, caption + frame.T.to_markdown(headers=["", "value"]) + "\n")
    return frame
