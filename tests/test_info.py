"""Self-describing result files and ``mosys info``: every dataset of every kind of file mosys
writes has a ``unit``, every root the provenance attrs; a controller table's ``/axes`` are HDF5
dimension scales of its per-node datasets; ``mosys info`` reports each kind (exit 0) and refuses,
with a one-line message and exit 2, a file that is not HDF5 or not mosys's.

The files are made by mosys's own code at small sizes (conftest's ``made``): the pendulum's
tables, a script run on two of them, three BSR searches of two generations and a composite
search of one; the start grid is written by ``write_start_grid`` from outcomes given there
(evaluating real starts needs a car table: about 20 s)."""

from __future__ import annotations

import dataclasses
import json
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from mosys.cli import main
from mosys.io import info
from mosys.io.attributes import INDEX, MIXED, SI_STATE, SPEC, TEXT
from mosys.io.controller_table import (
    ControllerTable,
    read_controller_table,
    write_controller_table,
)
from mosys.io.provenance import PROVENANCE_KEYS, checkout_commit, provenance_attributes
from mosys.io.start_grid import read_start_grid
from mosys.io.trajectory import Contacts, read_trajectory, write_trajectory

# the vocabulary of docs/formats/README.md
UNITS = {"s", "m", "m/s", "deg", "deg/s", "deg/s^2", "N", "N*m", "1"}
UNITS |= {INDEX, TEXT, SI_STATE, SPEC, MIXED}
ALWAYS = [key for key in PROVENANCE_KEYS if key != "git_commit"]


def datasets(path: Path) -> dict[str, dict]:
    """Every dataset's attributes, by path."""
    found = {}
    with h5py.File(path, "r") as h5:
        h5.visititems(
            lambda name, item: (
                found.__setitem__(name, dict(item.attrs))
                if isinstance(item, h5py.Dataset)
                else None
            )
        )
    return found


@pytest.mark.parametrize(
    "kind",
    ["controller table", "trajectory", "BSR search result", "composite result", "start grid"],
)
def test_every_dataset_has_a_unit_and_the_root_its_provenance(made, kind):
    found = datasets(made[kind])
    assert found
    for name, attrs in found.items():
        assert attrs.get("unit") in UNITS, f"{kind} /{name}: unit {attrs.get('unit')!r}"
    with h5py.File(made[kind], "r") as h5:
        attrs = dict(h5.attrs)
    expected = provenance_attributes()
    assert {key: attrs[key] for key in ALWAYS} == {key: expected[key] for key in ALWAYS}
    # from a checkout (as the tests run) its commit; elsewhere none
    assert attrs.get("git_commit") == checkout_commit(Path(info.__file__).resolve().parents[1])
    if kind != "start grid":  # made from a table, not a spec
        assert len(attrs["spec_sha256"]) == 64


def test_the_units_each_kind_writes(made):
    units = {kind: {n: a["unit"] for n, a in datasets(path).items()} for kind, path in made.items()}
    assert units["controller table"] == {
        "axes/angle": "deg",
        "axes/omega": "deg/s",
        "torque": "N*m",
        "value": "s",
    }
    # the pendulum's state (angle, omega): two units, listed per column
    assert units["trajectory"] == {
        "t": "s",
        "state": "mixed",
        "control": "N*m",
        "controller": INDEX,
        "figure_motion/t": "s",
        "figure_motion/endpoints": "m",
        "figure_motion/com": "m",
    }
    state = datasets(made["trajectory"])["state"]
    assert state["units"].tolist() == ["deg", "deg/s"]  # the state order: angle, omega
    assert units["BSR search result"] == {
        "learning_curve/evaluations": "1",
        "learning_curve/best_fitness": "1",
        "best/controller/target": "deg",
        "best/controller/tau": "s",
        "best/controller/center": "1",
        "best/controller/side": "1",
        "best/figure_motion/t": "s",
        "best/figure_motion/endpoints": "m",
        "best/figure_motion/com": "m",
        "best/active_rule": INDEX,
        "best/final_state": SI_STATE,
        "best/final_force": "N",
    }
    motion = {"figure_motion/t": "s", "figure_motion/endpoints": "m", "figure_motion/com": "m"}
    assert units["composite result"] == {
        **motion,
        **{f"before/{name}": unit for name, unit in motion.items()},
        "phase": INDEX,
        "active_rule": INDEX,
        "before/phase": INDEX,
        "before/active_rule": INDEX,
        "search/best_score": "1",
    }
    assert units["start grid"] == {
        "start": MIXED,
        "parked": INDEX,
        "collided": INDEX,
        "parking_seconds": "s",
        "excluded": TEXT,
        "cost_to_go": "s",
        "path_length": "m",
    }
    assert datasets(made["start grid"])["start"]["units"].tolist() == [
        "m",
        "m",
        "deg",
        "deg",
        "m/s",
    ]
    assert read_start_grid(made["start grid"]).state_units == ("m", "m", "deg", "deg", "m/s")


