"""The real command line: bad input gives a file:line:column message, exit 2 and no output;
bad arguments an argparse error, exit 2; ``--version`` and the top-level help."""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SPECS

import mosys
from mosys.cli import FAMILIES, build_parser, main


def mosys_command(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "mosys.cli", *args], cwd=cwd, capture_output=True, text=True
    )


def test_broken_controller_spec(tmp_path):
    spec = tmp_path / "B.ssc"
    spec.write_text("dyn link1\nssd omega -500.0 fivehundred 21\n")
    done = mosys_command("dp", str(spec), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == f"{spec}:2:18: expected a number for max, found 'fivehundred'\n"
    assert list(tmp_path.iterdir()) == [spec]


def test_controller_spec_naming_an_unknown_state_variable(tmp_path, link1):
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    shutil.copy(link1.__file__, dynamics / "link1.py")
    spec = tmp_path / "A.ssc"
    spec.write_text(
        (SPECS / "controllers/pendulum/A.ssc")
        .read_text()
        .replace("ssd omega", "ssd omgea")
        .replace("omega=0", "omgea=0")
    )
    done = mosys_command(
        "dp", str(spec), "--dynamics-dir", str(dynamics), "-o", "out.h5", cwd=tmp_path
    )
    assert done.returncode == 2
    line = next(n for n, text in enumerate(spec.read_text().splitlines(), 1) if "omgea" in text)
    assert done.stderr == (
        f"{spec}:{line}:5: expected a state variable of figure 'link1' (one of 'angle', "
        "'omega'), found 'omgea'\n"
    )
    assert not (tmp_path / "out.h5").exists()


def test_broken_figure_spec(tmp_path):
    spec = tmp_path / "bad.fig"
    spec.write_text("gravity lots\n")
    done = mosys_command("compile", str(spec), "-o", "bad.py", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == f"{spec}:1:9: expected a number for gravity (m/s²), found 'lots'\n"
    assert not (tmp_path / "bad.py").exists()


def test_broken_script(tmp_path):
    script = tmp_path / "s.anim"
    script.write_text("state link -135,350\nswapcon link conB.ctab\nsim soon\n")
    done = mosys_command(
        "run", str(script), "--controllers", str(tmp_path), "-o", "t.h5", cwd=tmp_path
    )
    assert done.returncode == 2
    assert done.stderr == f"{script}:3:5: expected a number for seconds, found 'soon'\n"
    assert not (tmp_path / "t.h5").exists()


def test_script_naming_a_missing_controller(tmp_path):
    script = tmp_path / "s.anim"
    script.write_text("state link -135,350\nswapcon link conZ.ctab\nsim 0.4\n")
    done = mosys_command(
        "run", str(script), "--controllers", str(tmp_path), "-o", "t.h5", cwd=tmp_path
    )
    assert done.returncode == 2
    assert done.stderr == (
        f"{script}:2:14: expected a controller table ({tmp_path / 'Z.h5'} does not exist), "
        "found 'conZ.ctab'\n"
    )
    assert not (tmp_path / "t.h5").exists()


def test_a_file_that_is_not_a_controller_table(tmp_path):
    table = tmp_path / "A.h5"
    table.write_text("not HDF5\n")
    done = mosys_command("plot", "controller", str(table), "--torque", "t.png", cwd=tmp_path)
    assert done.returncode == 2
    # the file, then h5py's own words for a file that is not HDF5 (mosys.io.contracts)
    assert done.stderr == (
        f"mosys: {table}: cannot read it as HDF5 (Unable to synchronously open file (file "
        "signature not found))\n"
    )
    assert not (tmp_path / "t.png").exists()


def test_dynamics_module_from_an_older_mosys(tmp_path):
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    (dynamics / "link1.py").write_text('Q_NAMES = ("angle",)\n')
    spec = tmp_path / "A.ssc"
    spec.write_text((SPECS / "controllers/pendulum/A.ssc").read_text())
    done = mosys_command(
        "dp", str(spec), "--dynamics-dir", str(dynamics), "-o", "out.h5", cwd=tmp_path
    )
    assert done.returncode == 2
    assert done.stderr == (
        f"mosys: {dynamics / 'link1.py'} is not a dynamics module of this mosys (it lacks "
        "STATE_NAMES): compile its figure again (mosys compile, or snakemake, which does so "
        "when mosys changes)\n"
    )
    assert not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize(
    ("source", "raised"),
    [
        ('raise RuntimeError("boom")\n', "RuntimeError: boom"),
        ("x = (\n", "SyntaxError: '(' was never closed"),
        ("import sys\nsys.exit(3)\n", "SystemExit: 3"),
    ],
)
def test_a_dynamics_file_that_fails_to_import(tmp_path, source, raised):
    """Any Python file can be named as a figure's dynamics: importing it is checked as reading
    any input is (the wrong-file matrix found the exception escaping, or exit 3)."""
    dynamics = tmp_path / "bad.py"
    dynamics.write_text(source)
    done = mosys_command(
        "starts", str(tmp_path / "park.h5"), "--dynamics", str(dynamics), "--x", "0", "1", "2",
        "--y", "1", "2", "2", "-o", "g.h5", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.startswith(
        f"mosys: {dynamics} is not a dynamics module of this mosys (importing it raised {raised}"
    )
    assert done.stderr.endswith("): compile its figure again (mosys compile)\n")
    assert not (tmp_path / "g.h5").exists()


def test_index_of_missing_files(tmp_path, capsys):
    present = tmp_path / "present.txt"
    present.write_text("")
    output = tmp_path / "index.txt"
    missing = [str(tmp_path / "a.txt"), str(tmp_path / "b.txt")]
    assert main(["index", str(present), *missing, "-o", str(output)]) == 2
    assert capsys.readouterr().err == f"mosys: cannot index missing files: {', '.join(missing)}\n"
    assert not output.exists()
    assert main(["index", str(present), "-o", str(output)]) == 0
    assert output.read_text() == f"{present}\n"


def usage_error(verb: str, message: str) -> tuple[str, str]:
    """A usage error of ``verb`` ("plot car"; "" for mosys itself): the program argparse names
    in the usage line and the error line, and the error line's message."""
    return f"mosys {verb}".strip(), message


@pytest.mark.parametrize(
    ("argv", "error"),
    [
        (
            ["plot", "controller", "C.h5"],
            usage_error("plot controller", "give --portrait and/or --torque"),
        ),
        (
            ["plot", "controller", "C.h5", "--portrait", "P.png"],
            usage_error("plot controller", "--portrait needs --dynamics"),
        ),
        (["plot", "script", "T.h5"], usage_error("plot script", "give --path and/or --gif")),
        (
            ["plot", "car"],
            usage_error("plot car", "give --frames, --gif, --map and/or --consistency"),
        ),
        (
            ["plot", "car", "--gif", "A.gif"],
            usage_error("plot car", "--frames and --gif need trajectories"),
        ),
        (
            ["plot", "bsr", "R.h5"],
            usage_error("plot bsr", "give --learning, --filmstrip and/or --gif"),
        ),
        (
            ["plot", "composite", "R.h5"],
            usage_error("plot composite", "give --filmstrips, --search and/or --gif"),
        ),
        *(
            (
                [
                    "starts",
                    "T.h5",
                    "--dynamics",
                    "c.py",
                    "-o",
                    "G.h5",
                    "--x",
                    "0",
                    "1",
                    "2",
                    "--y",
                    *y,
                    *more,
                ],
                usage_error("starts", message),
            )
            for y, more, message in (
                (
                    ("0", "1", "2"),
                    ("--threads", "0"),
                    "--threads must be a whole number from 1 to 2147483647, got 0",
                ),
                (("0", "1", "2"), ("--dt", "0"), "--dt must be a number > 0, got 0.0"),
                (
                    ("0", "1", "2"),
                    ("--seconds", "nan"),
                    "--seconds must be a number > 0, got nan",
                ),
                (
                    ("0", "1", "0.5"),
                    (),
                    "--y's COUNT must be a whole number >= 1, got 0.5",
                ),
                (("nan", "1", "2"), (), "--y must be finite numbers, got nan 1.0 2.0"),
                (
                    ("0", "1", "1e6"),
                    (),
                    "at most 1,000,000 starts, asked for 2,000,000",
                ),
                (("2", "1", "2"), (), "--y's MIN must not exceed its MAX, got 2 1"),
                (("3.5", "3.6", "1"), (), "--y 3.5 3.6 1: one start needs MIN = MAX"),
            )
        ),
        # issue 27's verb fuzz: numeric options nothing checked (tracebacks and hangs)
        *(
            (argv, usage_error("run", message))
            for argv, message in (
                (["run", "S.anim", "--controllers", "c", "--dt", dt, "-o", "T.h5"], message)
                for dt, message in (
                    ("0", "--dt must be a number > 0, got 0.0"),
                    ("-1", "--dt must be a number > 0, got -1.0"),
                    ("inf", "--dt must be a number > 0, got inf"),
                    ("nan", "--dt must be a number > 0, got nan"),
                )
            )
        ),
        *(
            (
                ["composite", "S.comp", f"--{key}", value, "-o", "C.h5"],
                usage_error(
                    "composite",
                    f"--{key} must be a whole number from 1 to {2**31 - 1}, got {value}",
                ),
            )  # fmt: skip
            for key, value in (("q", "-1"), ("g", "0"), ("h", "2147483648"))
        ),
        (
            ["dp", "S.ssc", "--tol", "-0.001", "-o", "T.h5"],
            usage_error("dp", "--tol must be a number > 0, got -0.001"),
        ),
        (
            ["dp", "S.ssc", "--max-iterations", "9223372036854775808", "-o", "T.h5"],
            usage_error(
                "dp",
                "--max-iterations must be a whole number from 1 to 2147483647, got "
                "9223372036854775808",
            ),
        ),
        (
            ["bsr-search", "S.bsr", "--seed", "1", "--threads", "99999999999999999999999"]
            + ["-o", "R.h5"],
            usage_error(
                "bsr-search",
                "--threads must be a whole number from 0 to 2147483647, got "
                "99999999999999999999999",
            ),
        ),
        ([], usage_error("", "the following arguments are required: verb")),
        (
            ["compile", "F.fig"],
            usage_error("compile", "the following arguments are required: -o/--output"),
        ),
        (  # the verb's usage: the top level's named no verb
            ["info", "a.h5", "b.h5"],
            usage_error("info", "unrecognized arguments: b.h5"),
        ),
    ],
)
def test_bad_arguments(tmp_path, monkeypatch, capsys, argv, error):
    """mosys's own checks of a verb's arguments print what argparse's print: the verb's usage
    first, then ``mosys VERB: error: ...``."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    prog, message = error
    assert out == ""
    assert err.startswith(f"usage: {prog} [-h]")
    assert err.endswith(f"\n{prog}: error: {message}\n")
    assert err.count(": error: ") == 1
    assert list(tmp_path.iterdir()) == []


def test_version(tmp_path):
    done = mosys_command("--version", cwd=tmp_path)
    assert (done.returncode, done.stdout, done.stderr) == (0, f"mosys {mosys.__version__}\n", "")


TOP_LEVEL_HELP = (
    "usage: mosys [-h] [--version] VERB ...\n"
    "\n"
    "Motion synthesis for physically based animation: state-space controllers (van\n"
    "de Panne et al. 1990) and BSR controllers (Auslander et al. 1995). Each verb\n"
    "is one step of the Snakemake pipeline and works on its own too;\n"
    "`mosys VERB --help` gives its arguments. Exit codes: 0 done; 2 a bad spec,\n"
    "input file or argument (the message says where; no output file is written); 1\n"
    "anything else.\n"
    "\n"
    "equations of motion:\n"
    "  compile            figure spec (.fig) -> generated dynamics module\n"
    "state-space controllers (the 1990 paper):\n"
    "  dp                 controller spec (.ssc) -> controller table (.h5)\n"
    "  starts             a car controller from a grid of start states\n"
    "animation:\n"
    "  run                animation script (.anim) -> trajectory (.h5)\n"
    "BSR controllers (the 1995 paper):\n"
    "  bsr-search         BSR search spec (.bsr) -> result (.h5)\n"
    "composite motion (the 1995 paper):\n"
    "  composite          composite script (.comp) -> refined transition points\n"
    "                     (.h5)\n"
    "  edit               the concatenation editor: a slider per phase of a script\n"
    "                     (.comp)\n"
    "plots (mosys plot KIND):\n"
    "  plot controller    a controller's portrait and torque map\n"
    "  plot script        a script's path (Figure 16 style) and its GIF\n"
    "  plot controls      a control against time in several scripts, with slew\n"
    "                     limits\n"
    "  plot free-swing    Figure 5: free-swing orbits and separatrix of a 1-joint\n"
    "                     figure\n"
    "  plot car           car frames (Figure 19 style), a GIF, the success map\n"
    "  plot luxo          Luxo: a motion's strip (Figure 22), forces, a GIF\n"
    "  plot bsr           a BSR search: learning curves, filmstrip, GIF\n"
    "  plot bsr-learning  learning curves of BSR searches compared (Figure 7 style)\n"
    "  plot bsr3d         3-D BSR searches: filmstrip (Figures 15-17), GIF, figure\n"
    "  plot bsr3d-kinds   time- vs sense-based learning curves (Figure 7 style)\n"
    "  plot bsr3d-seeds   each seed's learning curve (Figure 8 style)\n"
    "  plot composite     a composite motion: filmstrips before/after, the search,\n"
    "                     a GIF\n"
    "the papers' tables:\n"
    "  pendulum-table     the Figure 13 table of the pendulum controllers\n"
    "  car-table          the car controller's table\n"
    "  luxo-table         Luxo's motions table\n"
    "  bsr-table          the BSR runs table\n"
    "  bsr3d-table        the 3-D BSR runs table\n"
    "  bsr3d-targets      the 3-D motions against their targets\n"
    "  composite-table    the composite-motion table\n"
    "  robustness-table   robust BSR searches against their plain twins\n"
    "pipeline:\n"
    "  index              write an aggregate target: the list of its files\n"
    "  job-server         fork each job's mosys command from one warm process\n"
    "looking inside results:\n"
    "  info               a result file (.h5): its kind, axes, units and datasets\n"
    "\n"
    "options:\n"
    "  -h, --help  show this help message and exit\n"
    "  --version   print the version\n"
    "\n"
    "To build everything the 1990 pendulum example makes, from the repository root:\n"
    "  snakemake results/pendulum_all\n"
    "README.md describes the other targets (results/car_all, results/luxo_all,\n"
    "results/bsr_all, results/bsr3d_all, results/composite_all,\n"
    "results/paper_tables, all), the spec formats and the verbs.\n"
)


def test_top_level_help_lists_every_verb_by_family(monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "80")
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    assert capsys.readouterr() == (TOP_LEVEL_HELP, "")


# Every verb the Snakemake rules and the README use, in the order `mosys --help` lists them.
VERBS = [
    "compile",
    "dp",
    "starts",
    "run",
    "bsr-search",
    "composite",
    "edit",
    "plot controller",
    "plot script",
    "plot controls",
    "plot free-swing",
    "plot car",
    "plot luxo",
    "plot bsr",
    "plot bsr-learning",
    "plot bsr3d",
    "plot bsr3d-kinds",
    "plot bsr3d-seeds",
    "plot composite",
    "pendulum-table",
    "car-table",
    "luxo-table",
    "bsr-table",
    "bsr3d-table",
    "bsr3d-targets",
    "composite-table",
    "robustness-table",
    "index",
    "job-server",
    "info",
]


def test_every_verb_is_declared_once_and_has_its_own_usage(capsys):
    assert [verb.name for family in FAMILIES for verb in family.verbs] == VERBS
    for name in VERBS:
        with pytest.raises(SystemExit) as exit_:
            main([*name.split(), "--help"])
        assert exit_.value.code == 0
        assert capsys.readouterr().out.startswith(f"usage: mosys {name} [-h]")


def test_every_argument_of_every_verb_says_what_it_is_and_its_default(capsys):
    """``mosys VERB --help`` explains each argument, and an option with a default shows it
    (``mosys dp --help`` listed spec, -o, --max-iterations and --quiet bare, and no verb said
    its defaults)."""
    parser = build_parser()
    for name in VERBS:
        verb_parser = parser
        for word in name.split():
            (verbs,) = [
                a for a in verb_parser._actions if isinstance(a, argparse._SubParsersAction)
            ]
            verb_parser = verbs.choices[word]
        bare = [a.dest for a in verb_parser._actions if not a.help]
        assert not bare, f"mosys {name}: {bare} have no help"
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    shown = " ".join(capsys.readouterr().out.split())
    assert "--dt DT simulator step, s (default: 0.001)" in shown
    assert "-o OUTPUT, --output OUTPUT trajectory (.h5)" in shown  # required: no default
    with pytest.raises(SystemExit):
        main(["starts", "--help"])
    assert "start headings, deg (default: 0.0)" in " ".join(capsys.readouterr().out.split())


def test_help_imports_no_numerical_library():
    code = (
        "import sys\n"
        "from mosys.cli import main\n"
        "try:\n"
        "    main(['--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "heavy = {'numpy', 'h5py', 'sympy', 'numba', 'matplotlib', 'pandas'}\n"
        "print(sorted(heavy & {name.partition('.')[0] for name in sys.modules}), file=sys.stderr)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert (done.returncode, done.stderr) == (0, "[]\n")


def test_index_imports_no_numerical_library(tmp_path):
    """``mosys index`` writes text: it started twice as slowly as the other light verbs once
    the atomic writers imported h5py at the top of their module."""
    (tmp_path / "x.h5").touch()
    code = (
        "import sys\n"
        "from mosys.cli import main\n"
        "assert main(['index', 'x.h5', '-o', 'index']) == 0\n"
        "heavy = {'numpy', 'h5py', 'sympy', 'numba', 'matplotlib', 'pandas'}\n"
        "print(sorted(heavy & {name.partition('.')[0] for name in sys.modules}), file=sys.stderr)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path
    )
    assert (done.returncode, done.stderr) == (0, "[]\n")
    assert (tmp_path / "index").read_text() == "x.h5\n"


def test_starts_off_the_tables_heading_or_steer_axis_are_refused():
    """A start at -70 deg of heading (the axis: -45..60) was run and counted as a failure;
    one at 45 deg of steer (the axis: +-30, the model's stop 35) parked. A wrapping axis has
    no ends."""
    from types import SimpleNamespace

    import numpy as np

    from mosys.cli.ssc import off_table_problem
    from mosys.errors import InputError

    table = SimpleNamespace(
        state_order=("x", "y", "heading", "steer", "speed"),
        axes=(None, None, np.linspace(-45, 60, 43), np.linspace(-30, 30, 5), None),
        wrap=(False, False, False, False, False),
        axis_units=("m", "m", "deg", "deg", "m/s"),
    )
    off_table_problem(table, {"heading": np.array([-45.0, 60.0]), "steer": np.array([30.0])})
    for name, value, axis in (("heading", -70.0, "-45..60"), ("steer", 45.0, "-30..30")):
        with pytest.raises(InputError) as error:
            off_table_problem(table, {name: np.array([0.0, value])})
        assert str(error.value) == (
            f"starts: --{name} {value:g} lies outside the table's {name} axis ({axis} deg): a "
            "start there is off the table"
        )
    wrapped = SimpleNamespace(**{**vars(table), "wrap": (False, False, True, False, False)})
    off_table_problem(wrapped, {"heading": np.array([-70.0])})


def test_starts_from_a_table_that_is_not_a_cars_is_refused(tmp_path, pendulum):
    """The pendulum's table with its own dynamics ran into a KeyError ('angle'): a traceback,
    exit 1. It is a bad input file: one line, exit 2, nothing written."""
    table = pendulum / "controllers" / "A.h5"
    done = mosys_command(
        "starts", str(table), "--dynamics", str(pendulum / "dynamics" / "link1.py"),
        "--x", "0", "1", "2", "--y", "3", "3", "1", "--quiet", "-o", "grid.h5", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"mosys: {table}: controller A (a table of figure 'link1', state angle, omega) is not a "
        "car's: mosys starts runs a car controller, whose state is x, y and heading (and steer "
        "and speed if it has them)\n"
    )
    assert list(tmp_path.iterdir()) == []
