"""Shared fixtures (the real figures and controllers compiled from specs/ into temporary
results trees) and the helpers the spec-parser tests share."""

from __future__ import annotations

import math
import shutil
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import numpy as np
import pytest

from mosys.parsing.tokens import END_OF_FILE, SpecError, shortened_words, shown_text

if TYPE_CHECKING:
    from mosys.io.start_grid import StartGrid

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
CAR_STATE = ("x", "y", "heading", "steer", "speed")


# --- what the spec-parser tests share -------------------------------------------------------

Parsed = TypeVar("Parsed")


def parses_or_spec_error(
    parse: Callable[[str, str], Parsed], text: str, path: str, check: Callable[[Parsed], None]
) -> None:
    """The fuzzing property of every spec grammar: ``parse(text, path)`` returns a value that
    ``check`` accepts, or raises SpecError with the whole message ``path:line:column: expected
    ..., found ...`` pointing into the text: at the word it found, at a line of the text for
    'end of line', just past the last line at most for 'end of file'."""
    try:
        parsed = parse(text, path)
    except SpecError as error:
        shown = {None: "end of line", END_OF_FILE: "end of file"}
        found = shown.get(error.found) or shown_text(error.found)
        expected = shortened_words(error.expected)  # a word over 200 characters is cut
        assert (
            str(error) == f"{path}:{error.line}:{error.column}: expected {expected}, found {found}"
        )
        assert error.expected and error.line >= 1 and error.column >= 1
        lines = text.split("\n")  # lines end at '\n' only, as the tokenizer counts them
        if error.found == END_OF_FILE:
            assert error.line <= len(lines) + 1
        else:
            assert error.line <= len(lines)
            if error.found is not None:
                assert lines[error.line - 1][error.column - 1 :].startswith(error.found)
    else:
        check(parsed)


@dataclass(frozen=True)
class SpecLines:
    """A valid spec's text, edited a line at a time (lines count from 1) to make an error."""

    text: str

    def replace(self, number: int, line: str) -> str:
        lines = self.text.splitlines()
        lines[number - 1] = line
        return "\n".join(lines) + "\n"

    def drop(self, number: int) -> str:
        lines = self.text.splitlines()
        del lines[number - 1]
        return "\n".join(lines) + "\n"

    def insert(self, number: int, line: str) -> str:
        """``line`` becomes line ``number``."""
        lines = self.text.splitlines()
        lines.insert(number - 1, line)
        return "\n".join(lines) + "\n"


DOUBLE_INTEGRATOR = textwrap.dedent(
    '''
    """A unit point mass on a line, x'' = force: the textbook minimum-time problem."""
    import numpy as np
    from numba import njit, types

    STATE_NAMES = ("x", "v")
    STATE_UNITS = ("m", "m/s")
    INPUT_NAMES = ("force",)
    VECTOR = types.float64[::1]


    @njit(types.void(VECTOR, VECTOR, VECTOR), cache=True)
    def derivative_into(state, inputs, out):
        out[0] = state[1]
        out[1] = inputs[0]
    '''
)


@pytest.fixture(scope="session")
def double_integrator(tmp_path_factory):
    """The double integrator as a dynamics module (test input written by hand: only the names
    the DP uses, so it is imported directly rather than through load_dynamics' checks)."""
    import importlib.util
    import sys

    path = tmp_path_factory.mktemp("dynamics") / "double_integrator.py"
    path.write_text(DOUBLE_INTEGRATOR)
    spec = importlib.util.spec_from_file_location("mosys_test_double_integrator", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def car(tmp_path_factory):
    """The car's dynamics, compiled from specs/figures/car.fig."""
    from mosys.dynamics.compile import compile_figure
    from mosys.dynamics.load import load_dynamics

    path = tmp_path_factory.mktemp("dynamics") / "car.py"
    compile_figure(SPECS / "figures" / "car.fig", path)
    return load_dynamics(path)


@pytest.fixture(scope="session")
def link1(tmp_path_factory):
    """The pendulum's dynamics, compiled from specs/figures/link1.fig."""
    from mosys.dynamics.compile import compile_figure
    from mosys.dynamics.load import load_dynamics

    path = tmp_path_factory.mktemp("dynamics") / "link1.py"
    compile_figure(SPECS / "figures" / "link1.fig", path)
    return load_dynamics(path)


@pytest.fixture(scope="session")
def pendulum_tables(tmp_path_factory, link1):
    """The six pendulum controllers A–F generated from specs/controllers/pendulum."""
    from mosys.parsing.controller import parse_controller_spec
    from mosys.ssc.generate import generate_controller

    directory = tmp_path_factory.mktemp("controllers")
    for name in "ABCDEF":
        spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / f"{name}.ssc")
        generate_controller(spec, link1, directory / f"{name}.h5", quiet=True)
    return directory


