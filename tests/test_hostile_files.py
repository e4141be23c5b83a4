"""Files in the wrong place: an input that is a FIFO (whose read would block forever) or a
directory, an output that is no file name, a directory, a special file, one of the command's
own inputs or another output of it, an output of the wrong kind. Each is refused with one
message and exit 2, before anything is written, and nothing is replaced (README, "Files in the
wrong place"; found by a hunt on 2026-12-05)."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from mosys.cli import main

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"


@pytest.fixture(scope="module")
def script(tmp_path_factory) -> Path:
    """A pendulum script that runs controller A only (the ``pendulum`` fixture's one table)."""
    path = tmp_path_factory.mktemp("script") / "swing.anim"
    path.write_text("state link -135,350\nswapcon link conA.ctab\nsim 0.4\n")
    return path


def refused(argv: list, capsys) -> str:
    """Run ``argv`` in-process: exit 2 (a usage error's SystemExit too), no traceback, one
    message line; that line."""
    try:
        code = main([str(arg) for arg in argv])
    except SystemExit as exit_:
        code = exit_.code
    assert code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    if lines[0].startswith("usage:"):  # argparse's usage, then its message
        return lines[-1]
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["run", "{fifo}", "--controllers", "{controllers}", "-o", "{out}/x.h5"],
            "{fifo}:1:1: expected a spec file, found 'a FIFO'",
        ),
        (
            ["compile", "{fifo}", "-o", "{out}/m.py"],
            "{fifo}:1:1: expected a spec file, found 'a FIFO'",
        ),
        (
            ["plot", "controls", "{fifo}", "-o", "{out}/c.png"],
            "mosys: {fifo}: a FIFO, not an HDF5 file",
        ),
        (
            ["plot", "controls", "{out}", "-o", "{out}/c.png"],
            "mosys: {out}: a directory, not an HDF5 file",
        ),
    ],
)
def test_an_input_that_is_a_fifo_or_a_directory_is_refused_at_once(
    pendulum, tmp_path, argv, message
):
    """In a new process with a time limit: a FIFO nobody writes blocked the verb forever."""
    fifo = tmp_path / "blocked.anim"
    os.mkfifo(fifo)
    out = tmp_path / "out"
    out.mkdir()
    names = {"fifo": fifo, "controllers": pendulum / "controllers", "out": out}
    done = subprocess.run(
        [sys.executable, "-m", "mosys.command", *(arg.format(**names) for arg in argv)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MOSYS_JOB_SERVER": ""},
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines()[-1] == message.format(**names)
    assert not list(out.iterdir())


def test_an_output_that_is_an_input_is_refused_and_the_input_kept(
    pendulum, script, tmp_path, capsys
):
    """``mosys run -o`` one of the controller tables its script runs: found only as the run
    reads it, so refused as it would be written, the table unchanged."""
    controllers = tmp_path / "controllers"
    shutil.copytree(pendulum / "controllers", controllers)
    table = controllers / "A.h5"
    before = table.read_bytes()
    message = refused(
        ["run", script, "--controllers", controllers, "--dynamics-dir", pendulum / "dynamics",
         "-o", table],
        capsys,
    )  # fmt: skip
    assert message == (
        f"mosys: {table}: cannot write it: it is an input of this command; write the output "
        "elsewhere"
    )
    assert table.read_bytes() == before
    assert sorted(path.name for path in controllers.iterdir()) == ["A.h5"]


def test_an_output_given_as_an_input_on_the_command_line_is_refused_before_running(
    pendulum, tmp_path, capsys
):
    table = pendulum / "controllers" / "A.h5"
    before = table.read_bytes()
    message = refused(["starts", table, "--dynamics", pendulum / "dynamics" / "link1.py",
                       "--x", 0, 1, 2, "--y", 0, 1, 2, "-o", table], capsys)  # fmt: skip
    assert message == (
        f"mosys starts: error: --output {table} is also an input of this command; write the "
        "output elsewhere"
    )
    assert table.read_bytes() == before


def test_two_outputs_naming_one_file_are_refused(pendulum, tmp_path, capsys):
    out = tmp_path / "same.png"
    message = refused(
        ["plot", "controller", pendulum / "controllers" / "A.h5", "--dynamics",
         pendulum / "dynamics" / "link1.py", "--portrait", out, "--torque", out],
        capsys,
    )  # fmt: skip
    assert (
        message
        == f"mosys plot controller: error: --portrait and --torque name the same file, {out}"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("output", "problem"),
    [
        ("", "cannot write '': expected a file name to write"),
        ("{tmp}/", "cannot write '{tmp}/': expected a file name to write"),
        ("{tmp}", "cannot write '{tmp}': it is a directory, not a file mosys may replace"),
        ("{tmp}/fifo.h5",
         "cannot write '{tmp}/fifo.h5': it is a FIFO, not a file mosys may replace"),
        ("{tmp}/file.h5/x.h5",
         "cannot write '{tmp}/file.h5/x.h5': {tmp}/file.h5 is a file, not a folder"),
        ("{tmp}/x.png", "expected a file name ending in .h5 or .hdf5, got '{tmp}/x.png'"),
    ],
)  # fmt: skip
def test_an_output_that_is_no_new_file_is_a_usage_error(
    pendulum, script, tmp_path, capsys, output, problem
):
    os.mkfifo(tmp_path / "fifo.h5")
    (tmp_path / "file.h5").write_bytes(b"kept")
    output = output.format(tmp=tmp_path)
    message = refused(
        ["run", script, "--controllers", pendulum / "controllers", "--dynamics-dir",
         pendulum / "dynamics", "-o", output],
        capsys,
    )  # fmt: skip
    assert message == f"mosys run: error: argument -o/--output: {problem.format(tmp=tmp_path)}"
    assert stat.S_ISFIFO(os.stat(tmp_path / "fifo.h5").st_mode)  # not replaced by a file
    assert (tmp_path / "file.h5").read_bytes() == b"kept"
    assert sorted(path.name for path in tmp_path.iterdir()) == ["fifo.h5", "file.h5"]


def test_a_bad_second_output_is_refused_before_the_first_is_written(pendulum, tmp_path, capsys):
    good, bad = tmp_path / "portrait.png", tmp_path / "torque.gif"
    message = refused(
        ["plot", "controller", pendulum / "controllers" / "A.h5", "--dynamics",
         pendulum / "dynamics" / "link1.py", "--portrait", good, "--torque", bad],
        capsys,
    )  # fmt: skip
    assert message == (
        f"mosys plot controller: error: argument --torque: expected a file name ending in .png "
        f"or .pdf or .svg, got '{bad}'"
    )
    assert not list(tmp_path.iterdir())


def test_a_long_output_name_is_written(pendulum, script, tmp_path):
    """The partial file's name keeps at most 120 bytes of the final one: a name of 240
    characters (NAME_MAX is 255) was refused as too long."""
    out = tmp_path / ("x" * 237 + ".h5")
    argv = ["run", script, "--controllers", pendulum / "controllers", "--dynamics-dir",
            pendulum / "dynamics", "--dt", "0.01", "-o", out]  # fmt: skip
    assert main([str(arg) for arg in argv]) == 0
    assert sorted(tmp_path.iterdir()) == [out]


def test_a_budget_that_is_not_text_is_a_usage_error(pendulum, tmp_path, capsys):
    """Bytes of a command line that are not UTF-8 reach Python as surrogates, which h5py and
    the tables could not write (a UnicodeEncodeError after the work)."""
    message = refused(
        ["pendulum-table", pendulum / "controllers" / "A.h5", "--dynamics",
         pendulum / "dynamics" / "link1.py", "--csv", tmp_path / "t.csv", "--md",
         tmp_path / "t.md", "--budget", "\udcff"],
        capsys,
    )  # fmt: skip
    assert message == (
        "mosys pendulum-table: error: argument --budget: expected a config's name (printable "
        "text, 1 to 200 characters), got '\\udcff'"
    )
    assert not list(tmp_path.iterdir())


def test_the_job_server_replaces_only_a_socket(tmp_path, capsys):
    victim = tmp_path / "victim.h5"
    victim.write_bytes(b"kept")
    message = refused(["job-server", victim, "--idle", "1"], capsys)
    assert message == f"mosys job-server: error: {victim} exists and is not a socket; not replaced"
    assert victim.read_bytes() == b"kept"
    message = refused(["job-server", tmp_path / "no" / "sock"], capsys)
    assert message == (
        f"mosys job-server: error: {tmp_path}/no/sock: expected a path in an existing folder "
        f"({tmp_path}/no)"
    )


def test_the_job_server_names_which_socket_path_is_too_long(tmp_path, capsys):
    """A path within a socket's 107 bytes whose folder leaves no room for the name the server
    binds first (``.mosys-job-server-PID``) was refused as itself too long."""
    folder = tmp_path / ("d" * (100 - len(str(tmp_path))))
    folder.mkdir()
    path = folder / "s"
    assert len(str(path)) <= 107
    message = refused(["job-server", path], capsys)
    unready = f"{folder}/.mosys-job-server-{os.getpid()}"
    assert message == (
        f"mosys job-server: error: {path}: its folder's path is too long: the server binds the "
        f"socket first as {unready} ({len(unready)} bytes; a socket's path is at most 107)"
    )
    long = folder / ("s" * 10)
    message = refused(["job-server", long], capsys)
    assert message == f"mosys job-server: error: {long}: a socket's path is at most 107 bytes"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["robustness-table", "r.h5", "--pair", "a", "a", "--csv", "t.csv", "--md", "t.md"],
         "mosys robustness-table: error: --pair a a: a robust search and another, its twin"),
        (["plot", "controls", "t.h5", "--control", "", "-o", "c.png"],
         "mosys plot controls: error: --control must name a control (default: the first)"),
        (["plot", "luxo", "t.h5"], "mosys plot luxo: error: give --strip, --forces and/or --gif"),
        (["plot", "luxo", "t.h5", "--motion", "hop", "--forces", "f.png"],
         "mosys plot luxo: error: --motion names the motion --strip draws: give --strip too"),
        (["plot", "bsr3d", "r.h5", "--filmstrip", "f.png", "--interval", "inf"],
         "mosys plot bsr3d: error: --interval must be a positive number of seconds, got inf"),
        (["plot", "car", "--map", "g.h5", "map.gif"],
         "mosys plot car: error: argument --map: expected a file name ending in .png or .pdf "
         "or .svg, got 'map.gif'"),
        (["plot", "car", "--map", "g.h5", "same.png", "--consistency", "g.h5", "same.png"],
         "mosys plot car: error: --map and --consistency name the same file, same.png"),
        (["composite", "s.comp", "--controllers", "a/seed1.h5", "--bsr-results", "r", "-o",
          "c.h5"], "mosys composite: error: give --controllers or --bsr-results, not both"),
        (["composite", "s.comp", "--controllers", "a/table.h5", "-o", "c.h5"],
         "mosys composite: error: --controllers a/table.h5: expected a seed file, "
         "SEARCH/seedK.h5"),
    ],
)  # fmt: skip
def test_options_that_would_do_nothing_or_the_wrong_thing_are_usage_errors(
    tmp_path, monkeypatch, capsys, argv, message
):
    monkeypatch.chdir(tmp_path)
    assert refused(argv, capsys) == message
    assert not list(tmp_path.iterdir())