def test_a_trajectory_told_its_units_writes_them_per_column(made, tmp_path):
    """Given state and control units, ``/state`` and ``/control`` list them (``units``), with
    the common one or ``mixed`` as ``unit``; contact points are in m and N; they read back."""
    trajectory = read_trajectory(made["trajectory"])
    samples = len(trajectory.t)
    told = dataclasses.replace(
        trajectory,
        state_units=("deg", "deg/s"),
        control_units=("N*m",),
        contacts=Contacts(np.zeros((samples, 1, 2)), np.zeros((samples, 1, 2)), ("link",), [1.0]),
    )
    write_trajectory(tmp_path / "told.h5", told)
    found = datasets(tmp_path / "told.h5")
    assert (found["state"]["unit"], found["state"]["units"].tolist()) == (MIXED, ["deg", "deg/s"])
    assert (found["control"]["unit"], found["control"]["units"].tolist()) == ("N*m", ["N*m"])
    assert (found["contacts/position"]["unit"], found["contacts/force"]["unit"]) == ("m", "N")
    back = read_trajectory(tmp_path / "told.h5")
    assert (back.state_units, back.control_units) == (("deg", "deg/s"), ("N*m",))


def test_the_axes_are_dimension_scales_of_every_per_node_dataset(pendulum_tables, tmp_path):
    """``/axes/<name>`` is a dimension scale named <name>, attached along its state dimension
    to ``/value``, ``/torque``, ``/dead_end``, ``/destination_index`` and ``/arrival_value``
    (labelled <name>);
    ``/torque``'s last dimension is labelled ``control``. The reader is not confused by the
    scales' attributes."""
    table = read_controller_table(pendulum_tables / "A.h5")
    several = dataclasses.replace(
        table,
        dead_end=np.zeros(table.value.shape, dtype=bool),
        destinations=(table.dest, {"angle": 90.0, "omega": 0.0}),
        destination_index=np.zeros(table.value.shape, dtype=np.int64),
        arrival_value=table.value / 2,
    )
    write_controller_table(tmp_path / "several.h5", several)
    names = table.state_order
    with h5py.File(tmp_path / "several.h5", "r") as h5:
        for name in names:
            assert h5py.h5ds.is_scale(h5["axes"][name].id)
            assert h5py.h5ds.get_scale_name(h5["axes"][name].id) == name.encode()
        for dataset in ("value", "torque", "dead_end", "destination_index", "arrival_value"):
            dims = h5[dataset].dims
            assert [dims[k].label for k in range(len(names))] == list(names), dataset
            assert [dims[k][0].name for k in range(len(names))] == [f"/axes/{n}" for n in names]
        assert h5["torque"].dims[len(names)].label == "control"
        assert len(h5["torque"].dims[len(names)]) == 0
        assert (h5["dead_end"].attrs["unit"], h5["destination_index"].attrs["unit"]) == (
            INDEX,
            INDEX,
        )
        assert h5["arrival_value"].attrs["unit"] == "s"
    back = read_controller_table(tmp_path / "several.h5")
    assert back.state_order == names and back.axis_units == ("deg", "deg/s")
    assert back.wrap == table.wrap and back.control_units == ("N*m",)
    for axis, expected in zip(back.axes, table.axes, strict=True):
        np.testing.assert_array_equal(axis, expected)
    np.testing.assert_array_equal(back.value, table.value)
    np.testing.assert_array_equal(back.destination_index, several.destination_index)
    assert back.destinations == several.destinations
    np.testing.assert_array_equal(back.arrival_value, several.arrival_value)
    assert table.arrival_value is None  # an interpolate table has none


