"""Shared fixtures: the real pendulum compiled from specs/ into a temporary results tree."""

from __future__ import annotations

import shutil
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"

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
