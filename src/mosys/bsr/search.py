"""The serial search of the 1995 paper's Figure 3 for a BSR controller.

C controllers are drawn from Table 2's distributions and evaluated; then, for G generations, each
is mutated (one rule re-initialised with probability ``reinitialize``, else one rule crept) and
the mutant replaces it if it is fitter; every ``reseed`` generations the worse half of the set is
replaced by copies of the better half. All random numbers come, in a fixed order, from one
generator seeded with the search's seed, and each generation's C simulations are independent, so
a seed gives the same result whatever the number of threads that run them.

Choices where the paper is silent (documented in the README): creep perturbs every parameter of
the rule (target angles by N(0, 0.1 range), tau by a factor exp N(0, 0.2), centres by N(0, 0.1),
sides by a factor exp N(0, 0.1), a time segment's weight by exp N(0, 0.2)), each clipped to Table
2's range; a re-initialised sense rule puts one corner of its new hyper-rectangle (sides drawn as
Table 2) on the sense vector at a random step of the parent's run (just outside it, at 0.98 of
the half-side from the centre, so that the rule fires there); a time-based rule's segment
length is its weight over the sum of weights times t_per, weights drawn uniformly in [0.2, 1].

The same search drives 2-D and 3-D figures: a ``SearchSetup`` carries the simulation that
evaluates a population and records a run (``PlanarSimulation`` here, the 3-D one in
``mosys.bsr.search3d``), and how new sense rules are made relevant: 2-D shares a corner with
the sense trajectory; 3-D (§4.2) contains a point of it (the point uniformly inside the box, at
most 0.98 of the half-side from the centre), and a first set of 100 controllers (§4.2) is
enriched by three rounds of that mutation before the search begins, its best C going on.

A run whose figure's state blows up (NaN, inf or beyond ±``kernels.soundness.STATE_LIMIT``: the
kernels stop there) aborts the search with ``NonFiniteStateError`` at the spec's ``simulate``
line, naming the time, seed, generation and state; no candidate is ever scored NaN. A fitness
that is NaN all the same (weights so large that the terms overflow to inf - inf) ranks as -inf:
never best.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Literal, Protocol

import numpy as np

from mosys.bsr.figure import BsrFigure
from mosys.bsr.start import perturbed_state, standing_state
from mosys.errors import NonFiniteStateError
from mosys.io.bsr_result import BsrController
from mosys.io.progress import Progress
from mosys.kernels.bsr_controller import (
    CENTER_MAX,
    CENTER_MIN,
    SIDE_MAX,
    SIDE_MIN,
    ControllerArrays,
    RunRecord,
    run_controller,
    run_population,
)
from mosys.kernels.compile_lock import cold_compilation_seconds
from mosys.kernels.libm import exp_each
from mosys.kernels.soundness import steps_before_blow_up, unsoundness
from mosys.parsing.bsr import FITNESS_TERMS, BsrSpec
from mosys.parsing.tokens import SpecError, Token, location

if TYPE_CHECKING:  # the 3-D figure, for an annotation only
    from mosys.bsr.figure3d import BsrFigure3D

CORNER_INSIDE = 0.98  # a re-initialised box's corner: this fraction of the half-side out
SEGMENT_WEIGHT_MIN = 0.2
SEGMENT_WEIGHT_MAX = 1.0
CREEP_TARGET = 0.1  # of the joint's range
CREEP_LOG_TAU = 0.2
CREEP_CENTER = 0.1
CREEP_LOG_SIDE = 0.1
CREEP_LOG_SEGMENT = 0.2
# deg: a start angle this close outside its joint's range is on it (the range is kept in rad)
ANGLE_ROUNDING_DEG = 1e-9


class Simulation(Protocol):
    """How a search runs its figure: ``evaluate`` runs every controller of a population once
    and returns their fitness (C,), filling the population's senses; ``record`` runs one
    controller from the nominal start, every step recorded; both raise NonFiniteStateError
    (``check_run``) where a run's state blows up. ``describe_state``: a state (S,) SI of the
    figure in the spec's units. ``term_names``: the fitness terms its runs measure, in their
    order."""

    term_names: tuple[str, ...]

    def describe_state(self, figure, state: np.ndarray) -> str: ...

    def evaluate(
        self, setup: SearchSetup, population: _Population, rng: np.random.Generator
    ) -> np.ndarray: ...

    def record(self, setup: SearchSetup, controller: BsrController) -> RecordedRun: ...


@dataclass(frozen=True)
class SearchSetup:
    """A spec bound to its figure: the nominal start pose (root angle rad, joints (J,) rad, x
    m), the fall endpoints' indices, the term weights in the order of the simulation's terms,
    the budget, the simulation, the relevance heuristic (``corner`` or ``contain``), how many
    rounds of it enrich the first population, and how many controllers that first population
    has (``first_set``; 0: C) before the best C of them are kept."""

    spec: BsrSpec
    figure: BsrFigure
    root_angle: float
    joints: np.ndarray
    x: float
    fall_endpoints: np.ndarray
    weights: np.ndarray
    generations: int
    simulation: Simulation
    relevance: Literal["corner", "contain"] = "corner"
    enrich_rounds: int = 0
    first_set: int = 0

    @property
    def first_size(self) -> int:
        """The first population's size: ``first_set``, or C where that is larger (or 0)."""
        return max(self.spec.controllers, self.first_set)

    @classmethod
    def bound(
        cls,
        spec: BsrSpec,
        figure,
        names: BoundNames,
        generations: int | None,
        simulation: Simulation,
        **search,
    ) -> SearchSetup:
        """The set-up of a spec whose names ``bind_names`` looked up in its figure (2-D or 3-D);
        ``generations`` overrides the spec's G; ``search``: ``relevance``, ``enrich_rounds``,
        ``first_set``."""
        return cls(
            spec=spec,
            figure=figure,
            root_angle=names.root_angle,
            joints=names.joints,
            x=names.x,
            fall_endpoints=names.fall_endpoints,
            weights=names.weights,
            generations=spec.generations if generations is None else generations,
            simulation=simulation,
            **search,
        )

    @property
    def tau_range(self) -> tuple[float, float]:
        """Table 2: tau in [2 dt, T / 4], s (from tau_min if the spec raises the floor)."""
        low = 2.0 * self.spec.dt if self.spec.tau_min is None else self.spec.tau_min
        return low, self.spec.duration / 4.0

    @property
    def period(self) -> float:
        return self.spec.duration if self.spec.period is None else self.spec.period


