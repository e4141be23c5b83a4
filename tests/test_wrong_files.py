"""A verb given the wrong file: another kind of mosys file, an HDF5 file mosys did not write, a
file that is not HDF5, or a controller table of another figure. Each ends in one message that
names the file and what it is, exit 2, and no output (before ``mosys.io.contracts``, 64 of 240
such pairs of a verb's file argument and a file raised a KeyError or ValueError from inside
h5py or numpy: README, "The wrong file")."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from mosys.cli import main


@pytest.fixture(scope="module")
def files(pendulum, car_park, composite_workspace, tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("wrong_files")
    odd = root / "odd.h5"
    with h5py.File(odd, "w") as h5:
        h5["x"] = np.arange(3.0)
    text = root / "text.h5"
    text.write_text("not HDF5\n")
    return {
        "pendulum table": pendulum / "controllers" / "A.h5",
        "link1": pendulum / "dynamics" / "link1.py",
        "car table": car_park / "controllers" / "park.h5",
        "car": car_park / "dynamics" / "car.py",
        "bsr": sorted((composite_workspace.bsr_results / "starman_jump_robust").glob("*.h5"))[0],
        "composite": composite_workspace.result,
        "odd": odd,
        "text": text,
    }


def refused(argv: list[str], capsys, out: Path) -> str:
    """Run ``argv`` in-process: exit 2, no traceback, nothing written to ``out``; the message."""
    assert main([str(arg) for arg in argv]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not list(out.iterdir())
    return err.strip()


CASES = [
    (
        "plot controller bsr",
        lambda f, o: ["plot", "controller", f["bsr"], "--dynamics", f["link1"], "--portrait",
                      o / "p.png", "--torque", o / "t.png"],
        "mosys: {bsr}: not a controller table (a BSR search result; "
        "docs/formats/controller_table.md)",
    ),
    (
        "plot controls table",
        lambda f, o: ["plot", "controls", f["pendulum table"], "-o", o / "c.png"],
        "mosys: {pendulum_table}: not a trajectory (a controller table; "
        "docs/formats/trajectory.md)",
    ),
    (
        "bsr-table composite",
        lambda f, o: ["bsr-table", f["composite"], "--csv", o / "t.csv", "--md", o / "t.md"],
        "mosys: {composite}: not a BSR search result (a composite result; "
        "docs/formats/bsr_result.md)",
    ),
    (
        "composite-table odd",
        lambda f, o: ["composite-table", f["odd"], "--csv", o / "t.csv", "--md", o / "t.md"],
        "mosys: {odd}: not a composite result (it lacks figure_motion, before/figure_motion; "
        "docs/formats/composite_result.md)",
    ),
    (
        "pendulum-table text",
        lambda f, o: ["pendulum-table", f["text"], "--dynamics", f["link1"], "--csv",
                      o / "t.csv", "--md", o / "t.md"],
        "mosys: {text}: cannot read it as HDF5 (",
    ),
    (
        "car-table text start grid",
        lambda f, o: ["car-table", f["car table"], "--starts", f["text"], "--trajectories",
                      f["odd"], "--csv", o / "t.csv", "--md", o / "t.md"],
        "mosys: {text}: cannot read it as HDF5 (",
    ),
    (
        "starts pendulum table",
        lambda f, o: ["starts", f["pendulum table"], "--dynamics", f["car"], "--x", "0", "1", "2",
                      "--y", "1", "2", "2", "--quiet", "-o", o / "g.h5"],
        "mosys: {pendulum_table}: controller A (a table of figure 'link1'): the dynamics have no "
        "state variables angle, omega (theirs: x, y, heading, steer, speed)",
    ),
    (
        "plot controller car table",
        lambda f, o: ["plot", "controller", f["car table"], "--dynamics", f["link1"],
                      "--portrait", o / "p.png", "--torque", o / "t.png"],
        "mosys: {car_table}: controller park (a table of figure 'car'): the dynamics have no "
        "state variables x, y, heading, steer, speed (theirs: angle, omega)",
    ),
]  # fmt: skip


@pytest.mark.parametrize(("verb", "argv", "message"), CASES, ids=[case[0] for case in CASES])
def test_a_verb_given_the_wrong_file_says_which_and_what_it_is(
    files, tmp_path, capsys, verb, argv, message
):
    out = tmp_path / "out"
    out.mkdir()
    shown = refused(argv(files, out), capsys, out)
    expected = message.format(**{name.replace(" ", "_"): path for name, path in files.items()})
    assert shown.startswith(expected) if expected.endswith("(") else shown == expected


@pytest.mark.parametrize(
    ("kind", "argv", "attribute", "message"),
    [
        ("composite result", ["composite-table"], "budget", "no root attribute 'budget', which "
         "mosys reads here"),
        ("BSR search result", ["bsr-table"], "steps_per_second", "not a 2-D BSR result file: no "
         "root attribute steps_per_second"),
    ],
)  # fmt: skip
def test_a_table_of_a_file_without_an_attribute_it_reads_names_both(
    made, tmp_path, capsys, kind, argv, attribute, message
):
    """A file that keeps its contract but lacks an attribute of mosys's own that a table reads
    (one written before the attribute was added) stopped the table with a KeyError traceback."""
    old = tmp_path / "old.h5"
    old.write_bytes(made[kind].read_bytes())
    with h5py.File(old, "a") as h5:
        del h5.attrs[attribute]
    csv, md = tmp_path / "t.csv", tmp_path / "t.md"
    assert main([*argv, str(old), "--csv", str(csv), "--md", str(md)]) == 2
    assert capsys.readouterr().err == f"mosys: {old}: {message}\n"
    assert not csv.exists() and not md.exists()
