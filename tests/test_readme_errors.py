"""The README's spec errors against what mosys prints. Every example of the form
``FILE:LINE:COLUMN: expected ..., found ...`` in README.md (and docs/) has a recipe here: the file
the example describes (a shipped spec with a line edited, or a short text for a file that does
not ship), written at the example's own path in an empty directory, and the verb a user would
run on it. The verb must exit 2 and print the example, word for word as the README has it
(an inline example wrapped across lines read as one line; the memory limit's example with this
machine's memory for the README's). The examples are read from the
README at test time, so a message changed in either place fails here; an example added without
a recipe fails ``test_every_example_has_a_recipe``. Until this test they were compared by hand,
and six had gone stale.

Only the errors mosys raises before it computes anything are reproduced (no DP or search runs);
runtime errors (``the state became non-finite``) and warnings have no ``expected`` and are not
collected. The usage errors the README shows (``mosys VERB: error: ...``) and its errors of
input files (``mosys: FILE: ...``, the wrong kind of file) are held to what their command lines
print the same way.
"""

from __future__ import annotations

import enum
import os
import re
import shutil
from pathlib import Path

import h5py
import pytest
from conftest import ROOT, SPECS, SpecLines
from test_car import SMALL
from test_car_lookahead import ARRIVAL

from mosys.cli import main
from mosys.limits import physical_memory_bytes
from mosys.parsing.motor import parse_motor_program
from mosys.parsing.tokens import SpecError

