"""The contract checker's command (``python tests/contract_check.py WORKDIR``, which CI runs on
the paper tables' build): its exit codes, and malformed files reported, not raised."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from contract_check import composite_result_problems, main, name_list_problems


def test_no_results_folder_is_refused(tmp_path: Path, capsys) -> None:
    assert main([str(tmp_path)]) == 2
    assert f"no results/ folder in {tmp_path}" in capsys.readouterr().err


def test_an_empty_results_folder_has_no_problems(tmp_path: Path, capsys) -> None:
    (tmp_path / "results").mkdir()
    assert main([str(tmp_path)]) == 0
    assert capsys.readouterr().out == "contract_check: no contract files; 0 problems\n"


def test_malformed_files_are_problems_named_by_file(tmp_path: Path, capsys) -> None:
    trajectories = tmp_path / "results/trajectories"
    trajectories.mkdir(parents=True)
    with h5py.File(trajectories / "no_state.h5", "w") as trajectory:
        trajectory["t"] = [0.0, 0.01]
        for name in ("state_order", "control_names", "controllers"):
            trajectory.attrs[name] = "x"
    with h5py.File(trajectories / "no_attrs.h5", "w") as trajectory:
        trajectory["t"] = [0.0]
    (trajectories / "not_hdf5.h5").write_bytes(b"not an HDF5 file")
    bsr = tmp_path / "results/bsr/walk"
    bsr.mkdir(parents=True)
    (bsr / "seed1.h5").write_bytes(b"")
    assert main([str(tmp_path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "contract_check: 1 bsr result, 3 trajectory; 7 problems"
    assert out[1:4] == [
        f"results/trajectories/no_attrs.h5: lacks root attr {name}"
        for name in ("state_order", "control_names", "controllers")
    ]
    unreadable = "cannot be read as the contract says"
    assert out[4].startswith(f"results/trajectories/no_state.h5: {unreadable} (KeyError: ")
    assert out[5].startswith(f"results/trajectories/not_hdf5.h5: {unreadable} (OSError: ")
    assert out[6].startswith(f"results/bsr/walk/seed1.h5: {unreadable} (OSError: ")
    assert out[7].startswith("chained searches cannot be read (OSError: ")


def test_names_stored_as_numbers_are_a_problem(tmp_path: Path) -> None:
    """An empty list of names written as a plain list is float64 to h5py: the trajectories'
    domain_violation_controllers and time-based searches' sense_names were, until 2026-12-07."""
    path = tmp_path / "names.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["controllers"] = []
        h5.attrs["state_order"] = np.array([], dtype=h5py.string_dtype())
        h5.create_group("best/controller").attrs["sense_names"] = []
        h5.attrs["other"] = []
    assert name_list_problems(path) == [
        "/ attr controllers: names stored as float64, not text",
        "/best/controller attr sense_names: names stored as float64, not text",
    ]


@pytest.mark.parametrize("argv", [[], ["."]])
def test_the_working_directory_is_the_default(tmp_path: Path, monkeypatch, argv) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results").mkdir()
    assert main(argv) == 0


@pytest.mark.parametrize(
    "phase",
    [
        {"name": "jump", "start": 0.0, "end": 1.0},  # no controller, an extra key of mosys's own
        {"controller": "jump", "start": 0.0},  # no end
        ["jump", 0.0, 1.0],  # not an object
    ],
)
def test_a_composite_phase_without_controller_start_and_end_is_a_problem(
    tmp_path: Path, phase
) -> None:
    """DESIGN.md: phases is a JSON list of {controller, start, end}; a phase that lacks one of
    them is a problem also where it has keys of its own (a strict-subset test let it pass)."""
    path = tmp_path / "show.h5"
    good = {"controller": "jump", "start": 0.0, "end": 1.0}
    with h5py.File(path, "w") as h5:
        for name, value in {
            "format_version": 1,
            "script": "show",
            "phases": json.dumps([phase]),
            "phases_before": json.dumps([good]),
            "score_before": 0.0,
            "score_after": 0.0,
            "simulations": 1,
            "spec_sha256": "0" * 64,
            "wall_seconds": 0.0,
        }.items():
            h5.attrs[name] = value
        for group in ("figure_motion", "before/figure_motion"):
            motion = h5.create_group(group)
            motion["t"] = np.array([0.0, 0.01])
            motion["endpoints"] = np.array([[[[0.0, 0.0], [0.0, 1.0]]]] * 2)
            motion["com"] = np.array([[0.0, 0.5]] * 2)
            for key, value in {
                "rod_names": np.array(["rod"], dtype=h5py.string_dtype()),
                "rod_mass": [1.0],
                "rod_length": [1.0],
                "rod_com": [0.5],
                "rod_inertia": [1 / 12],
                "gravity": 9.81,
                "terrain": "[[-1000, 0], [1000, 0]]",
                "contact": "none",
            }.items():
                motion.attrs[key] = value
    assert composite_result_problems(path, None) == [
        "phases: a phase without controller, start and end"
    ]