@dataclass(frozen=True)
class SearchOutcome:
    """What a search found: the learning curve (evaluations (M,), best fitness (M,)), the best
    controller, its fitness during the search, and its run from the nominal start (terms named
    by ``term_names``, the active rule (steps + 1,), rod ends (steps + 1, N, 2, D) m, com (steps
    + 1, D) m, the state it ends in (S,) and its endpoints' forces (E,) N), the wall time s and
    the simulated steps per second."""

    evaluations: np.ndarray
    best_fitness: np.ndarray
    controller: BsrController
    fitness: float
    nominal_fitness: float
    terms: np.ndarray
    active_rule: np.ndarray
    rod_ends: np.ndarray
    com: np.ndarray
    wall_seconds: float
    steps_per_second: float  # numba's compilation left out (``compile_seconds``)
    compile_seconds: float  # of wall_seconds: compiling kernels that missed numba's cache
    term_names: tuple[str, ...] = FITNESS_TERMS
    final_state: np.ndarray | None = None
    final_force: np.ndarray | None = None

    def terms_json(self) -> str:
        terms = zip(self.term_names, self.terms, strict=True)
        return json.dumps({name: float(value) for name, value in terms})


@dataclass(frozen=True)
class BoundNames:
    """A spec's names looked up in its figure: the start pose (root angle rad, joint angles
    (J,) rad, x m), the fall endpoints' indices (F,) and the term weights in the figure's term
    order."""

    root_angle: float
    joints: np.ndarray
    x: float
    fall_endpoints: np.ndarray
    weights: np.ndarray