def car_table(**changes) -> ControllerTable:
    """A 2 x 3 table over the car's x and speed with the car's two controls."""
    table = ControllerTable(
        state_order=("x", "speed"),
        control_names=("steer_rate", "wheel_accel"),
        axes=(np.array([0.0, 1.0]), np.array([-1.0, 0.0, 1.0])),
        axis_units=("m", "m/s"),
        wrap=(False, False),
        torque=np.zeros((2, 3, 2)),
        value=np.array([[1.0, 0.0, np.inf], [2.0, 1.0, np.nan]]),
        control_min=np.array([-60.0, -200.0]),
        control_max=np.array([60.0, 200.0]),
        effort_weight=np.zeros(2),
        dest={"x": 0.0, "speed": 0.0},
        figure="car",
        attrs={"wheelbase": 2.5},
    )
    return dataclasses.replace(table, **changes)


def test_torque_units_are_the_controls_units(tmp_path):
    """Told (``control_units``): as told; not told: the car's controls for a car's table (root
    attr ``wheelbase``), N*m for a figure's (hinge actuators)."""
    for name, table, units, unit in (
        ("car", car_table(), ["deg/s", "deg/s^2"], MIXED),
        ("told", car_table(control_units=("N", "N")), ["N", "N"], "N"),
        ("figure", car_table(attrs={}), ["N*m", "N*m"], "N*m"),
    ):
        write_controller_table(tmp_path / f"{name}.h5", table)
        torque = datasets(tmp_path / f"{name}.h5")["torque"]
        assert (torque["units"].tolist(), torque["unit"]) == (units, unit), name
        assert read_controller_table(tmp_path / f"{name}.h5").control_units == tuple(units)


def test_a_rewritten_file_records_the_process_that_wrote_it(pendulum_tables, tmp_path):
    """A table read and written again records the process that wrote it, not the one it was
    read from."""
    table = read_controller_table(pendulum_tables / "A.h5")
    stale = {"git_commit": "0" * 40, "mosys_version": "0.0.1", "numpy_version": "1.0"}
    write_controller_table(
        tmp_path / "again.h5", dataclasses.replace(table, attrs={**table.attrs, **stale})
    )
    with h5py.File(tmp_path / "again.h5", "r") as h5:
        written = {key: h5.attrs.get(key) for key in PROVENANCE_KEYS}
    expected = provenance_attributes()
    assert written == {key: expected.get(key) for key in PROVENANCE_KEYS}


# --- the commit of a checkout -----------------------------------------------------------------

COMMIT = "0123456789abcdef0123456789abcdef01234567"


def package_in(root: Path) -> Path:
    package = root / "src" / "mosys"
    package.mkdir(parents=True)
    return package


