"""Issue 27, "hostile input never crashes a verb": the reproducers end with exit 2 and a
``file:line:column`` message (no traceback, no output file), and every accepted figure spec
renders and parses back."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import SPECS
from hypothesis import given, settings
from hypothesis import strategies as st

from mosys.cli import main
from mosys.dynamics.model import build_model
from mosys.parsing.bsr import parse_bsr_text
from mosys.parsing.composite import parse_composite_text
from mosys.parsing.controller import parse_controller_text
from mosys.parsing.figure import (
    ROD_INERTIA_RANGE,
    Figure,
    parse_figure_spec,
    parse_figure_text,
    render_figure_spec,
)
from mosys.parsing.motor import parse_motor_program_text
from mosys.parsing.script import parse_script_text
from mosys.parsing.tokens import MAX_INT64, SpecError
from mosys.parsing.vehicle import Vehicle

FIGURES = SPECS / "figures"
HUGE_SEED = "99999999999999999999999"


def mosys_command(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "mosys.cli", *args], cwd=cwd, capture_output=True, text=True
    )


def edited(source: Path, old: str, new: str) -> str:
    """``source``'s text with its one ``old`` replaced by ``new``."""
    text = source.read_text()
    assert text.count(old) == 1
    return text.replace(old, new)


def where(text: str, needle: str) -> str:
    """``line:column`` (1-based) of the first ``needle`` in ``text``."""
    for number, line in enumerate(text.split("\n"), start=1):
        if needle in line:
            return f"{number}:{line.index(needle) + 1}"
    raise AssertionError(f"{needle!r} not in the text")


def assert_refused(done: subprocess.CompletedProcess, message: str, directory: Path) -> None:
    """Exit 2 with exactly ``message`` on stderr, and no .h5 or .py output left behind."""
    assert "Traceback" not in done.stderr
    assert done.returncode == 2
    assert done.stderr == message + "\n"
    assert not [path for path in directory.rglob("*") if path.suffix in (".h5", ".py")]
    assert not [path for path in directory.rglob(".*.partial")]


# --- 1. an underflowing length ---------------------------------------------------------------


def test_compile_refuses_an_underflowing_length(tmp_path: Path) -> None:
    text = edited(FIGURES / "link1.fig", "length=1 mass=1 ", "length=1e-300 mass=1 ")
    spec = tmp_path / "link1.fig"
    spec.write_text(text)
    done = mosys_command("compile", str(spec), "-o", str(tmp_path / "link1.py"), cwd=tmp_path)
    at = where(text, "1e-300")
    assert_refused(
        done,
        f"{spec}:{at}: expected a number from 1e-06 to 1e+06 for length (m), found '1e-300'",
        tmp_path,
    )


FIGURE_ERRORS = {
    "rod a length=1 mass=1e300\npin a\n": "bad.fig:1:21: expected a number from 1e-06 to "
    "1e+06 for mass (kg), found '1e300'",
    "rod a length=1 mass=1 inertia=1e-300\npin a\n": "bad.fig:1:31: expected a number from "
    "1e-20 to 1e+20 for inertia (kg·m²), found '1e-300'",
    "rod a length=1 mass=1 inertia=0\npin a\n": "bad.fig:1:31: expected a number > 0 for "
    "inertia (kg·m²), found '0'",
    "gravity 1e300\nrod a length=1 mass=1\npin a\n": "bad.fig:1:9: expected a number <= "
    "1e+06 for gravity (m/s²), found '1e300'",
    "rod a length=1 mass=1\npin a at=1e300,0\n": "bad.fig:2:10: expected a pivot within "
    "1e+06 m of the origin, found '1e300,0'",
    "rod a length=1 mass=1\npin a\nterrain floor height=-1e300\n": "bad.fig:3:22: expected a "
    "height within 1e+06 m of 0, as terrain vertices are, found '-1e300'",
    "vehicle wheelbase=1e-300 length=4.0 width=1.7 front_overhang=0.8 wheel_radius=0.3 "
    "steer_limit=35\n": "bad.fig:1:19: expected a number from 1e-06 to 1e+06 for wheelbase, "
    "found '1e-300'",
}


@pytest.mark.parametrize("text", list(FIGURE_ERRORS))
def test_figure_ranges(text: str) -> None:
    with pytest.raises(SpecError) as error:
        parse_figure_text(text, "bad.fig")
    assert str(error.value) == FIGURE_ERRORS[text]