def bind_names(
    spec: BsrSpec, figure: BsrFigure | BsrFigure3D, term_names: tuple[str, ...]
) -> BoundNames:
    """Look the spec's start coordinates, fall endpoints and fitness terms up in the figure (a
    2-D or 3-D BSR figure: its ``root_angle``, ``root_x``, ``joint_names``, ``endpoint_names``)
    and ``term_names``; a name it lacks raises SpecError at its word, and so does a figure
    without gravity, at the spec's ``figure`` line."""
    if not figure.gravity > 0.0:  # the senses' scales: the weight M g and the speed of a fall
        raise SpecError.at(
            spec.path,
            spec.tokens["figure"],
            f"a figure with gravity > 0 for a BSR search (the controllers' senses are scaled by "
            f"its weight and its speed of fall; '{figure.figure.name}' has gravity "
            f"{figure.gravity:g})",
        )
    if math.isnan(figure.floor):  # no floor: every fitness term and sense reads the ground
        raise SpecError.at(
            spec.path,
            spec.tokens["figure"],
            f"a figure on a floor for a BSR search (a 'terrain floor' line: the fitness terms "
            f"and senses measure the figure against the ground; '{figure.figure.name}' has "
            "none and would fall for ever)",
        )
    for term in spec.weights:
        if term not in term_names:
            raise SpecError.at(
                spec.path,
                spec.tokens[f"fitness.{term}"],
                f"a fitness term of figure '{figure.figure.name}' ({', '.join(term_names)})",
            )
    known = {figure.root_angle: "angle", figure.root_x: "x"}
    known.update({name: "joint" for name in figure.joint_names})
    joints = np.zeros(len(figure.joint_names))
    root_angle = 0.0
    x = 0.0
    for name, value in spec.start.items():
        kind = known.get(name)
        if kind is None:
            raise SpecError.at(
                spec.path,
                spec.tokens[f"start.{name}"],
                f"a coordinate of figure '{figure.figure.name}' ({', '.join(known)})",
            )
        if kind == "x":
            x = value
        elif kind == "angle":
            root_angle = math.radians(value)
        else:
            joint = figure.joint_names.index(name)
            low, high = np.degrees([figure.joint_min[joint], figure.joint_max[joint]])
            if not low - ANGLE_ROUNDING_DEG <= value <= high + ANGLE_ROUNDING_DEG:
                allowed = (
                    f"{name} at its fixed angle, {low:g} deg"
                    if low == high
                    else f"an angle of {name} within its range, {low:g} to {high:g} deg"
                )
                raise SpecError.at(spec.path, spec.tokens[f"start.{name}"], allowed)
            joints[joint] = math.radians(value)
    fall = []
    for i, endpoint in enumerate(spec.fall):
        name = f"{endpoint.rod}.{endpoint.end}"
        if name not in figure.endpoint_names:
            raise SpecError.at(
                spec.path,
                spec.tokens[f"fall.{i}"],
                f"an endpoint of figure '{figure.figure.name}' "
                f"({', '.join(figure.endpoint_names)})",
            )
        fall.append(figure.endpoint_names.index(name))
    return BoundNames(
        root_angle,
        joints,
        x,
        np.array(fall, np.int64),
        np.array([spec.weights.get(term, 0.0) for term in term_names]),
    )


def bind_search(spec: BsrSpec, figure: BsrFigure, generations: int | None = None) -> SearchSetup:
    """Check the spec's names against the figure (start coordinates, fall endpoints, terms) and
    lay out its numbers; a name the figure lacks, or a 3-D option, raises SpecError at its word.
    ``generations`` overrides the spec's G (a reduced budget)."""
    three_d_only = {
        "filter": "no filter= for a 2-D figure (the senses' low-pass filter is 3-D's)",
        "fall.below": "no below= for a 2-D figure (it has fallen when an endpoint of its 'fall' "
        "line touches the floor; a height is 3-D's)",
    }
    for key, expected in three_d_only.items():  # both were ignored without a word (a
        # fall line of below= alone measured nothing)
        if key in spec.tokens:
            raise SpecError.at(spec.path, spec.tokens[key], expected)
    names = bind_names(spec, figure, FITNESS_TERMS)
    return SearchSetup.bound(spec, figure, names, generations, PlanarSimulation())


def searched_variables(setup: SearchSetup) -> int:
    """The variables the search varies: per rule the free (not fixed) angles' targets and tau,
    plus the sense-based rules' boxes (centre and side per sense) or the time-based segments
    (R - 1 independent lengths)."""
    spec = setup.spec
    free = int(np.count_nonzero(setup.figure.joint_max > setup.figure.joint_min))
    if spec.kind == "sense":
        return spec.rules * (free + 1 + 2 * len(setup.figure.sense_names))
    return spec.rules * (free + 1) + spec.rules - 1