def test_the_commit_of_a_branch_a_packed_ref_a_detached_head_and_a_worktree(tmp_path):
    loose = tmp_path / "loose"
    (loose / ".git" / "refs" / "heads").mkdir(parents=True)
    (loose / ".git" / "HEAD").write_text("ref: refs/heads/main\n")
    (loose / ".git" / "refs" / "heads" / "main").write_text(COMMIT + "\n")
    assert checkout_commit(package_in(loose)) == COMMIT

    packed = tmp_path / "packed"
    (packed / ".git").mkdir(parents=True)
    (packed / ".git" / "HEAD").write_text("ref: refs/heads/main\n")
    (packed / ".git" / "packed-refs").write_text(
        f"# pack-refs with: peeled fully-peeled sorted\n{'f' * 40} refs/heads/other\n"
        f"{COMMIT} refs/heads/main\n^{'e' * 40}\n"
    )
    assert checkout_commit(package_in(packed)) == COMMIT

    detached = tmp_path / "detached"
    (detached / ".git").mkdir(parents=True)
    (detached / ".git" / "HEAD").write_text(COMMIT + "\n")
    assert checkout_commit(package_in(detached)) == COMMIT

    worktree = tmp_path / "worktree"
    worktree.mkdir()
    linked = loose / ".git" / "worktrees" / "worktree"
    linked.mkdir(parents=True)
    (linked / "HEAD").write_text("ref: refs/heads/main\n")
    (linked / "commondir").write_text("../..\n")
    (worktree / ".git").write_text(f"gitdir: {linked}\n")
    assert checkout_commit(package_in(worktree)) == COMMIT


def test_no_commit_outside_a_checkout_in_an_installed_copy_or_an_unborn_branch(tmp_path):
    assert checkout_commit(package_in(tmp_path / "plain")) is None
    installed = tmp_path / "repo"
    (installed / ".git").mkdir(parents=True)
    (installed / ".git" / "HEAD").write_text(COMMIT + "\n")
    site = installed / ".venv" / "lib" / "python3.11" / "site-packages" / "mosys"
    site.mkdir(parents=True)
    assert checkout_commit(site) is None
    unborn = tmp_path / "unborn"
    (unborn / ".git").mkdir(parents=True)
    (unborn / ".git" / "HEAD").write_text("ref: refs/heads/main\n")
    assert checkout_commit(package_in(unborn)) is None
    garbled = tmp_path / "garbled"
    (garbled / ".git").mkdir(parents=True)
    (garbled / ".git" / "HEAD").write_bytes(b"\xff\xfe not a ref")
    assert checkout_commit(package_in(garbled)) is None


# --- mosys info -------------------------------------------------------------------------------