@pytest.mark.parametrize(
    ("figure", "old", "new"),
    [
        ("link1.fig", "length=1 mass=1 ", "length=1 mass=1e-300 "),
        ("link1.fig", "gravity 9.81 ", "gravity 1e300 "),
        (
            "luxo.fig",
            "terrain polyline -1000,0 -1.25,0 -1.25,-0.15 -0.9,-0.15 -0.9,-0.3 -0.65,-0.3 "
            "-0.65,0 1000,0",
            "terrain floor height=1e300",
        ),
    ],
    ids=["mass 1e-300", "gravity 1e300", "Luxo's floor at 1e300"],
)
def test_compile_refuses_the_segfaulting_figures(tmp_path: Path, figure, old, new) -> None:
    """Reproducer 1's figures, which compiled and then crashed the simulator with a segfault:
    refused at the word, exit 2, no module written."""
    text = edited(FIGURES / figure, old, new)
    spec = tmp_path / figure
    spec.write_text(text)
    done = mosys_command("compile", str(spec), "-o", str(tmp_path / "out.py"), cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.startswith(f"{spec}:{where(text, '1e')}: expected ")
    assert not list(tmp_path.glob("out.py*"))


@settings(max_examples=200, deadline=None)
@given(
    st.floats(1e-320, 1e308, allow_infinity=False),
    st.floats(1e-320, 1e308, allow_infinity=False),
)
def test_any_accepted_rod_has_a_finite_positive_inertia(length: float, mass: float) -> None:
    text = f"rod a length={length!r} mass={mass!r}\npin a\n"
    try:
        figure = parse_figure_text(text, "rod.fig")
    except SpecError:
        return
    assert isinstance(figure, Figure)
    inertia = figure.rods[0].inertia
    assert ROD_INERTIA_RANGE[0] <= inertia <= ROD_INERTIA_RANGE[1]
    assert 0 < mass * length * length < math.inf


def test_model_refuses_a_zero_inertia_built_in_code() -> None:
    figure = parse_figure_spec(FIGURES / "link1.fig")
    assert isinstance(figure, Figure)
    rod = dataclasses.replace(figure.rods[0], inertia=0.0)
    with pytest.raises(SpecError) as error:
        build_model(dataclasses.replace(figure, rods=(rod,)))
    assert str(error.value) == (
        f"{FIGURES / 'link1.fig'}:7:5: expected a rod whose inertia (kg·m²) is from 1e-20 to "
        "1e+20 (it is 0), found 'link'"
    )


# --- 2. a tiny dt, a huge mass, a huge grid ---------------------------------------------------


def test_dp_refuses_a_tiny_dt(tmp_path: Path) -> None:
    spec = tmp_path / "A.ssc"
    text = (SPECS / "controllers/pendulum/A.ssc").read_text() + "dt 1e-300\n"
    spec.write_text(text)
    done = mosys_command("dp", str(spec), "-o", str(tmp_path / "A.h5"), cwd=tmp_path)
    at = where(text, "1e-300")
    assert_refused(
        done, f"{spec}:{at}: expected a dt of at least 1e-05 s, found '1e-300'", tmp_path
    )


def test_dp_refuses_a_grid_too_large(tmp_path: Path) -> None:
    old = "ssd omega -500.0 500.0 21"
    text = edited(SPECS / "controllers/pendulum/A.ssc", old, "ssd omega -500.0 500.0 " + "9" * 20)
    spec = tmp_path / "A.ssc"
    spec.write_text(text)
    done = mosys_command("dp", str(spec), "-o", str(tmp_path / "A.h5"), cwd=tmp_path)
    at = where(text, "9" * 20)
    assert_refused(
        done,
        f"{spec}:{at}: expected fewer samples (at most 100,000,000 state grid nodes in all; "
        f"these lines make 1e+20), found '{'9' * 20}'",
        tmp_path,
    )


def test_controller_torq_samples_bounded() -> None:
    text = "dyn link1\nssd angle -180 170 36 wrap\ntorq torque -10 10 2000000 0.1\n"
    with pytest.raises(SpecError) as error:
        parse_controller_text(text, "A.ssc")
    assert str(error.value) == (
        "A.ssc:3:20: expected fewer samples (at most 1,000,000 control samples in all; these "
        "lines make 2e+06), found '2000000'"
    )


def test_bsr_search_refuses_a_huge_mass(tmp_path: Path) -> None:
    figures = tmp_path / "figures"
    figures.mkdir()
    old = "rod arm_b length=0.6 mass=5"
    text = edited(FIGURES / "starman.fig", old, "rod arm_b length=0.6 mass=1e300")
    (figures / "starman.fig").write_text(text)
    output = tmp_path / "seed1.h5"
    done = mosys_command(
        "bsr-search", str(SPECS / "bsr/starman_jump.bsr"), "--seed", "1", "--figures",
        str(figures), "--generations", "1", "-o", str(output), cwd=tmp_path,
    )  # fmt: skip
    at = where(text, "1e300")
    assert_refused(
        done,
        f"{figures / 'starman.fig'}:{at}: expected a number from 1e-06 to 1e+06 for mass (kg), "
        "found '1e300'",
        tmp_path,
    )


@pytest.mark.parametrize(("search", "figure"), [("starman_jump", "starman"), ("bob_walk", "bob")])
def test_bsr_search_refuses_a_figure_without_gravity(tmp_path: Path, search, figure) -> None:
    """2-D and 3-D: the senses are scaled by the weight and the speed of a fall, so gravity 0
    (which a figure may have) is refused for a search at the spec's figure line (the verb fuzz,
    freshly drawn, found the 2-D kernel dividing by zero; a 3-D search ran on senses of inf
    and NaN)."""
    figures = tmp_path / "figures"
    figures.mkdir()
    (figures / f"{figure}.fig").write_text(
        edited(FIGURES / f"{figure}.fig", "gravity 9.81", "gravity 0")
    )
    spec = SPECS / "bsr" / f"{search}.bsr"
    output = tmp_path / "seed1.h5"
    done = mosys_command(
        "bsr-search", str(spec), "--seed", "1", "--figures", str(figures), "--generations", "1",
        "-o", str(output), cwd=tmp_path,
    )  # fmt: skip
    lines = spec.read_text().split("\n")
    number = next(n for n, line in enumerate(lines, start=1) if line.startswith("figure"))
    at = f"{number}:{lines[number - 1].index(figure) + 1}"
    assert_refused(
        done,
        f"{spec}:{at}: expected a figure with gravity > 0 for a BSR search (the "
        f"controllers' senses are scaled by its weight and its speed of fall; '{figure}' has "
        f"gravity 0), found '{figure}'",
        tmp_path,
    )


def test_bsr_search_refuses_a_tiny_dt(tmp_path: Path) -> None:
    text = edited(SPECS / "bsr/starman_jump.bsr", "dt=0.01", "dt=1e-300")
    spec = tmp_path / "jump.bsr"
    spec.write_text(text)
    done = mosys_command(
        "bsr-search", str(spec), "--seed", "1", "--figures", str(FIGURES), "--generations", "1",
        "-o", str(tmp_path / "seed1.h5"), cwd=tmp_path,
    )  # fmt: skip
    at = where(text, "1e-300")
    assert_refused(
        done,
        f"{spec}:{at}: expected a dt= (s) of at least duration / 2147483647 = "
        "1.8626451500983188e-09 (at most 2147483647 steps per run), found '1e-300'",
        tmp_path,
    )


# --- 3. a huge seed ---------------------------------------------------------------------------


def test_bsr_search_refuses_a_huge_seed_in_the_spec(tmp_path: Path) -> None:
    text = edited(SPECS / "bsr/starman_jump.bsr", "seeds 1 2 3 4 5", f"seeds 1 {HUGE_SEED}")
    spec = tmp_path / "jump.bsr"
    spec.write_text(text)
    done = mosys_command(
        "bsr-search", str(spec), "--seed", "1", "--figures", str(FIGURES), "--generations", "1",
        "-o", str(tmp_path / "seed1.h5"), cwd=tmp_path,
    )  # fmt: skip
    at = where(text, HUGE_SEED)
    assert_refused(
        done,
        f"{spec}:{at}: expected a whole number from 0 to {MAX_INT64} for a seed, found "
        f"'{HUGE_SEED}'",
        tmp_path,
    )


def test_bsr_search_refuses_a_huge_seed_argument(tmp_path: Path) -> None:
    text = edited(SPECS / "bsr/starman_jump.bsr", "seeds 1 2 3 4 5", f"seeds {HUGE_SEED}")
    spec = tmp_path / "jump.bsr"
    spec.write_text(text)
    done = mosys_command(
        "bsr-search", str(spec), "--seed", HUGE_SEED, "--figures", str(FIGURES),
        "--generations", "1", "-o", str(tmp_path / "seed.h5"), cwd=tmp_path,
    )  # fmt: skip
    assert "Traceback" not in done.stderr
    assert done.returncode == 2
    assert done.stderr.endswith(
        f"mosys bsr-search: error: --seed must be a whole number from 0 to {MAX_INT64}, got "
        f"{HUGE_SEED}\n"
    )
    assert not list(tmp_path.glob("*.h5"))


def test_bsr_whole_numbers_fit_the_kernels() -> None:
    text = (
        (SPECS / "bsr/starman_jump.bsr")
        .read_text()
        .replace("generations=4000", "generations=" + "9" * 20)
    )
    with pytest.raises(SpecError) as error:
        parse_bsr_text(text, "jump.bsr")
    assert str(error.value) == (
        f"jump.bsr:{where(text, '9' * 20)}: expected a whole number from 1 to 2147483647 for "
        f"generations=, found '{'9' * 20}'"
    )


# --- 4. render -> parse round-trips -----------------------------------------------------------


def assert_same(a: object, b: object) -> None:
    """Equal dataclasses, tuples and values, floats within 1e-12 (angles go through degrees);
    ``path`` and ``spec_sha256`` are not compared."""
    if dataclasses.is_dataclass(a):
        assert type(a) is type(b)
        for field in dataclasses.fields(a):
            if field.name not in ("path", "spec_sha256", "token") and field.compare:
                assert_same(getattr(a, field.name), getattr(b, field.name))
    elif isinstance(a, tuple):
        assert isinstance(b, tuple) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            assert_same(x, y)
    elif isinstance(a, float):
        assert a == pytest.approx(b, rel=1e-12, abs=1e-12)
    else:
        assert a == b


@pytest.mark.parametrize("path", sorted(FIGURES.glob("*.fig")), ids=lambda path: path.stem)
def test_every_shipped_figure_renders_and_parses_back(path: Path) -> None:
    figure = parse_figure_spec(path)
    text = render_figure_spec(figure)
    again = parse_figure_text(text, str(path))
    assert_same(again, figure)
    assert render_figure_spec(again) == text  # rendering is a fixed point after one trip


def test_vehicle_renders_as_one_line() -> None:
    vehicle = parse_figure_spec(FIGURES / "car.fig")
    assert isinstance(vehicle, Vehicle)
    assert render_figure_spec(vehicle) == (
        "vehicle wheelbase=2.5 length=4 width=1.7 front_overhang=0.8 wheel_radius=0.3 "
        "steer_limit=35\n"
    )


# --- 8. a 100 kB word is not echoed whole ------------------------------------------------------

PARSERS = {
    ".fig": parse_figure_text,
    ".ssc": parse_controller_text,
    ".anim": parse_script_text,
    ".mot": parse_motor_program_text,
    ".bsr": parse_bsr_text,
    ".comp": parse_composite_text,
}
HUGE_WORD = 100_000


@pytest.mark.parametrize("path", sorted(p for p in SPECS.rglob("*.*") if p.suffix in PARSERS))
def test_an_error_quotes_at_most_the_start_of_a_huge_word(path: Path) -> None:
    """Every word of every shipped spec, in turn, replaced by a 100,000-character one (a name, or a
    name=value with a huge value): the error, wherever it arises, stays short — also where it
    lists names the spec defined — and says how long the word was."""
    parse = PARSERS[path.suffix]
    lines = path.read_text().split("\n")
    for number, line in enumerate(lines):
        words = line.split("#")[0].split()
        for k, word in enumerate(words):
            name, equals, _ = word.partition("=")
            for huge in (
                "x" * HUGE_WORD,
                f"{name}={'9' * HUGE_WORD}" if equals else "7" * HUGE_WORD,
            ):
                edited_line = " ".join([*words[:k], huge, *words[k + 1 :]])
                text = "\n".join([*lines[:number], edited_line, *lines[number + 1 :]])
                try:
                    parse(text, str(path))
                except SpecError as error:
                    assert len(str(error)) < 2_000 + len(str(path))
                    if len(error.found or "") >= HUGE_WORD:
                        assert f"... ({len(error.found):,} characters)" in str(error)


# --- 6. a step longer than a sim line -----------------------------------------------------------


def test_run_with_a_step_longer_than_its_sim_line(tmp_path: Path, pendulum: Path, capsys) -> None:
    """``mosys run --dt 2`` (reproducer 6, once an AssertionError): a 0.4 s ``sim`` rounds to no
    step, and says so (it used to say nothing), a 4 s one to two steps of 2 s; the run ends with
    a finite trajectory."""
    script = tmp_path / "long_steps.anim"
    script.write_text("state link -135,350\nswapcon link conA.ctab\nsim 0.4\nsim 4\n")
    out = tmp_path / "long_steps.h5"
    argv = ["run", str(script), "--controllers", str(pendulum / "controllers")]
    argv += ["--dynamics-dir", str(pendulum / "dynamics"), "--dt", "2", "-o", str(out)]
    assert main(argv) == 0
    with h5py.File(out) as file:
        assert np.isfinite(file["state"][...]).all() and np.isfinite(file["t"][...]).all()
        assert file["t"][-1] == 4.0
    assert capsys.readouterr().err.splitlines() == [
        f"warning: {script}:3: sim 0.4 is less than half a step (dt = 2 s): no step simulated"
    ]


# --- 8. a composite score that divides by zero ------------------------------------------------


@pytest.mark.parametrize(("expression", "shown"), [("0 / 0", "nan"), ("1 / 0", "inf")])
def test_a_composite_score_dividing_by_zero_is_written_plainly(
    tmp_path: Path, composite_workspace, capsys, expression: str, shown: str
) -> None:
    """IEEE arithmetic in a script's scores (README, "The composite script"): the result file
    says "nan"/"inf" in strict JSON, ``mosys info`` shows it, and the search's best is never
    nan."""
    script = tmp_path / "show.comp"
    text = composite_workspace.script.read_text()
    old = "score jump      = max_t(min_i(y_i(t))) * (dtime ?= 150)"
    assert old in text
    script.write_text(text.replace(old, f"score jump      = {expression}"))
    out = tmp_path / "show.h5"
    argv = ["composite", str(script), "--bsr-results", str(composite_workspace.bsr_results)]
    assert main([*argv, "--q", "4", "--g", "2", "--h", "2", "-o", str(out)]) == 0
    with h5py.File(out) as file:
        scores = json.loads(file.attrs["scores_after"])  # strict JSON: no NaN/Infinity tokens
        assert scores["jump"] == shown
        assert not np.isnan(file["search/best_score"][...]).any() or shown == "nan"
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    listing = capsys.readouterr().out
    assert f'"jump": "{shown}"' in listing
    assert f"score_after       {shown}" in listing


def test_a_joint_range_written_minus_zero_is_zero(tmp_path: Path) -> None:
    """The verb fuzz's ``swing_upper=-0`` on a fixed angle (range 0..0): numpy's uniform took
    -0 below 0 and refused the range with a traceback; the search runs."""
    figures = tmp_path / "figures"
    figures.mkdir()
    text = (FIGURES / "rex.fig").read_text()
    (figures / "rex.fig").write_text(
        text.replace("swing_lower=0 swing_upper=0\n", "swing_lower=0 swing_upper=-0\n")
    )
    out = tmp_path / "seed1.h5"
    argv = ["bsr-search", str(SPECS / "bsr/rex_walk.bsr"), "--figures", str(figures)]
    assert main([*argv, "--seed", "1", "--generations", "1", "-o", str(out)]) == 0
    assert out.exists()


def test_a_script_of_motor_programs_alone_needs_an_object_line(
    tmp_path: Path, pendulum: Path, capsys
) -> None:
    """With no swapcon, nothing named the object's figure: a StopIteration traceback, exit 1."""
    script = tmp_path / "nomot.anim"
    script.write_text("state link -90,0\nmotor link swing\n")
    out = tmp_path / "nomot.h5"
    argv = ["run", str(script), "--controllers", str(pendulum / "controllers")]
    argv += ["--dynamics-dir", str(pendulum / "dynamics"), "-o", str(out)]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"{script}:2:1: expected an 'object link figure=FIGURE' line before it (with no "
        "swapcon, nothing else names the object's figure), found 'motor'\n"
    )
    assert not out.exists()