def search_memory_bytes(setup: SearchSetup, record_step_bytes: int) -> float:
    """About the memory a search takes, bytes: two populations (the controllers and their
    mutants; or the first population, where it is larger), each controller's rules (targets,
    tau, boxes) and the senses of its last run (steps + 1, V) float64 (``_Population``), and one
    recorded run of ``record_step_bytes`` per step."""
    spec, figure = setup.spec, setup.figure
    senses = len(figure.sense_names)
    rules = 8.0 * spec.rules * (len(figure.joint_names) + 3 + 2 * senses)
    per_controller = rules + 8.0 * (spec.steps + 1) * senses
    populations = max(2 * spec.controllers, setup.first_size)
    return float(populations) * per_controller + float(spec.steps) * record_step_bytes


class _Population:
    """C controllers (or ``size``) as stacked arrays (what ``run_population`` takes), their
    fitness and the sense trajectory of each one's last run (for the relevance heuristic)."""

    ARRAYS = ("target", "tau", "center", "side", "segment", "senses", "fitness")

    def __init__(self, setup: SearchSetup, rng: np.random.Generator, size: int | None = None):
        spec, figure = setup.spec, setup.figure
        c = spec.controllers if size is None else size
        r, j, v = spec.rules, len(figure.joint_names), 0
        if spec.kind == "sense":
            v = len(figure.sense_names)
        self.setup = setup
        self.target = np.empty((c, r, j))
        self.tau = np.empty((c, r))
        self.center = np.empty((c, r, v))
        self.side = np.empty((c, r, v))
        self.segment = np.ones((c, r))
        self.draw_first_rules(rng)
        self.fitness = np.full(c, -np.inf)
        self.senses = np.zeros((c, spec.steps + 1, len(figure.sense_names)))

    def draw_first_rules(self, rng: np.random.Generator) -> None:
        """Every rule of every controller as ``draw_rule`` without senses draws them, rule after
        rule, bit for bit, but from one call for all their uniform numbers (a draw is
        ``low + (high - low) * next_double``, in order), not from five calls a rule: a search
        with 10,000 rules a controller spent seconds here."""
        figure = self.setup.figure
        low, high = self.setup.tau_range
        c, r, j = self.target.shape
        v = self.center.shape[2]
        draws = rng.random((c, r, j + 1 + (2 * v if v else 1)))
        span = figure.joint_max - figure.joint_min
        self.target[...] = figure.joint_min + span * draws[:, :, :j]
        log_low, log_high = math.log(low), math.log(high)
        self.tau[...] = exp_each(log_low + (log_high - log_low) * draws[:, :, j])
        if v:
            side_low, side_high = math.log(SIDE_MIN), math.log(SIDE_MAX)
            self.side[...] = exp_each(
                side_low + (side_high - side_low) * draws[:, :, j + 1 : j + 1 + v]
            )
            self.center[...] = CENTER_MIN + (CENTER_MAX - CENTER_MIN) * draws[:, :, j + 1 + v :]
        else:
            self.segment[...] = (
                SEGMENT_WEIGHT_MIN + (SEGMENT_WEIGHT_MAX - SEGMENT_WEIGHT_MIN) * draws[:, :, j + 1]
            )

    def draw_rule(self, k: int, i: int, rng: np.random.Generator, senses: np.ndarray | None):
        """Rule i of controller k from Table 2; with senses (steps + 1, V), its
        hyper-rectangle on a random one of them (the relevance heuristic: a corner there, or
        containing it)."""
        figure = self.setup.figure
        low, high = self.setup.tau_range
        self.target[k, i] = rng.uniform(figure.joint_min, figure.joint_max)
        self.tau[k, i] = math.exp(rng.uniform(math.log(low), math.log(high)))
        v = self.center.shape[2]
        if v:
            self.side[k, i] = exp_each(rng.uniform(math.log(SIDE_MIN), math.log(SIDE_MAX), v))
            if senses is None:
                self.center[k, i] = rng.uniform(CENTER_MIN, CENTER_MAX, v)
            elif self.setup.relevance == "contain":
                point = senses[rng.integers(senses.shape[0])]
                where = rng.uniform(-1.0, 1.0, v)
                self.center[k, i] = point + where * self.side[k, i] / 2.0 * CORNER_INSIDE
            else:
                corner = senses[rng.integers(senses.shape[0])]
                sign = rng.choice(np.array([-1.0, 1.0]), v)
                # the sense point sits just inside that corner, so that the rule fires there
                # (exactly on it, its score would be 0: never positive, never active)
                self.center[k, i] = corner + sign * self.side[k, i] / 2.0 * CORNER_INSIDE
        else:
            self.segment[k, i] = rng.uniform(SEGMENT_WEIGHT_MIN, SEGMENT_WEIGHT_MAX)

    def creep_rule(self, k: int, i: int, rng: np.random.Generator):
        """Perturb every parameter of rule i of controller k slightly, within Table 2's ranges."""
        figure = self.setup.figure
        low, high = self.setup.tau_range
        span = figure.joint_max - figure.joint_min
        self.target[k, i] = np.clip(
            self.target[k, i] + rng.normal(0.0, CREEP_TARGET, span.shape) * span,
            figure.joint_min,
            figure.joint_max,
        )
        creep = math.exp(rng.normal(0.0, CREEP_LOG_TAU))
        self.tau[k, i] = np.clip(self.tau[k, i] * creep, low, high)
        v = self.center.shape[2]
        if v:
            self.center[k, i] = np.clip(
                self.center[k, i] + rng.normal(0.0, CREEP_CENTER, v), CENTER_MIN, CENTER_MAX
            )
            self.side[k, i] = np.clip(
                self.side[k, i] * exp_each(rng.normal(0.0, CREEP_LOG_SIDE, v)),
                SIDE_MIN,
                SIDE_MAX,
            )
        else:
            self.segment[k, i] = np.clip(
                self.segment[k, i] * math.exp(rng.normal(0.0, CREEP_LOG_SEGMENT)),
                SEGMENT_WEIGHT_MIN,
                SEGMENT_WEIGHT_MAX,
            )

    def copy(self) -> _Population:
        """An independent copy (its arrays are new)."""
        return self.take(slice(None))

    def take(self, keep: np.ndarray | slice) -> _Population:
        """A population of the controllers ``keep`` (K,) of this one, in that order (a slice:
        those it selects); its arrays are new."""
        kept = _Population.__new__(_Population)
        kept.setup = self.setup
        for name in _Population.ARRAYS:
            setattr(kept, name, getattr(self, name)[keep].copy())
        return kept

    def copy_from(self, other: _Population, k_to: int, k_from: int) -> None:
        for name in _Population.ARRAYS:
            getattr(self, name)[k_to] = getattr(other, name)[k_from]

    def segment_end(self) -> np.ndarray:
        """(C, R) cumulative segment ends, s (time-based)."""
        weights = self.segment / self.segment.sum(axis=1, keepdims=True)
        ends = np.cumsum(weights, axis=1) * self.setup.period
        ends[:, -1] = self.setup.period
        return ends

    def controller(self, k: int) -> BsrController:
        spec = self.setup.spec
        segment = np.diff(self.segment_end()[k], prepend=0.0) if spec.kind == "time" else None
        return BsrController(
            kind=spec.kind,
            target=self.target[k].copy(),
            tau=self.tau[k].copy(),
            center=self.center[k].copy(),
            side=self.side[k].copy(),
            segment=np.zeros(0) if segment is None else segment,
            period=self.setup.period if spec.kind == "time" else math.nan,
        )


