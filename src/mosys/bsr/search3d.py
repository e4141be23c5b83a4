"""The 1995 paper's search (Figure 3, with §4's changes) for a 3-D figure: binding a spec to a
3-D figure and the simulation that runs it (``mosys.kernels.bsr3d_controller``).

A search that continues another (``chain NAME``) starts exactly where the best motion of that
search's best seed (highest ``best_fitness``) ends: its final state and contact forces, in the
same world frame.

A run whose state blows up raises NonFiniteStateError, as in 2-D (``mosys.bsr.search``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from mosys.bsr.figure3d import BsrFigure3D
from mosys.bsr.search import (
    RecordedRun,
    SearchSetup,
    bind_names,
    check_population,
    check_run,
    controller_arrays,
    describe_values,
    population_arrays,
)
from mosys.bsr.start3d import pose_at_rest, standing_state
from mosys.errors import InputError
from mosys.io.bsr_result import BsrController
from mosys.io.contracts import open_contract
from mosys.kernels.bsr3d_controller import Task, run_controller
from mosys.kernels.bsr3d_population import run_population
from mosys.kernels.bsr3d_simulate import CX, CY, JOINTS, LX, QW, VX
from mosys.parsing.bsr import FITNESS_TERMS_3D, BsrSpec
from mosys.parsing.tokens import SpecError

ENRICH_ROUNDS = 3  # §4.2: rounds of the relevance mutation that enrich the first population
FIRST_SET = 100  # §4.2: "the first set of 100 motion controllers" they enrich; the best C go on
FEET_TERMS = ("feet_distance", "foot_steps")  # the fitness terms that measure the feet
# the least horizontal part of the heading rod's length at the start (sin 5.7°): nearer upright,
# its horizontal direction, the heading, is rounding, and so are the terms that measure it
HEADING_MIN_HORIZONTAL = 0.1


@dataclass(frozen=True)
class ChainStart:
    """Where a continued search starts: the ``state`` (S,) and endpoint forces ``force`` (E,) N
    at the end of the best motion of seed ``seed`` of search ``name``."""

    name: str
    seed: int
    state: np.ndarray
    force: np.ndarray


def chain_start(name: str, result_paths: list[str | Path]) -> ChainStart:
    """The final state of the best seed (highest ``best_fitness``, the lowest seed on a tie)
    among a search's result files; InputError naming a file that is not a result of the search
    ``name``."""
    best: tuple[float, int, Path] | None = None
    for path in map(Path, result_paths):
        with open_contract(path, "BSR search result") as h5:
            searched = str(h5.attrs["name"]) if "name" in h5.attrs else path.parent.name
            if searched != name:
                raise InputError(
                    f"{path}: a result of search '{searched}', not of '{name}' (the search the "
                    "spec's chain line continues)"
                )
            key = (float(h5.attrs["best_fitness"]), -int(h5.attrs["seed"]), path)
        if best is None or key[:2] > best[:2]:
            best = key
    if best is None:
        raise InputError(f"no result files of search '{name}' to continue")
    with open_contract(best[2], "BSR search result") as h5:
        if "best/final_state" not in h5 or "best/final_force" not in h5:
            raise InputError(
                f"{best[2]}: no best/final_state to continue from (a result of an older mosys: "
                "run its search again)"
            )
        return ChainStart(name, -best[1], h5["best/final_state"][()], h5["best/final_force"][()])


def describe_spatial_state(figure: BsrFigure3D, state: np.ndarray) -> str:
    """A 3-D BSR state (S = 13 + 2J,) SI in the spec's units: the centre of mass (cm_x, cm_y,
    cm_z m; cm_vx, cm_vy, cm_vz m/s), the orientation quaternion (q_w, q_x, q_y, q_z), the
    angular momentum (L_x, L_y, L_z kg·m²/s), the angles (deg) and their rates (NAME', deg/s)."""
    values = [(f"cm_{axis}", state[CX + a], "m") for a, axis in enumerate("xyz")]
    values += [(f"cm_v{axis}", state[VX + a], "m/s") for a, axis in enumerate("xyz")]
    values += [(f"q_{axis}", state[QW + a], "") for a, axis in enumerate("wxyz")]
    values += [(f"L_{axis}", state[LX + a], "kg·m²/s") for a, axis in enumerate("xyz")]
    n = len(figure.joint_names)
    for j, name in enumerate(figure.joint_names):
        values.append((name, math.degrees(state[JOINTS + j]), "deg"))
    for j, name in enumerate(figure.joint_names):
        values.append((f"{name}'", math.degrees(state[JOINTS + n + j]), "deg/s"))
    return describe_values(values)


class SpatialSimulation:
    """The 3-D simulator (Simulation of ``mosys.bsr.search``): every controller from the same
    start (the nominal pose, or the chain's final state) measured as ``task`` says."""

    term_names = FITNESS_TERMS_3D

    def __init__(self, task: Task, start: np.ndarray, start_force: np.ndarray):
        self.task = task
        self.start = start
        self.start_force = start_force

    def describe_state(self, figure: BsrFigure3D, state: np.ndarray) -> str:
        return describe_spatial_state(figure, state)

    def evaluate(self, setup: SearchSetup, population, rng: np.random.Generator) -> np.ndarray:
        spec = setup.spec
        c = population.target.shape[0]  # C, or the first population's size
        starts = np.repeat(self.start[None, :], c, axis=0)
        rules = np.zeros((c, spec.steps + 1), np.int64)
        terms = np.zeros((c, len(FITNESS_TERMS_3D)))
        senses = population.senses if spec.kind == "sense" else np.zeros((c, spec.steps + 1, 0))
        taken = np.zeros(c, np.int64)
        final = np.empty_like(starts)
        run_population(
            setup.figure.arrays,
            population_arrays(setup, population),
            self.task,
            starts,
            spec.steps,
            spec.dt,
            senses,
            rules,
            terms,
            taken,
            final,
        )
        check_population(taken, final, spec.dt, partial(describe_spatial_state, setup.figure))
        return terms @ setup.weights

    def record(self, setup: SearchSetup, controller: BsrController) -> RecordedRun:
        return record_run(
            setup.figure, controller, self.task, self.start, self.start_force, setup.spec
        )


def record_run(
    figure: BsrFigure3D,
    controller: BsrController,
    task: Task,
    start: np.ndarray,
    start_force: np.ndarray,
    spec: BsrSpec,
) -> RecordedRun:
    """Run ``controller`` for the spec's steps from the state ``start`` (S,) with the endpoint
    forces ``start_force`` (E,) N, recording every step; a state that blows up raises
    NonFiniteStateError (``check_run``)."""
    run = RecordedRun.empty(len(FITNESS_TERMS_3D), spec.steps, figure, 3, start)
    taken = run_controller(
        figure.arrays,
        controller_arrays(controller),
        task,
        np.asarray(start, np.float64),
        np.asarray(start_force, np.float64),
        False,
        spec.steps,
        spec.dt,
        run.record(0 if controller.kind == "time" else len(figure.sense_names)),
    )
    check_run(taken, spec.dt, run.final_state, partial(describe_spatial_state, figure))
    return run


def standing_height(figure: BsrFigure3D, root_angle: float = 0.0) -> float:
    """The centre of mass's height, m, of the figure stood on the floor at rest with every
    angle at 0 (held in its range): the scale of the height sense and of a fall."""
    return float(standing_state(figure, root_angle, np.zeros(len(figure.joint_names)))[CY])


def _check_heading_rod(
    spec: BsrSpec, figure: BsrFigure3D, root_angle: float, angles: np.ndarray
) -> None:
    """Raise SpecError at the spec's ``figure`` word if the heading rod stands within
    asin(HEADING_MIN_HORIZONTAL) of upright in the start pose (root_angle rad about the world
    z axis, angles (J,) rad): its horizontal direction is then no heading."""
    rod_ends, _ = pose_at_rest(figure, angles)
    dx, dy, dz = rod_ends[figure.heading_rod, 1] - rod_ends[figure.heading_rod, 0]
    along = math.cos(root_angle) * dx - math.sin(root_angle) * dy
    horizontal = math.hypot(along, dz) / math.sqrt(dx * dx + dy * dy + dz * dz)
    if horizontal < HEADING_MIN_HORIZONTAL:
        rod = figure.figure.rods[figure.heading_rod].name
        raise SpecError.at(
            spec.path,
            spec.tokens["figure"],
            f"a figure whose heading rod lies nearer the horizontal at the start ('{rod}', "
            f"its 'heading' line's rod, is {math.degrees(math.asin(horizontal)):.1f} deg from "
            "upright in the start pose, and its horizontal direction is the heading)",
        )


def bind_search3d(
    spec: BsrSpec,
    figure: BsrFigure3D,
    generations: int | None = None,
    chain: ChainStart | None = None,
) -> SearchSetup:
    """Check the spec's names against the 3-D figure (``bind_names``) and lay out its numbers;
    a mistake raises SpecError at its word. ``chain``: where a continued search starts
    (required exactly when the spec has a ``chain`` line)."""
    if spec.perturbation.any:
        raise SpecError.at(
            spec.path, spec.tokens["perturb"], "no 'perturb' line for a 3-D figure (not built)"
        )
    names = bind_names(spec, figure, FITNESS_TERMS_3D)
    for term in FEET_TERMS:
        if spec.weights.get(term, 0.0) != 0.0 and not figure.feet:
            raise SpecError.at(
                spec.path,
                spec.tokens[f"fitness.{term}"],
                f"a term of a figure with feet for {term} (a 'feet' line in its .fig; "
                f"'{figure.figure.name}' has none)",
            )
    endpoints = [tuple(row) for row in figure.endpoints.tolist()]
    feet = np.array([endpoints.index(tuple(foot)) for foot in figure.feet], np.int64)
    height = standing_height(figure)
    if not height > 0.0:  # the senses' and the fall's scale
        raise SpecError.at(
            spec.path,
            spec.tokens["figure"],
            f"a figure whose centre of mass stands above the floor at rest (every angle 0; "
            f"'{figure.figure.name}' lies flat, its centre of mass {height:g} m up)",
        )
    speed = math.sqrt(figure.gravity * height)
    task = Task(
        falls=names.fall_endpoints,
        fall_height=spec.fall_below * height,
        feet=feet,
        heading_rod=int(figure.heading_rod),
        heading_offset=float(figure.heading_offset),
        free=np.flatnonzero(figure.free).astype(np.int64),
        scales=np.array([height, speed, speed / height]),
        filter_time=spec.sense_filter,
    )
    if chain is None:
        _check_heading_rod(spec, figure, names.root_angle, names.joints)
        start = standing_state(figure, names.root_angle, names.joints, names.x)
        start_force = np.zeros(figure.endpoints.shape[0])
    else:
        start, start_force = chain.state, chain.force
        size = 13 + 2 * len(figure.joint_names)
        if start.shape != (size,) or start_force.shape != (figure.endpoints.shape[0],):
            raise SpecError.at(
                spec.path,
                spec.tokens["chain"],
                f"a search of figure '{figure.figure.name}' to continue ({size} state values and "
                f"{figure.endpoints.shape[0]} endpoint forces; the final state of "
                f"'{chain.name}' has {start.size} and {start_force.size})",
            )
    return SearchSetup.bound(
        spec,
        figure,
        names,
        generations,
        SpatialSimulation(task, start, start_force),
        relevance="contain",
        enrich_rounds=ENRICH_ROUNDS if spec.kind == "sense" else 0,
        first_set=FIRST_SET if spec.kind == "sense" else 0,
    )