def test_run_says_where_the_motion_ends(tmp_path: Path, pendulum: Path, capsys) -> None:
    """A run whose controller never brought the figure to its destination was written without
    a word: the command's line now says whether it ends in the last controller's arrival box."""
    argv = ["--controllers", str(pendulum / "controllers"), "--dynamics-dir"]
    argv += [str(pendulum / "dynamics")]
    cases = {
        "there.anim": (
            "state link 0,0\nswapcon link conA.ctab\nsim 1 until=dest\n",
            "0.00 s of motion; ends at controller A's destination (in its arrival box)",
        ),
        "short.anim": (
            "state link -135,350\nswapcon link conA.ctab\nsim 0.05\n",
            "0.05 s of motion; ends away from controller A's destination (not in its arrival box)",
        ),
    }
    for name, (text, said) in cases.items():
        (tmp_path / name).write_text(text)
        out = tmp_path / f"{name}.h5"
        assert main(["run", str(tmp_path / name), *argv, "-o", str(out)]) == 0
        assert capsys.readouterr().out == f"{out}: {said}\n"


def test_a_car_started_on_an_obstacle_is_told_so() -> None:
    """Its runs said only 'hit bollard'; the start itself overlapped it."""
    from types import SimpleNamespace

    from mosys.animation.trajectory_file import run_summary

    run = SimpleNamespace(t=np.array([0.0, 20.0]))
    hit = {"parked": False, "collision_index": 0, "collided_with": "bollard"}
    assert run_summary("T.h5", run, None, hit) == (
        "T.h5: 20.00 s of motion; not parked, hit bollard (its start pose overlaps it: no run "
        "from there is free)"
    )
    later = {**hit, "collision_index": 7}
    assert run_summary("T.h5", run, None, later).endswith("not parked, hit bollard")
    parked = {"parked": True, "parking_seconds": 11.79}
    assert run_summary("T.h5", run, None, parked).endswith("parked after 11.79 s")