def population_arrays(setup: SearchSetup, population: _Population) -> ControllerArrays:
    """The population as the kernels take it (arrays with a leading axis C)."""
    return ControllerArrays(
        setup.spec.kind == "time",
        population.target,
        population.tau,
        population.center,
        population.side,
        population.segment_end(),
        setup.period,
    )


def describe_values(values: list[tuple[str, float, str]]) -> str:
    """``name=value unit, ...`` of (name, value, unit) triples, each value to 6 digits (unit
    "": a pure number)."""
    return ", ".join(f"{name}={value:.6g} {unit}".rstrip() for name, value, unit in values)


def describe_planar_state(figure: BsrFigure, state: np.ndarray) -> str:
    """A 2-D BSR state (S = 6 + 2J,) SI in the spec's units: the centre of mass (cm_x, cm_y m;
    cm_vx, cm_vy m/s), the root rod's angle (deg), the angular momentum L (kg·m²/s), the joint
    angles (deg) and their rates (NAME', deg/s)."""
    joints = figure.joint_names
    n = len(joints)
    values = [
        ("cm_x", state[0], "m"),
        ("cm_y", state[1], "m"),
        ("cm_vx", state[2], "m/s"),
        ("cm_vy", state[3], "m/s"),
        (figure.root_angle, math.degrees(state[4]), "deg"),
        ("L", state[5], "kg·m²/s"),
    ]
    for j, name in enumerate(joints):
        values.append((name, math.degrees(state[6 + j]), "deg"))
    for j, name in enumerate(joints):
        values.append((f"{name}'", math.degrees(state[6 + n + j]), "deg/s"))
    return describe_values(values)