@pytest.fixture(scope="session")
def pendulum(tmp_path_factory, link1) -> Path:
    """A directory with link1's dynamics (dynamics/link1.py), controller A (controllers/A.h5)
    and, for motor programs, motor/link1/: what ``mosys run`` takes."""
    from mosys.dynamics.compile import compile_figure
    from mosys.parsing.controller import parse_controller_spec
    from mosys.ssc.generate import generate_controller

    root = tmp_path_factory.mktemp("pendulum_run")
    (root / "dynamics").mkdir()
    compile_figure(SPECS / "figures" / "link1.fig", root / "dynamics" / "link1.py")
    (root / "controllers").mkdir()
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")
    generate_controller(spec, link1, root / "controllers" / "A.h5", quiet=True)
    (root / "motor" / "link1").mkdir(parents=True)
    return root


@pytest.fixture(scope="session")
def car_park(car, tmp_path_factory) -> Path:
    """The car test's SMALL scene as a lookahead table, controllers/park.h5, and the car's
    dynamics, dynamics/car.py."""
    from test_car import SMALL

    from mosys.dynamics.compile import compile_figure
    from mosys.parsing.controller import parse_controller_text
    from mosys.ssc.generate import generate_controller

    root = tmp_path_factory.mktemp("car_park")
    (root / "dynamics").mkdir()
    compile_figure(SPECS / "figures" / "car.fig", root / "dynamics" / "car.py")
    (root / "controllers").mkdir()
    spec = parse_controller_text(SMALL + "policy lookahead x=0.1 y=0.1 heading=4\n", "park.ssc")
    generate_controller(spec, car, root / "controllers" / "park.h5", quiet=True)
    return root


@dataclass(frozen=True)
class CompositeWorkspace:
    """The three robust Star-Man searches built at a tiny budget (``bsr_results``/NAME/seedK.h5,
    two seeds each), the Table 4 script copied beside them, and its composite result made with
    a small search (``result``)."""

    root: Path
    bsr_results: Path
    script: Path
    result: Path

    def controller_files(self) -> dict[str, list[Path]]:
        from mosys.composite.session import find_controller_files
        from mosys.parsing.composite import parse_composite_script

        return find_controller_files(parse_composite_script(self.script), self.bsr_results)


COMPOSITE_SEARCHES = ("starman_cartwheel_robust", "starman_jump_robust", "starman_shuffle_robust")


@pytest.fixture(scope="session")
def composite_workspace(tmp_path_factory) -> CompositeWorkspace:
    """Real BSR searches (G = 8, seeds 1 and 2) and a real composite result (Q = 4, G = 3,
    H = 2): the composite tests' input, made by the same functions as the pipeline."""
    from mosys.bsr.result_file import search_to_file
    from mosys.composite.result_file import composite_to_file

    root = tmp_path_factory.mktemp("composite")
    bsr_results = root / "results" / "bsr"
    for name in COMPOSITE_SEARCHES:
        for seed in (1, 2):
            search_to_file(
                SPECS / "bsr" / f"{name}.bsr",
                SPECS / "figures",
                seed,
                bsr_results / name / f"seed{seed}.h5",
                generations=8,
                budget="test",
            )
    script = root / "starman_show.comp"
    shutil.copy(SPECS / "composite" / "starman_show.comp", script)
    workspace = CompositeWorkspace(root, bsr_results, script, root / "starman_show.h5")
    composite_to_file(
        script,
        workspace.controller_files(),
        workspace.result,
        SPECS / "figures",
        SPECS / "bsr",
        {"q": 4, "g": 3, "h": 2},
        budget="test",
    )
    return workspace