def test_a_chain_given_to_a_search_that_continues_none_is_refused(tmp_path, capsys):
    chain = tmp_path / "seed1.h5"
    chain.write_bytes(b"")
    spec = SPECS / "bsr" / "starman_jump.bsr"
    message = refused(
        ["bsr-search", spec, "--seed", 1, "--chain", chain, "-o", tmp_path / "s.h5"], capsys
    )
    assert message == (
        f"mosys: {spec}: --chain given, but the spec has no 'chain' line (it starts at rest)"
    )
    assert sorted(tmp_path.iterdir()) == [chain]


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        ("NUMBA_NUM_THREADS", "0", "NUMBA_NUM_THREADS='0': expected a whole number >= 1"),
        (
            "MPLBACKEND",
            "bogus",
            "MPLBACKEND='bogus': expected one of matplotlib's backends, such as Agg (or unset it)",
        ),
    ],
)
def test_an_environment_numba_or_matplotlib_cannot_start_in_is_a_usage_error(
    tmp_path, variable, value, message
):
    """In a new process: a failed import of matplotlib leaves it half imported."""
    argv = ["dp", SPECS / "controllers" / "pendulum" / "A.ssc", "-o", tmp_path / "A.h5"]
    done = subprocess.run(
        [sys.executable, "-m", "mosys.command", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, variable: value, "MOSYS_JOB_SERVER": ""},
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines()[-1] == f"mosys: error: the environment's {message}"
    assert not list(tmp_path.iterdir())


def test_the_plot_suffixes_the_command_line_allows_are_those_plots_write():
    from mosys.cli.verb import PLOT
    from mosys.plots.style import FIGURE_FORMATS

    assert tuple(f".{name}" for name in FIGURE_FORMATS) == PLOT


def test_only_the_verbs_own_arguments_count_as_its_inputs(tmp_path, monkeypatch):
    """``mosys index listed.txt -o index`` run again: the output's name is also the verb's,
    which is no input of it (the start-up benchmark's second run was refused)."""
    monkeypatch.chdir(tmp_path)
    Path("listed.txt").write_text("")
    for _ in range(2):
        assert main(["index", "listed.txt", "-o", "index"]) == 0
    assert Path("index").is_file()