def unsound_state_message(t: float, state: np.ndarray, described: str, when: str = "") -> str:
    """What NonFiniteStateError says of a BSR run whose state (S,) SI, ``described`` in the
    spec's units, was not sound (``kernels.soundness.state_is_sound``) at ``t`` s from the run's
    start; ``when``: which run (seed, generation), if known. A state that blew up during the run
    may want a smaller dt; one unsound at t = 0 was the start itself, which no dt mends."""
    during = f" ({when})" if when else ""
    hint = "a smaller dt= may help"
    if t == 0:
        hint = "the start is not sound (a huge start or perturb value?)"
    return f"the figure's state {unsoundness(state)} at t = {t:.6g} s{during}: {described}; {hint}"


def check_run(
    taken: int, dt: float, state: np.ndarray, describe: Callable[[np.ndarray], str]
) -> None:
    """Raise NonFiniteStateError if a run of dt s steps returned ``blown_up(n)`` (taken < 0):
    its state ``state`` (S,) SI was not sound at t = n dt s (``describe`` puts it in the spec's
    units). The message names no file: ``located`` adds the spec's."""
    if taken >= 0:
        return
    t = steps_before_blow_up(taken) * dt
    state = np.array(state, np.float64)
    raise NonFiniteStateError(unsound_state_message(t, state, describe(state)), t, state)


def check_population(
    taken: np.ndarray, final: np.ndarray, dt: float, describe: Callable[[np.ndarray], str]
) -> None:
    """``check_run`` of the first (lowest-numbered) of C runs that stopped: taken (C,) what
    each returned, final (C, S) SI their last states."""
    stopped = np.flatnonzero(taken < 0)
    if stopped.size:
        check_run(int(taken[stopped[0]]), dt, final[stopped[0]], describe)


def located(setup: SearchSetup, error: NonFiniteStateError, when: str) -> NonFiniteStateError:
    """``error`` of one of the setup's runs, led by the spec's ``simulate`` line (its dt=) and
    naming ``when`` (seed, generation)."""
    spec = setup.spec
    token = spec.simulate_token if spec.simulate_token.line else Token("simulate", 1, 1)
    described = setup.simulation.describe_state(setup.figure, error.state)
    message = unsound_state_message(error.t, error.state, described, when)
    return NonFiniteStateError(f"{location(spec.path, token)}: {message}", error.t, error.state)


def ranked(fitness: float | np.ndarray) -> np.ndarray:
    """A fitness (C,) or a score as a search ranks it: NaN (terms times weights overflowing to
    inf - inf; a composite script's 0/0) becomes -inf, never best."""
    return np.where(np.isnan(fitness), -np.inf, fitness)


class PlanarSimulation:
    """The 2-D simulator of ``mosys.kernels.bsr_simulate`` (Simulation)."""

    term_names = FITNESS_TERMS

    def describe_state(self, figure: BsrFigure, state: np.ndarray) -> str:
        return describe_planar_state(figure, state)

    def evaluate(
        self, setup: SearchSetup, population: _Population, rng: np.random.Generator
    ) -> np.ndarray:
        """Run every controller once (from the nominal start, or a perturbed one per
        controller); returns the fitness (C,), and fills population.senses."""
        return _evaluate(setup, population, rng)

    def record(self, setup: SearchSetup, controller: BsrController) -> RecordedRun:
        """Run one controller from the nominal start, recording every step."""
        return record_run(
            setup.figure,
            controller,
            standing_state(setup.figure, setup.root_angle, setup.joints, setup.x),
            setup.spec.steps,
            setup.spec.dt,
            setup.fall_endpoints,
        )