DOCUMENTS = (ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md")))
# an example's start: its file (as the README names it), line and column, and "expected"
EXAMPLE = re.compile(r"(?<![\w/.])[\w/.]+\.(?:fig|ssc|bsr|anim|mot|comp):\d+:\d+: expected")


def documented_examples() -> list[str]:
    """Every example in the README and docs/, in order: a fenced or indented one to the end of
    its line, an inline one (after a backtick) to its closing backtick, its line breaks and the
    indentation after them read as one space."""
    examples = []
    for document in DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        for match in EXAMPLE.finditer(text):
            start = match.start()
            end = text.index("`" if text[start - 1] == "`" else "\n", start)
            examples.append(re.sub(r"\s*\n\s*", " ", text[start:end]).rstrip())
    return examples


EXAMPLES = documented_examples()


def example(start: str) -> str:
    """The one documented example that begins with ``start``."""
    found = [text for text in EXAMPLES if text.startswith(start)]
    assert len(found) == 1, f"{len(found)} examples begin with {start!r}"
    return found[0]


# --- the files ---------------------------------------------------------------------------------


class Special(enum.Enum):
    MISSING = "no file at the path"
    FIFO = "a named pipe at the path"


def shipped(relative: str) -> SpecLines:
    """The spec ``specs/relative`` as it ships."""
    return SpecLines((SPECS / relative).read_text(encoding="utf-8"))


def edited(relative: str, number: int, old: str, new: str) -> str:
    """The shipped spec ``specs/relative`` with ``old`` replaced by ``new`` in its line
    ``number``."""
    spec = shipped(relative)
    line = spec.text.splitlines()[number - 1]
    assert old in line, f"{relative}:{number} has no {old!r}: {line!r}"
    return spec.replace(number, line.replace(old, new, 1))


def from_line(relative: str, first: int) -> SpecLines:
    """The shipped spec ``specs/relative`` from its line ``first`` on: its comment header
    dropped, as the README lists it."""
    return SpecLines("".join(shipped(relative).text.splitlines(keepends=True)[first - 1 :]))


# The README's double pendulum listing ("Figure spec"), as a file of its own.
DOUBLE_PENDULUM = SpecLines(
    "rod upper length=1 mass=1\n"
    "rod lower length=1 mass=1\n"
    "pin upper at=0,0 angle=shoulder rate=shoulder_rate actuator=shoulder_torque\n"
    "hinge lower on=upper angle=elbow rate=elbow_rate actuator=elbow_torque\n"
)
ROD = "rod a length=1 mass=1\n"
PARK = "controllers/car/park.ssc"
PENDULUM_A = "controllers/pendulum/A.ssc"
SHUFFLE = "bsr/starman_shuffle.bsr"
SHOW = "composite/starman_show.comp"
JUMP = "bsr/starman_jump.bsr"

# The start of each example (FILE:LINE:COLUMN:, and its first words where two share a place)
# -> the file's text.
RECIPES: dict[str, str | Special] = {
    # section "Running the pipeline": a dry run's message for a missing script is the parser's
    "specs/scripts/nosuch.anim:1:1:": Special.MISSING,
    "specs/controllers/pendulum/B.ssc:7:18:": edited(
        "controllers/pendulum/B.ssc", 7, "500.0 21", "fivehundred 21"
    ),
    # "Figure spec"
    "specs/figures/link1.fig:7:17:": edited("figures/link1.fig", 7, "length=1", "length=0"),
    "specs/figures/dp.fig:4:16:": DOUBLE_PENDULUM.replace(4, "hinge lower on=uper"),
    "specs/figures/dp.fig:6:12:": (
        ROD + "rod b length=1 mass=1\nrod c length=1 mass=1\npin a\nhinge b on=c\nhinge c on=b\n"
    ),
    "specs/figures/dp.fig:4:1:": DOUBLE_PENDULUM.replace(4, "free lower"),
    "specs/figures/dp.fig:5:1:": DOUBLE_PENDULUM.replace(3, "# no root"),
    # "Controller spec": the shipped park.ssc with its dest at x=3; with ssd speed misspelled
    # (and speed=0 taken out of dest); with a control's samples 0
    "park.ssc:27:6:": edited(PARK, 27, "x=0", "x=3"),
    "park.ssc:24:5:": SpecLines(edited(PARK, 24, "ssd speed", "ssd sped")).replace(
        27, "dest x=0 y=1.15 heading=0"
    ),
    "park.ssc:25:24:": edited(PARK, 25, "60 5 0.0", "60 0 0.0"),
    # the policy line of the car test's small scene (tests/test_car.py), its line 15
    "x.ssc:15:8: expected one of": SMALL + "policy greedy x=0.1\n",
    "x.ssc:15:17:": SMALL + "policy lookahead\n",
    "x.ssc:15:18:": SMALL + "policy lookahead steer=5\n",
    "x.ssc:15:28:": SMALL + "policy lookahead x=0.1 aim=0\n",
    "x.ssc:15:46:": SMALL + "policy lookahead x=0.1 arrival_value aim=0.5 arrival_value\n",
    "x.ssc:15:20:": SMALL + "policy lookahead x=0\n",
    "x.ssc:6:8:": from_line(PENDULUM_A, 6).text + "policy lookahead angle=5\n",
    "x.ssc:15:8: expected a wheel_accel": (
        SpecLines(SMALL).replace(8, "torq wheel_accel 0 200 3 0") + ARRIVAL
    ),
    "specs/controllers/pendulum/A.ssc:7:18:": edited(PENDULUM_A, 7, "500.0 21", "fivehundred 21"),
    "specs/controllers/pendulum/A.ssc:10:12:": edited(PENDULUM_A, 10, "angle=0", "angle=5"),
    "specs/controllers/pendulum/A.ssc:10:1:": shipped(PENDULUM_A).drop(10),
    # "Conditional goals": the README's listing (G.ssc without its header), its second dest
    # at the first's node once wrapped
    "G.ssc:6:1:": from_line("controllers/pendulum/G.ssc", 5).replace(6, "dest angle=450 omega=0"),
    # "Animation script"
    "specs/scripts/pendulum.anim:2:1:": shipped("scripts/pendulum.anim").drop(2),
    "specs/scripts/pendulum.anim:2:14:": edited("scripts/pendulum.anim", 2, "conB.ctab", "B.h5"),
    "specs/scripts/pendulum.anim:1:17:": edited("scripts/pendulum.anim", 1, "-135,350", "-135,"),
    # "Keyframed motor programs": the README's listing (the shipped program under a one-line
    # header) with its third key at 0.5 s
    "swing.mot:7:5:": from_line("motor/link1/swing.mot", 8).replace(7, "key 0.5 angle=-150"),
    # "BSR search spec"
    "specs/bsr/starman_shuffle.bsr:6:24:": edited(SHUFFLE, 6, "dt=0.01", "dt=0.003"),
    "specs/bsr/starman_shuffle.bsr:5:27:": edited(SHUFFLE, 5, "rules=10", "rules=10 period=2"),
    "specs/bsr/starman_shuffle.bsr:10:39:": shipped(SHUFFLE).drop(11),
    "specs/bsr/starman_shuffle.bsr:11:38:": edited(SHUFFLE, 11, "torso.distal", "torso.middle"),
    # "Composite script"
    "specs/composite/starman_show.comp:18:19: expected an expression": edited(
        SHOW, 18, "max_t(min_i(y_i(t)))", "min_i(y_i(t))"
    ),
    "specs/composite/starman_show.comp:17:40:": edited(SHOW, 17, "215)", "215"),
    "specs/composite/starman_show.comp:18:19: expected a function": edited(
        SHOW, 18, "max_t(", "mean_t("
    ),
    "specs/composite/starman_show.comp:22:51:": edited(SHOW, 22, "+ shuffle", "+ shufle"),
    "specs/composite/starman_show.comp:26:1:": shipped(SHOW).drop(19),
    # "Hostile input"
    "link1.fig:7:17:": edited("figures/link1.fig", 7, "length=1", "length=1e-300"),
    "starman.fig:14:27:": edited("figures/starman.fig", 14, "mass=5", "mass=1e300"),
    "bad.fig:1:31:": "rod a length=1 mass=1 inertia=1e-300\npin a\n",
    "bad.fig:1:9:": "gravity 1e300\n" + ROD + "pin a\n",
    "bad.fig:2:10:": ROD + "pin a at=1e300,0\n",
    "bad.fig:3:22:": ROD + "pin a\nterrain floor height=-1e300\n",
    "car.fig:8:19:": edited("figures/car.fig", 8, "wheelbase=2.5", "wheelbase=1e-300"),
    "A.ssc:7:24:": edited(PENDULUM_A, 7, "500.0 21", "500.0 99999999999999999999"),
    "A.ssc:11:4:": shipped(PENDULUM_A).insert(11, "dt 1e-300"),
    "jump.bsr:5:24:": edited(JUMP, 5, "dt=0.01", "dt=1e-300"),
    "jump.bsr:7:9:": edited(JUMP, 7, "seeds 1 2", "seeds 1 99999999999999999999999"),
    # "Limits": a sim line past the steps limit at mosys run's dt, 1 ms
    "pendulum.anim:3:1:": edited("scripts/pendulum.anim", 3, "sim 0.4", "sim 100000"),
    # "Limits": a million torque samples against a limit of 4 GiB (ENVIRONMENT)
    "A.ssc:9:6:": edited(PENDULUM_A, 9, "10.0 11 0.1", "10.0 1000000 0.1"),
    # "Files in the wrong place"
    "specs/x.anim:1:1:": Special.FIFO,
}

# Examples with no recipe, and why.
# The environment a recipe runs in: the memory example's limit (its message also gives this
# machine's memory, which the comparison takes from this machine)
ENVIRONMENT = {"A.ssc:9:6:": {"MOSYS_MAX_MEMORY_GIB": "4"}}
MACHINE_MEMORY = re.compile(r"this machine has [\d,.]+ GiB")


def write(path: Path, text: str | Special) -> None:
    """The recipe's file at ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if text is Special.FIFO:
        os.mkfifo(path)
    elif text is not Special.MISSING:
        path.write_text(text, encoding="utf-8")


def dynamics(figure: str, request: pytest.FixtureRequest) -> str:
    """A folder ``dynamics`` holding the figure's module, compiled by its conftest fixture."""
    module = Path(request.getfixturevalue(figure).__file__)  # a content-addressed copy
    Path("dynamics").mkdir(exist_ok=True)
    shutil.copy(module, Path("dynamics") / f"{figure}.py")
    return "dynamics"


def command(path: str, text: str | Special, request: pytest.FixtureRequest) -> list[str]:
    """What a user runs on the spec at ``path`` (output ``out.*``)."""
    suffix = Path(path).suffix
    if suffix == ".fig":
        return ["compile", path, "-o", "out.py"]
    if suffix == ".ssc":  # the figure its dyn line names
        figure = re.search(r"^dyn (\w+)", text, re.MULTILINE).group(1)
        return ["dp", path, "--dynamics-dir", dynamics(figure, request), "-o", "out.h5"]
    if suffix == ".anim":  # the pendulum's six tables: steps are counted once they are loaded
        tables = str(request.getfixturevalue("pendulum_tables"))
        places = ["--controllers", tables, "--dynamics-dir", dynamics("link1", request)]
        return ["run", path, *places, "-o", "out.h5"]
    if suffix == ".bsr":
        figures = str(SPECS / "figures")  # seed 1: one of the shipped searches' seeds
        return ["bsr-search", path, "--seed", "1", "--figures", figures, "-o", "out.h5"]
    if suffix == ".comp":
        places = ["--figures", str(SPECS / "figures"), "--bsr-specs", str(SPECS / "bsr")]
        return ["composite", path, *places, "--bsr-results", "results/bsr", "-o", "out.h5"]
    raise AssertionError(f"no verb for {path}")


@pytest.mark.parametrize("start", list(RECIPES), ids=[start.rstrip(":") for start in RECIPES])
def test_the_example_is_what_mosys_prints(start, tmp_path, monkeypatch, capsys, request):
    machine = f"this machine has {physical_memory_bytes() / 2**30:,.2f} GiB"
    expected = MACHINE_MEMORY.sub(machine, example(start))
    path = start.split(":", 1)[0]
    text = RECIPES[start]
    monkeypatch.chdir(tmp_path)
    for variable, value in ENVIRONMENT.get(start, {}).items():
        monkeypatch.setenv(variable, value)
    write(tmp_path / path, text)
    if path.endswith(".mot"):
        # no verb reads a motor program alone: `mosys run` reads DIR/FIGURE/NAME.mot for a
        # script's motor line, with this parser, so the message would name DIR/link1/swing.mot
        with pytest.raises(SpecError) as error:
            parse_motor_program(path)
        assert str(error.value) == expected
        return
    code = main(command(path, text, request))
    assert (code, capsys.readouterr().err) == (2, expected + "\n")
    assert not list(tmp_path.glob("out.*")), "an output was written"


# --- usage errors (``mosys VERB: error: ...``, shown without the usage argparse prints first) -

USAGE_EXAMPLE = re.compile(r"^ *(mosys [a-z][a-z0-9 -]*: error: .*)$", re.MULTILINE)


def lines_matching(pattern: re.Pattern) -> list[str]:
    """The first group of every line of the README and docs/ that ``pattern`` matches."""
    return [
        match.group(1)
        for document in DOCUMENTS
        for match in pattern.finditer(document.read_text(encoding="utf-8"))
    ]


USAGE_EXAMPLES = lines_matching(USAGE_EXAMPLE)
A_TABLE = "results/controllers/pendulum/A.h5"  # an input that exists (written empty: never read)
# the start of each usage example (its verb and option) -> the command line that makes it
USAGE_RECIPES = {
    "mosys bsr-search: error: --seed": ["bsr-search", "jump.bsr", "--seed", "9" * 23]
    + ["-o", "out.h5"],
    "mosys run: error: --dt": ["run", "S.anim", "--controllers", "c", "--dt", "0", "-o", "out.h5"],
    "mosys run: error: argument -o/--output": ["run", "S.anim", "--controllers", "results"]
    + ["-o", "results/controllers"],
    "mosys plot controller: error: --portrait and --torque": ["plot", "controller", A_TABLE]
    + ["--dynamics", "link1.py", "--portrait", "out.png", "--torque", "out.png"],
}


@pytest.mark.parametrize("start", list(USAGE_RECIPES))
def test_the_usage_example_is_what_mosys_prints(start, tmp_path, monkeypatch, capsys):
    """The error line (the last) of what the verb prints; argparse prints its usage first."""
    [expected] = [text for text in USAGE_EXAMPLES if text.startswith(start)]
    monkeypatch.chdir(tmp_path)
    write(tmp_path / A_TABLE, "")
    with pytest.raises(SystemExit) as exit_:
        main(USAGE_RECIPES[start])
    err = capsys.readouterr().err
    assert (exit_.value.code, err.splitlines()[-1]) == (2, expected)
    assert err.startswith(f"usage: {expected.split(':')[0]} [-h]")
    assert not list(tmp_path.glob("out.*")), "an output was written"


# --- input files (``mosys: FILE: ...``): the wrong kind of file, a file that is not HDF5 -----

INPUT_EXAMPLE = re.compile(r"^ +(mosys: (?!error:)\S+: .*)$", re.MULTILINE)
INPUT_EXAMPLES = lines_matching(INPUT_EXAMPLE)


def placed(source: Path, path: str) -> str:
    """A copy of ``source`` at ``path`` (below the working directory)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    shutil.copy(source, path)
    return path


def a_trajectory_as_a_table(request: pytest.FixtureRequest) -> list[str]:
    trajectory = placed(
        request.getfixturevalue("made")["trajectory"], "results/trajectories/park_1.h5"
    )
    return ["plot", "controller", trajectory, "--torque", "out.png"]


def an_odd_file_as_a_composite(request: pytest.FixtureRequest) -> list[str]:
    with h5py.File("odd.h5", "w") as h5:
        h5["x"] = [1.0, 2.0]
    return ["composite-table", "odd.h5", "--csv", "out.csv", "--md", "out.md"]


def text_as_a_table(request: pytest.FixtureRequest) -> list[str]:
    Path("A.h5").write_text("not HDF5\n")
    return ["plot", "controller", "A.h5", "--torque", "out.png"]


def the_cars_table_on_the_pendulums_dynamics(request: pytest.FixtureRequest) -> list[str]:
    car = request.getfixturevalue("car_park")
    table = placed(car / "controllers" / "park.h5", "results/controllers/car/park.h5")
    link1 = f"{dynamics('link1', request)}/link1.py"
    return ["plot", "controller", table, "--dynamics", link1, "--portrait", "out.png"]


def a_run_writing_a_table_it_reads(request: pytest.FixtureRequest) -> list[str]:
    shutil.copytree(request.getfixturevalue("pendulum_tables"), "results/controllers/pendulum")
    script = placed(SPECS / "scripts" / "pendulum.anim", "pendulum.anim")
    places = ["--controllers", "results/controllers/pendulum"]
    places += ["--dynamics-dir", dynamics("link1", request)]
    return ["run", script, *places, "-o", "results/controllers/pendulum/A.h5"]


# the start of each example (``mosys: FILE: the first words``) -> what makes it
INPUT_RECIPES = {
    "mosys: results/trajectories/park_1.h5: not a": a_trajectory_as_a_table,
    "mosys: odd.h5: not a": an_odd_file_as_a_composite,
    "mosys: A.h5: cannot read": text_as_a_table,
    "mosys: results/controllers/car/park.h5: controller park": (
        the_cars_table_on_the_pendulums_dynamics
    ),
    "mosys: results/controllers/pendulum/A.h5: cannot write": a_run_writing_a_table_it_reads,
}


@pytest.mark.parametrize("start", list(INPUT_RECIPES))
def test_the_input_example_is_what_mosys_prints(start, tmp_path, monkeypatch, capsys, request):
    [expected] = [text for text in INPUT_EXAMPLES if text.startswith(start)]
    monkeypatch.chdir(tmp_path)
    argv = INPUT_RECIPES[start](request)
    before = {path: path.read_bytes() for path in tmp_path.rglob("*.h5")}
    assert (main(argv), capsys.readouterr().err.splitlines()[-1]) == (2, expected)
    assert not list(tmp_path.glob("out.*")), "an output was written"
    assert {path: path.read_bytes() for path in before} == before, "an input was changed"


def test_every_example_has_a_recipe():
    for text in EXAMPLES:
        matching = [start for start in RECIPES if text.startswith(start)]
        assert len(matching) == 1, f"{len(matching)} recipes for {text!r}"
    for examples, recipes in ((USAGE_EXAMPLES, USAGE_RECIPES), (INPUT_EXAMPLES, INPUT_RECIPES)):
        for text in examples:
            matching = [start for start in recipes if text.startswith(start)]
            assert len(matching) == 1, f"{len(matching)} recipes for {text!r}"