# --- what the plot tests share --------------------------------------------------------------

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def assert_png(
    path: Path, least_bytes: int = 10_000, least_width: int = 500, least_height: int = 300
) -> tuple[int, int]:
    """``path`` is a PNG of at least ``least_bytes`` (under 3 MB), at least ``least_width`` x
    ``least_height`` pixels (under 2500 each), not blank (more than 20 colours), written
    atomically (no partial file beside it); returns its (width, height)."""
    from PIL import Image

    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC)
    assert least_bytes < len(data) < 3_000_000, len(data)
    with Image.open(path) as image:
        assert image.format == "PNG"
        width, height = image.size
        colors = image.convert("RGB").getcolors(maxcolors=1 << 20)
    assert least_width < width < 2500 and least_height < height < 2500, (width, height)
    assert len(colors) > 20, f"{path} looks blank: {len(colors)} colours"
    assert not list(path.parent.glob(".*.partial"))  # written atomically
    return width, height


# --- summaries a test leaves for the end of the run ---------------------------------------------

SUMMARY_PROPERTY = "summary"  # a test's record_property(SUMMARY_PROPERTY, text): printed at the end
_summaries: list[tuple[str, str]] = []


def pytest_runtest_logreport(report) -> None:
    """Keep the summaries of passed and failed tests (xdist sends each report, with its
    properties, back from the worker that ran it)."""
    if report.when == "call":
        _summaries.extend(
            (report.nodeid, str(value)) for key, value in report.user_properties
            if key == SUMMARY_PROPERTY
        )  # fmt: skip


def pytest_terminal_summary(terminalreporter) -> None:
    """The summaries (the verb fuzz's table of outcome classes), after the test results."""
    for nodeid, text in _summaries:
        terminalreporter.section(nodeid)
        terminalreporter.write_line(text)


@pytest.fixture(scope="session")
def made(pendulum_tables, link1, tmp_path_factory) -> dict[str, Path]:
    """One file of each kind mosys writes, small, by kind (``mosys info``'s tests, the
    docs/formats examples' test)."""
    from mosys.animation.trajectory_file import run_animation_script
    from mosys.bsr.result_file import search_to_file
    from mosys.composite.result_file import composite_to_file
    from mosys.composite.session import find_controller_files
    from mosys.io.start_grid import write_start_grid
    from mosys.parsing.composite import parse_composite_script

    root = tmp_path_factory.mktemp("info")
    dynamics = root / "dynamics"
    dynamics.mkdir()
    shutil.copy(link1.__file__, dynamics / "link1.py")
    script = root / "swing.anim"
    script.write_text("state link -135,350\nswapcon link conB.ctab\nsim 0.4\n")
    motor = SPECS / "motor"
    run_animation_script(script, pendulum_tables, dynamics, root / "swing.h5", 0.01, motor)
    bsr = root / "bsr"
    for name in COMPOSITE_SEARCHES:  # one seed of two generations each
        search_to_file(
            SPECS / "bsr" / f"{name}.bsr", SPECS / "figures", 1, bsr / name / "seed1.h5", 2
        )
    comp = root / "starman_show.comp"
    shutil.copy(SPECS / "composite" / "starman_show.comp", comp)
    files = find_controller_files(parse_composite_script(comp), bsr)
    sizes = {"q": 2, "g": 1, "h": 1}
    composite_to_file(comp, files, root / "show.h5", SPECS / "figures", SPECS / "bsr", sizes)
    write_start_grid(root / "grid.h5", start_grid())
    return {
        "controller table": pendulum_tables / "A.h5",
        "trajectory": root / "swing.h5",
        "BSR search result": bsr / "starman_jump_robust" / "seed1.h5",
        "composite result": root / "show.h5",
        "start grid": root / "grid.h5",
    }


def start_grid() -> StartGrid:
    """Three car starts: one parks in 7.5 s, one times out, one overlaps an obstacle."""
    from mosys.io.start_grid import NOT_FREE, StartGrid

    return StartGrid(
        start=np.array([[1.5, 2.0, 0.0, 0.0, 0.0], [-1.0, 1.5, 5.0, 0.0, 0.0], [0, 0.6, 0, 0, 0]]),
        state_order=CAR_STATE,
        parked=np.array([True, False, False]),
        collided=np.array([False, False, False]),
        parking_seconds=np.array([7.5, math.nan, math.nan]),
        excluded=np.array(["", "", NOT_FREE], dtype=object),
        cost_to_go=np.array([7.0, 9.0, math.inf]),
        path_length=np.array([2.0, 3.0, math.nan]),
        attrs={"controller": "park", "simulated_seconds": 10.0, "dt": 0.01},
    )