def _evaluate(setup: SearchSetup, population: _Population, rng: np.random.Generator):
    """PlanarSimulation.evaluate."""
    spec, figure = setup.spec, setup.figure
    c = population.target.shape[0]  # C, or the first population's size
    if spec.perturbation.any:
        starts = np.stack(
            [
                perturbed_state(
                    figure, setup.root_angle, setup.joints, setup.x, spec.perturbation, rng
                )
                for _ in range(c)
            ]
        )
    else:
        start = standing_state(figure, setup.root_angle, setup.joints, setup.x)
        starts = np.repeat(start[None, :], c, axis=0)
    rules = np.zeros((c, spec.steps + 1), np.int64)
    terms = np.zeros((c, len(FITNESS_TERMS)))
    taken = np.zeros(c, np.int64)
    final = np.empty_like(starts)
    run_population(
        figure.arrays,
        population_arrays(setup, population),
        starts,
        spec.steps,
        spec.dt,
        setup.fall_endpoints,
        population.senses,
        rules,
        terms,
        taken,
        final,
    )
    check_population(taken, final, spec.dt, partial(describe_planar_state, figure))
    return terms @ setup.weights


def _evaluated(
    setup: SearchSetup, population: _Population, rng: np.random.Generator, when: str
) -> np.ndarray:
    """The population's fitness (C,) as the search ranks it (``ranked``); a run that blows up
    raises NonFiniteStateError at the spec's ``simulate`` line, naming ``when``."""
    try:
        return ranked(setup.simulation.evaluate(setup, population, rng))
    except NonFiniteStateError as error:
        raise located(setup, error, when) from None


def run_search(setup: SearchSetup, seed: int, label: str = "search") -> SearchOutcome:
    """Figure 3 with the setup's C, G and reseed period, seeded with ``seed``; reports
    progress (generations, rate, ETA, best fitness) on stderr."""
    spec = setup.spec
    c = spec.controllers
    rng = np.random.default_rng(seed)
    compiled = cold_compilation_seconds()
    began = time.perf_counter()
    first_size = setup.first_size
    current = _Population(setup, rng, first_size)
    first = f"seed {seed}, generation 0"
    # silent unless slow (many rules): a line at most every second, and no closing line
    starting = Progress(f"{label}: first population", 1 + setup.enrich_rounds, "rounds")
    current.fitness[:] = _evaluated(setup, current, rng, first)
    starting.update(1)
    for round_ in range(setup.enrich_rounds):
        # §4.2: rounds of the relevance-heuristic mutation enrich the first population
        for k in range(first_size):
            current.draw_rule(k, int(rng.integers(spec.rules)), rng, current.senses[k])
        current.fitness[:] = _evaluated(setup, current, rng, first)
        starting.update(2 + round_)
    if first_size > c:  # §4.2's "first set of 100": the best C go on
        current = current.take(np.argsort(-current.fitness, kind="stable")[:c])
    mutant = current.copy()
    best_k = int(np.argmax(current.fitness))
    best = current.controller(best_k)
    best_fitness = float(current.fitness[best_k])
    evaluations = [first_size * (1 + setup.enrich_rounds)]
    curve = [best_fitness]
    progress = Progress(label, setup.generations, "generations")
    for generation in range(1, setup.generations + 1):
        for k in range(c):
            mutant.copy_from(current, k, k)
            i = int(rng.integers(spec.rules))
            if rng.random() < spec.reinitialize:
                mutant.draw_rule(k, i, rng, current.senses[k] if spec.kind == "sense" else None)
            else:
                mutant.creep_rule(k, i, rng)
        fitness = _evaluated(setup, mutant, rng, f"seed {seed}, generation {generation}")
        for k in range(c):
            if fitness[k] > current.fitness[k]:
                current.copy_from(mutant, k, k)
                current.fitness[k] = fitness[k]
        k = int(np.argmax(current.fitness))
        if current.fitness[k] > best_fitness:
            best_fitness = float(current.fitness[k])
            best = current.controller(k)
        if generation % spec.reseed == 0:
            order = np.argsort(-current.fitness, kind="stable")
            half = c // 2
            for worse, better in zip(order[c - half :], order[:half], strict=True):
                current.copy_from(current, int(worse), int(better))
        evaluations.append(evaluations[0] + c * generation)
        curve.append(best_fitness)
        progress.update(generation, f"best fitness {best_fitness:.3f}")
    progress.finish(f"best fitness {best_fitness:.3f}")
    wall = time.perf_counter() - began
    compiling = cold_compilation_seconds() - compiled  # a fresh install's first search: a minute
    try:
        run = setup.simulation.record(setup, best)
    except NonFiniteStateError as error:
        raise located(setup, error, f"seed {seed}, the best controller's recorded run") from None
    return SearchOutcome(
        evaluations=np.array(evaluations, np.int64),
        best_fitness=np.array(curve),
        controller=best,
        fitness=best_fitness,
        nominal_fitness=float(ranked(run.terms @ setup.weights)),
        terms=run.terms,
        active_rule=run.active_rule,
        rod_ends=run.rod_ends,
        com=run.com,
        wall_seconds=wall,
        steps_per_second=evaluations[-1] * spec.steps / max(wall - compiling, 1e-9),
        compile_seconds=compiling,
        term_names=setup.simulation.term_names,
        final_state=run.final_state,
        final_force=run.final_force,
    )