@pytest.mark.parametrize(
    ("state", "column", "found"),
    [("1.5,2,0,-50,0", 19, "-50"), ("x=1.5 y=2 steer=35.5", 27, "35.5")],
)
def test_a_start_steered_past_the_cars_limit_is_refused(
    tmp_path, car_park, state, column, found, capsys
):
    """A car started with its wheels at -50° (car.fig: steer_limit=35) kept them there and
    drove, exit 0: the steer rate only stops the wheels turning further past the limit."""
    script = tmp_path / "steer.anim"
    script.write_text(f"object car figure=car\nstate car {state}\nswapcon car park\nsim 1\n")
    out = tmp_path / "steer.h5"
    argv = ["run", str(script), "--controllers", str(car_park / "controllers")]
    argv += ["--dynamics-dir", str(car_park / "dynamics"), "--dt", "0.01", "-o", str(out)]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"{script}:2:{column}: expected a steer within ±35 deg (the figure's limit), "
        f"found '{found}'\n"
    )
    assert not out.exists()


def test_a_damaged_table_is_named_as_a_file_and_another_figures_at_the_line(
    tmp_path, pendulum, car_park, capsys
):
    """A damaged table that a ``when`` line named was reported as the line's mistake (the
    same file named by a ``swapcon`` was reported as a file); a table of another figure is."""
    controllers = tmp_path / "controllers"
    controllers.mkdir()
    shutil.copy(pendulum / "controllers" / "A.h5", controllers / "A.h5")
    (controllers / "B.h5").write_bytes((pendulum / "controllers" / "A.h5").read_bytes()[:5000])
    shutil.copy(car_park / "controllers" / "park.h5", controllers / "park.h5")
    script = tmp_path / "catch.anim"
    out = tmp_path / "catch.h5"
    argv = ["run", str(script), "--controllers", str(controllers)]
    argv += ["--dynamics-dir", str(pendulum / "dynamics"), "-o", str(out)]
    for table, expected in (
        ("conB.ctab", f"mosys: {controllers / 'B.h5'}: cannot read it as HDF5 ("),
        (
            "park",
            f"{script}:3:38: expected a controller over state variables and actuators of the "
            f"object's figure ({controllers / 'park.h5'}: controller park (a table of figure "
            "'car'): the dynamics have no state variables",
        ),
    ):
        script.write_text(
            f"state link -90,0\nswapcon link conA.ctab\nwhen link angle>75 angle<105 swapcon "
            f"{table} once\nsim 0.1\n"
        )
        assert main(argv) == 2
        assert capsys.readouterr().err.startswith(expected)
        assert not out.exists()
