"""One composite motion end to end: script and BSR results in, ``results/composite/NAME.h5``
out (the guessed concatenation, Figure 5's search, the refined concatenation)."""

from __future__ import annotations

import json
import time
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from mosys.bsr.result_file import motion_step_bytes
from mosys.composite.session import CompositeSession, ScoredMotion, open_session
from mosys.composite.transitions import TransitionSearch, search_transitions
from mosys.io.attributes import string_list
from mosys.io.composite_result import (
    CompositeMotion,
    CompositeResult,
    encode_scores,
    write_composite_result,
)
from mosys.limits import check_job
from mosys.parsing.composite import parse_composite_script
from mosys.parsing.tokens import location, read_spec_text


def phase_table(session: CompositeSession, ticks: np.ndarray) -> list[dict]:
    """The contract's ``phases`` entry for these durations: per phase its controller, start and
    end s (and ours: name, seed, ticks)."""
    bounds = np.concatenate([[0], np.cumsum(ticks)]) * session.dt
    return [
        {
            "name": phase.name,
            "controller": phase.controller,
            "seed": session.seeds[k],
            "ticks": int(ticks[k]),
            "start": float(bounds[k]),
            "end": float(bounds[k + 1]),
        }
        for k, phase in enumerate(session.script.phases)
    ]


def stored_motion(session: CompositeSession, scored: ScoredMotion) -> CompositeMotion:
    """A scored motion as the result file keeps it: its rod ends (samples, rods, 2, 2) m and
    centre of mass as a figure motion at the session's dt, with each sample's phase and rule."""
    motion = scored.motion
    return CompositeMotion(
        motion=session.figure.motion(motion.rod_ends, motion.com, session.dt),
        phase=motion.phase,
        active_rule=motion.active_rule,
    )


def check_size(session: CompositeSession, durations: Sequence[int] | None = None) -> None:
    """LimitError at the first phase's ``ticks=`` (or the ``figure`` line, without them) where
    the concatenation of ``durations`` (P,) ticks (None: the guess), counted from its start,
    needs more steps or memory than the limits allow, or at the ``figure`` line when the
    search's Q arrays do (``mosys.limits``)."""
    script = session.script
    step_bytes = motion_step_bytes(len(session.figure.endpoint_names))
    if durations is None:
        durations = session.guess
    ticks = 0  # exact, a Python int: each phase's ticks fit int64, their sum need not
    for phase, phase_ticks in zip(script.phases, durations, strict=True):
        ticks += int(phase_ticks)
        token = script.tokens.get(f"phase.{phase.name}.ticks", script.tokens["figure"])
        check_job(
            location(script.path, token),
            f"the phases' {ticks:,} ticks to the end of this one",
            float(ticks),
            float(ticks) * step_bytes,
        )
    arrays, figure = script.search.q, script.tokens["figure"]
    check_job(  # the search's population: Q arrays of switch ticks and their scores, copied
        location(script.path, figure),
        f"a transition search of {arrays:,} arrays",
        memory_bytes=4.0 * 8.0 * arrays * len(script.phases),
    )


def composite_to_file(
    script_path: str | Path,
    controller_files: Mapping[str, Sequence[str | Path]],
    output: str | Path,
    figures_dir: str | Path = "specs/figures",
    bsr_specs_dir: str | Path = "specs/bsr",
    search_sizes: Mapping[str, int] | None = None,
    budget: str = "paper",
    looked_in: str = "results/bsr/{search}/seed*.h5",
) -> TransitionSearch:
    """Parse the script, bind it to its controllers (``controller_files``: search -> its
    seedK.h5 files; ``looked_in``: where, for a message, as ``open_session``), score the guess,
    run Figure 5's search and write both motions atomically. ``search_sizes`` overrides the
    script's q, g, h or seed (a config's budget)."""
    script = parse_composite_script(script_path)
    if search_sizes:
        script = replace(script, search=replace(script.search, **search_sizes))
    session = open_session(script, controller_files, figures_dir, bsr_specs_dir, looked_in)
    check_size(session)
    before = session.score(session.guess)  # also compiles the kernels before the clock starts
    settings = script.search
    began = time.perf_counter()
    found = search_transitions(
        session.total,
        before.ticks,
        len(script.phases),
        q=settings.q,
        g=settings.g,
        h=settings.h,
        seed=settings.seed,
    )
    wall = time.perf_counter() - began
    after = session.score(found.durations)
    result = CompositeResult(
        after=stored_motion(session, after),
        before=stored_motion(session, before),
        best_by_generation=found.best_by_generation,
        attrs={
            "script": script.name,
            "phases": json.dumps(phase_table(session, after.ticks)),
            "phases_before": json.dumps(phase_table(session, before.ticks)),
            "score_before": before.total,
            "score_after": after.total,
            "simulations": found.simulations,
            "spec_sha256": script.spec_sha256,
            "wall_seconds": wall,
            "name": script.name,
            "figure": script.figure,
            "dt": session.dt,
            "ticks_before": before.ticks,
            "ticks_after": after.ticks,
            "scores_before": encode_scores(before.scores),
            "scores_after": encode_scores(after.scores),
            "seeds": np.array(session.seeds, np.int64),
            "controller_files": string_list(session.controller_files),
            "search_q": settings.q,
            "search_g": settings.g,
            "search_h": settings.h,
            "search_seed": settings.seed,
            "budget": budget,
            "script_text": read_spec_text(script_path)[0],
        },
    )
    write_composite_result(output, result)
    return found
