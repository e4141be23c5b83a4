"""A composite script bound to what it runs: the figure, each phase's BSR controller, the start
state and the time step. The pipeline's transition search and the interactive editor both score
phase durations through one ``CompositeSession``.

Each phase names a BSR search (``results/bsr/SEARCH/seedK.h5``). Its controller is the seed the
phase names, or else the seed whose best controller scores best from the search's own nominal
start (the ``nominal_fitness`` attribute; the search's ``best_fitness`` of a perturbed search is
one lucky draw). The motion starts from the first phase's search's nominal start pose, at rest.

A motion whose figure's state blows up (NaN, inf or beyond ±``kernels.soundness.STATE_LIMIT``)
raises NonFiniteStateError at the script's line of the phase that was running, with the
motion's time and state: no score is ever NaN for it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mosys.bsr.figure import BsrFigure, load_bsr_figure
from mosys.bsr.search import bind_search, describe_planar_state, unsound_state_message
from mosys.bsr.start import standing_state
from mosys.composite.concatenation import ConcatenatedMotion, run_concatenation
from mosys.composite.evaluate import PhaseMotion, score_script
from mosys.composite.phase_searches import check_phase_searches
from mosys.composite.transitions import equal_split
from mosys.errors import NonFiniteStateError
from mosys.io.bsr_result import BsrController, read_bsr_result
from mosys.parsing.bsr import parse_bsr_spec
from mosys.parsing.composite_script import CompositeScript
from mosys.parsing.tokens import SpecError, location

SEED_FILE = re.compile(r"seed(\d+)\.h5$")  # a search's result files: SEARCH/seedK.h5


@dataclass(frozen=True)
class ScoredMotion:
    """One concatenation and its script scores: ``ticks`` (P,) the phase durations, the motion,
    each phase's score (phase name -> score) and the total."""

    ticks: np.ndarray
    motion: ConcatenatedMotion
    scores: dict[str, float]
    total: float


@dataclass(frozen=True)
class CompositeSession:
    """The script, its figure, one controller per phase (and the seed it came from, and its
    file), the start state (S,), the time step dt s, and the length in ticks a script without
    guessed durations splits equally: the phases' searches' run lengths (each its T) together."""

    script: CompositeScript
    figure: BsrFigure
    controllers: tuple[BsrController, ...]
    seeds: tuple[int, ...]
    controller_files: tuple[str, ...]
    start: np.ndarray
    dt: float
    default_length: int

    @property
    def guess(self) -> np.ndarray:
        """The guessed phase durations (P,) ticks: the script's, or the phases' searches' run
        lengths together split equally."""
        if self.script.guessed_ticks is not None:
            return np.array(self.script.guessed_ticks, np.int64)
        return equal_split(self.default_length, len(self.controllers))

    def run(self, ticks: Sequence[int]) -> ConcatenatedMotion:
        """The concatenated motion with these phase durations (P,) ticks; a state that blows up
        raises NonFiniteStateError at the script's line of the phase it blew up in."""
        try:
            return run_concatenation(self.figure, self.controllers, ticks, self.start, self.dt)
        except NonFiniteStateError as error:
            raise self._blown_up([int(count) for count in ticks], error) from None

    def _blown_up(self, ticks: list[int], error: NonFiniteStateError) -> NonFiniteStateError:
        """``error`` of ``run(ticks)`` (its t from the start of a phase) located: the phase is
        the first whose motion up to its end blows up (the motion up to each phase is run
        again, on this error path only), t becomes the motion's time."""
        phase = len(ticks) - 1
        for k in range(len(ticks) - 1):
            if sum(max(count, 0) for count in ticks[: k + 1]) == 0:
                continue  # no motion yet
            try:
                run_concatenation(
                    self.figure, self.controllers[: k + 1], ticks[: k + 1], self.start, self.dt
                )
            except NonFiniteStateError:
                phase = k
                break
        t = sum(max(count, 0) for count in ticks[:phase]) * self.dt + error.t
        name = self.script.phases[phase].name
        token = self.script.tokens[f"phase.{name}.controller"]
        during = f"phase {name}, durations {', '.join(map(str, ticks))} ticks"
        described = describe_planar_state(self.figure, error.state)
        message = unsound_state_message(t, error.state, described, during)
        return NonFiniteStateError(
            f"{location(self.script.path, token)}: {message}", t, error.state
        )

    def score(self, ticks: Sequence[int]) -> ScoredMotion:
        """Run the phases for ``ticks`` (P,) and score the motion with the script."""
        ticks = np.asarray(ticks, np.int64)
        motion = self.run(ticks)
        phases = {}
        for k, phase in enumerate(self.script.phases):
            samples = motion.phase_samples(k)
            phases[phase.name] = PhaseMotion.from_rod_ends(
                motion.com[samples], motion.rod_ends[samples], int(ticks[k])
            )
        scores, total = score_script(self.script, phases)
        return ScoredMotion(ticks=ticks, motion=motion, scores=scores, total=total)

    def total(self, ticks: Sequence[int]) -> float:
        """The script's total for these phase durations (what the search maximises)."""
        return self.score(ticks).total