def info_of(path: Path, capsys) -> str:
    assert main(["info", str(path)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    return out


def section(out: str, title: str) -> list[str]:
    """The lines of a section of ``mosys info``: from its title to the blank line."""
    lines = out.splitlines()
    start = lines.index(title)
    end = lines.index("", start) if "" in lines[start:] else len(lines)
    return lines[start:end]


def test_info_of_a_controller_table_shows_its_axes_and_controls_with_units(made, capsys):
    out = info_of(made["controller table"], capsys)
    assert out.startswith(
        f"{made['controller table']}: controller table, format_version 1 "
        "(docs/formats/controller_table.md)\n"
    )
    assert section(out, "axes (state_order):") == [
        "axes (state_order):",
        "  name   unit   min   max  count  step  wrap",
        "  angle  deg    -180  170  36     10    yes (period 360)",
        "  omega  deg/s  -500  500  21     50    no",
    ]
    assert section(out, "dimension scales (the /axes datasets):") == [
        "dimension scales (the /axes datasets):",
        "  dataset  dimensions",
        "  /value   angle, omega",
        "  /torque  angle, omega, control",
    ]
    assert section(out, "controls (control_names):") == [
        "controls (control_names):",
        "  name    unit  min  max  K    torque in table",
        "  torque  N*m   -10  10   0.1  -10 … 10",
    ]
    datasets_section = section(out, "groups and datasets:")
    assert datasets_section[0:2] == [
        "groups and datasets:",
        "  path         shape        dtype    unit   summary",
    ]
    assert "  /value       (36, 21)     float64  s      0 … " in "\n".join(datasets_section)
    for key in PROVENANCE_KEYS:
        assert f"\n  {key} " in out


def test_info_of_each_other_kind(made, capsys):
    out = info_of(made["trajectory"], capsys)
    assert section(out, "control columns (control_names):")[1:] == [
        "  name    unit  min  max",
        "  torque  N*m   0    10",
    ]
    assert section(out, "samples:") == ["samples:", "  41 samples, t 0 … 0.4 s", "  controllers: B"]

    out = info_of(made["start grid"], capsys)
    assert section(out, "start columns (state_order):") == [
        "start columns (state_order):",
        "  name     unit  min  max",
        "  x        m     -1   1.5",
        "  y        m     0.6  2",
        "  heading  deg   0    5",
        "  steer    deg   0    0",
        "  speed    m/s   0    0",
    ]
    assert section(out, "starts:") == [
        "starts:",
        "  3 starts, 1 parked; 2 counted (not excluded)",
        "  success rate 50.0% of the counted starts",
    ]
    assert (
        '  /excluded         (3,)    string   text                 2 distinct: "" ×2, '
        '"start pose overlaps an obst…" ×1\n' in out
    )
    assert "  /parking_seconds  (3,)    float64  s                    7.5; 2 nan\n" in out

    out = info_of(made["BSR search result"], capsys)
    assert section(out, "search:")[1] == (
        "  sense-based controller, 10 rules, joints: arm_a, arm_b, leg_a, leg_b"
    )
    assert "  /best/figure_motion: 251 samples, t 0 … 2.5 s, 2-D, 5 rods (torso, arm_a, " in out
    # the terms in full (the root attribute's line is cut at 80 characters), with the weights
    with h5py.File(made["BSR search result"]) as h5:
        terms = json.loads(h5.attrs["fitness_terms"])
    listed = " ".join(line.strip() for line in section(out, "search:")[3:])
    assert listed.startswith("fitness terms of the best motion: distance ")
    assert [part.split()[0] for part in listed.split(": ", 1)[1].split(", ")] == list(terms)
    assert f"max_height {terms['max_height']:.6g} (weight 25)" in listed

    out = info_of(made["composite result"], capsys)
    refined = section(out, "phases, refined (phases):")
    assert refined[1].split() == ["phase", "controller", "start", "(s)", "end", "(s)"]
    assert [line.split()[0] for line in refined[2:]] == ["cartwheel", "jump", "shuffle"]
    assert "  /before/figure_motion: " in out and "  /figure_motion: " in out


def test_info_measures_the_papers_rules_on_each_bsr_motion(made, capsys):
    """Depth below the floor and sliding lone contacts, measured as the tests of the pipeline's
    files measure them (a user had to find those functions to check a search of their own)."""
    from mosys.bsr.lone_contact import lone_contacts, sliding
    from mosys.io.bsr_result import read_bsr_result

    out = info_of(made["BSR search result"], capsys)
    motion = read_bsr_result(made["BSR search result"]).motion
    contacts = lone_contacts(motion.t, motion.endpoints)
    depth = max(0.0, -float(motion.endpoints[..., 1].min()))
    rules = section(out, "the paper's rules (README, 'The simulator'), measured:")
    assert rules[1:] == [
        f"  /best/figure_motion: deepest rod end {1000 * depth:.2f} mm below the floor; "
        f"{len(contacts)} lone contact{'' if len(contacts) == 1 else 's'}, "
        f"{len(sliding(contacts))} of them sliding 5 mm or more"
    ]
    out = info_of(made["composite result"], capsys)
    rules = section(out, "the paper's rules (README, 'The simulator'), measured:")
    assert [line.split(":")[0] for line in rules[1:]] == [
        "  /before/figure_motion",
        "  /figure_motion",
    ]
    assert "the paper's rules" not in info_of(made["trajectory"], capsys)  # a pendulum


def test_a_composite_result_with_only_the_contracts_groups_is_one(made, tmp_path, capsys):
    """DESIGN.md's composite result is its two figure_motion groups and root attrs; mosys
    recognised one only by its own /search/best_score, and said another tool's was none."""
    path = tmp_path / "contract_only.h5"
    shutil.copy(made["composite result"], path)
    with h5py.File(path, "a") as h5:
        for name in ("search", "phase", "active_rule", "before/phase", "before/active_rule"):
            del h5[name]
    out = info_of(path, capsys)
    assert out.startswith(f"{path}: composite result, format_version 1 ")
    argv = ["composite-table", str(path), "--csv", str(tmp_path / "t.csv")]
    assert main([*argv, "--md", str(tmp_path / "t.md")]) == 2  # mosys's reader needs its own
    assert capsys.readouterr().err == (
        f"mosys: {path}: a composite result without phase, active_rule, before/phase, "
        "before/active_rule, search/best_score, which mosys reads beside the contract "
        "(docs/formats/composite_result.md)\n"
    )


def test_info_of_a_file_of_an_older_mosys(tmp_path, capsys):
    """No units, no provenance, no scales: reported as such."""
    path = tmp_path / "old.h5"
    with h5py.File(path, "w") as h5:
        h5["axes/angle"] = np.array([0.0, 10.0])
        h5["axes/angle"].attrs.update({"unit": "deg", "wrap": False})
        h5["torque"] = np.zeros((2, 1))
        h5["value"] = np.array([0.0, np.inf])
        h5.attrs.update({"state_order": ["angle"], "control_names": ["torque"]})
    out = info_of(path, capsys)
    assert "made by: no provenance recorded (an older mosys)\n" in out
    assert "dimension scales (the /axes datasets):\n  none attached\n" in out
    assert "  /value       (2,)    float64  -     0; 1 +inf\n" in out


def test_summaries_read_block_by_block_agree_with_numpy(tmp_path, monkeypatch):
    """Values read a few rows at a time: the same min, max and counts as the whole array."""
    rng = np.random.default_rng(1)
    values = rng.normal(size=(50, 4, 3))
    values[rng.random(values.shape) < 0.1] = np.nan
    values[3, 1, 2], values[40, 0, 0] = np.inf, -np.inf
    with h5py.File(tmp_path / "v.h5", "w") as h5:
        h5["v"] = values
        monkeypatch.setattr(info, "BLOCK_ELEMENTS", 25)  # two rows (12 values each) a block
        summary = info.summarise(h5["v"])
    finite = np.where(np.isfinite(values), values, np.nan)
    assert (summary.nan, summary.posinf, summary.neginf) == (int(np.isnan(values).sum()), 1, 1)
    np.testing.assert_array_equal(summary.low, np.nanmin(finite, axis=(0, 1)))
    np.testing.assert_array_equal(summary.high, np.nanmax(finite, axis=(0, 1)))


def test_info_refuses_what_is_not_a_file_mosys_writes(tmp_path, capsys):
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5\n")
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["t"] = np.arange(3.0)
    for path, message in (
        (text, "not an HDF5 file (mosys info reads the .h5 files mosys writes)"),
        (
            foreign,
            "an HDF5 file, but not one mosys writes: it has the groups and datasets of none of "
            "its kinds (controller table, trajectory, BSR search result, composite result, "
            "start grid; docs/formats/)",
        ),
        (tmp_path / "missing.h5", "no such file"),
        (tmp_path, "not a file"),
    ):
        assert main(["info", str(path)]) == 2
        assert capsys.readouterr() == ("", f"mosys: {path}: {message}\n")


def test_info_on_a_file_that_is_not_hdf5_gives_no_traceback(tmp_path):
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5\n")
    done = subprocess.run(
        [sys.executable, "-m", "mosys.cli", "info", str(text)], capture_output=True, text=True
    )
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr == (
        f"mosys: {text}: not an HDF5 file (mosys info reads the .h5 files mosys writes)\n"
    )


def test_info_read_into_a_pipe_closed_early_stops_quietly(made):
    """``mosys info F | head -1``: the reader goes away after one line. The rest is not written,
    and no 'mosys: [Errno 32] Broken pipe' follows (it did): exit 141, as a Unix tool's."""
    command = [sys.executable, "-m", "mosys.cli", "info", str(made["composite result"])]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as process:
        first = process.stdout.readline()
        process.stdout.close()  # as head does after its line
        stderr = process.stderr.read().decode()
        code = process.wait()
    assert first.startswith(str(made["composite result"]).encode())
    assert (code, stderr) == (141, "")