def nominal_run(setup: SearchSetup, controller: BsrController) -> RecordedRun:
    """Run one controller from the nominal start, recording every step."""
    return setup.simulation.record(setup, controller)


@dataclass(frozen=True)
class RecordedRun:
    """One controller's run, every step: terms (the simulation's terms), active_rule (steps +
    1,), rod_ends (steps + 1, N, 2, D) m, com (steps + 1, D) m (D = 2 or 3), and where it
    ended: final_state (S,) and the endpoints' normal forces final_force (E,) N."""

    terms: np.ndarray
    active_rule: np.ndarray
    rod_ends: np.ndarray
    com: np.ndarray
    final_state: np.ndarray
    final_force: np.ndarray

    @classmethod
    def empty(
        cls, terms: int, steps: int, figure, dimensions: int, start: np.ndarray
    ) -> RecordedRun:
        """Zeroed arrays for a run of ``steps`` steps of ``figure`` (its ``parent`` (N,) and
        ``endpoints`` (E, 2)) in ``dimensions`` (2 or 3) from the state ``start`` (S,)."""
        return cls(
            terms=np.zeros(terms),
            active_rule=np.zeros(steps + 1, np.int64),
            rod_ends=np.zeros((steps + 1, figure.parent.shape[0], 2, dimensions)),
            com=np.zeros((steps + 1, dimensions)),
            final_state=np.empty_like(start),
            final_force=np.empty(figure.endpoints.shape[0]),
        )

    def record(self, senses: int) -> RunRecord:
        """The kernels' RunRecord writing into these arrays, with room for ``senses`` senses."""
        return RunRecord(
            np.zeros((self.active_rule.shape[0], senses)),
            self.active_rule,
            self.terms,
            self.rod_ends,
            self.com,
            self.final_state,
            self.final_force,
        )


def controller_arrays(controller: BsrController) -> ControllerArrays:
    """One controller as the kernels take it (a time-based one's segments as their cumulative
    ends, s, the last exactly its period)."""
    time_based = controller.kind == "time"
    segment_end = np.cumsum(controller.segment) if time_based else np.zeros(controller.rules)
    if time_based:
        segment_end[-1] = controller.period
    return ControllerArrays(
        time_based,
        controller.target,
        controller.tau,
        controller.center,
        controller.side,
        segment_end,
        controller.period if time_based else 1.0,
    )


def record_run(
    figure: BsrFigure,
    controller: BsrController,
    start: np.ndarray,
    steps: int,
    dt: float,
    fall_endpoints: np.ndarray | None = None,
    start_force: np.ndarray | None = None,
    carry_over: bool = False,
) -> RecordedRun:
    """Run ``controller`` for ``steps`` steps of dt s from the state ``start`` (S,), recording
    every step. ``start_force`` (E,) N and ``carry_over``: a controller taking over from another
    keeps the senses (contact forces) where the last one left them and starts with the rule
    they select. A state that blows up raises NonFiniteStateError (``check_run``; t from the
    run's start)."""
    n_ends = figure.endpoints.shape[0]
    run = RecordedRun.empty(len(FITNESS_TERMS), steps, figure, 2, start)
    taken = run_controller(
        figure.arrays,
        controller_arrays(controller),
        np.asarray(start, np.float64),
        np.zeros(n_ends) if start_force is None else np.asarray(start_force, np.float64),
        carry_over,
        steps,
        dt,
        np.zeros(0, np.int64) if fall_endpoints is None else fall_endpoints,
        run.record(len(figure.sense_names)),
    )
    check_run(taken, dt, run.final_state, partial(describe_planar_state, figure))
    return run