def files_by_search(result_paths: Sequence[str | Path]) -> dict[str, list[Path]]:
    """Seed files grouped by their directory: results/bsr/SEARCH/seedK.h5 -> SEARCH."""
    grouped: dict[str, list[Path]] = {}
    for path in map(Path, result_paths):
        grouped.setdefault(path.parent.name, []).append(path)
    return grouped


def find_controller_files(script: CompositeScript, results_dir: str | Path) -> dict[str, list]:
    """Each phase's search -> its result files ``results_dir/SEARCH/seed*.h5``, sorted by seed."""
    found = {}
    for phase in script.phases:
        files = Path(results_dir, phase.controller).glob("seed*.h5")
        found[phase.controller] = sorted(
            (path for path in files if SEED_FILE.search(path.name)),
            key=lambda path: int(SEED_FILE.search(path.name).group(1)),
        )
    return found


BUILD_ATTRS = ("spec_sha256", "generations", "budget")  # what the seeds of one build share


def _one_build(script, token, search: str, results: Mapping, files: Mapping) -> None:
    """SpecError at the phase's search unless its seed files come from one build: one version
    of the spec, one budget (a seed left from an earlier build, beside seeds rebuilt at another
    G, was mixed in without a word)."""
    first = min(results)
    for seed, result in results.items():
        differ = [
            name
            for name in BUILD_ATTRS
            if str(result.attrs.get(name)) != str(results[first].attrs.get(name))
        ]
        if differ:
            raise SpecError.at(
                script.path,
                token,
                f"the seed files of one build of {search} ({files[first]} and {files[seed]} "
                f"differ in {', '.join(differ)}: rebuild or remove the stale ones, or name a "
                "seed)",
            )


def open_session(
    script: CompositeScript,
    controller_files: Mapping[str, Sequence[str | Path]],
    figures_dir: str | Path = "specs/figures",
    bsr_specs_dir: str | Path = "specs/bsr",
    looked_in: str = "results/bsr/{search}/seed*.h5",
) -> CompositeSession:
    """Bind the script: ``controller_files`` maps each phase's search to its result files
    (``.../seedK.h5``). A figure, search or seed that is not there raises SpecError at the word
    of the script that names it; ``looked_in`` says where a search's files were looked for
    (``{search}``: its name)."""
    figure = load_bsr_figure(figures_dir, script.path, script.tokens["figure"])
    check_phase_searches(script, bsr_specs_dir)
    controllers, seeds, files, dts, lengths = [], [], [], [], []
    for phase in script.phases:
        token = script.tokens[f"phase.{phase.name}.controller"]
        candidates = {}
        for path in controller_files.get(phase.controller, ()):
            match = SEED_FILE.search(Path(path).name)
            if match:
                candidates[int(match.group(1))] = Path(path)
        if not candidates:
            raise SpecError.at(
                script.path,
                token,
                f"a built BSR search (no {looked_in.format(search=phase.controller)}: "
                "snakemake results/composite/SCRIPT.h5 builds a script's searches first)",
            )
        if phase.seed is not None:
            if phase.seed not in candidates:
                raise SpecError.at(
                    script.path,
                    script.tokens[f"phase.{phase.name}.seed"],
                    f"a built seed of {phase.controller} ({', '.join(map(str, candidates))})",
                )
            seed = phase.seed
            result = read_bsr_result(candidates[seed])
        else:
            results = {k: read_bsr_result(path) for k, path in sorted(candidates.items())}
            _one_build(script, token, phase.controller, results, candidates)
            seed = max(results, key=lambda k: float(results[k].attrs["nominal_fitness"]))
            result = results[seed]
        if str(result.attrs["name"]) != phase.controller:  # a file put in another's folder
            raise SpecError.at(
                script.path,
                token,
                f"results of the search {phase.controller} ({candidates[seed]} is a result of "
                f"{result.attrs['name']})",
            )
        if str(result.attrs["figure"]) != script.figure:
            raise SpecError.at(
                script.path,
                token,
                f"a search of figure '{script.figure}' ({phase.controller} moves "
                f"'{result.attrs['figure']}')",
            )
        controllers.append(result.controller)
        seeds.append(seed)
        files.append(str(candidates[seed]))
        dts.append(float(result.attrs["dt"]))
        lengths.append(int(round(float(result.attrs["duration"]) / dts[-1])))
    if len(set(dts)) > 1:
        raise SpecError.at(
            script.path,
            script.tokens[f"phase.{script.phases[-1].name}.controller"],
            f"searches with one time step (their dt: {', '.join(map(str, dts))} s)",
        )
    # the first phase's search's start pose starts the motion (check_phase_searches: its spec
    # is there)
    spec_path = Path(bsr_specs_dir) / f"{script.phases[0].controller}.bsr"
    setup = bind_search(parse_bsr_spec(spec_path), figure)
    return CompositeSession(
        script=script,
        figure=figure,
        controllers=tuple(controllers),
        seeds=tuple(seeds),
        controller_files=tuple(files),
        start=standing_state(figure, setup.root_angle, setup.joints, setup.x),
        dt=dts[0],
        default_length=sum(lengths),
    )
