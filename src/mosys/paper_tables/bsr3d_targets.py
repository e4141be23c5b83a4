"""The 3-D motions against the targets set for them (issue 22, after the 1995 paper's §4),
measured on the result files: Cujo bounds at least three body lengths without falling; Rex walks,
turns so that his second walk heads at least 45° away from his first, and walks on, without
falling (each walk at least WALK_ON on the floor: a shorter one has no direction to compare);
Bob walks at least four steps (alternating foot touch-downs), facing forward, without
falling, in at least one seed, and the time-based Bob does worse than the sense-based one (the
paper's finding, reported either way: here, it walks in fewer of its seeds and has the lower
median fitness; the best fitness of each is shown too); no endpoint sinks more than 1 cm into
the floor and no lone contact slides, in any motion.

Definitions: a *body length* is the length of the figure's heading rod (Cujo's spine); *fallen*:
the centre of mass below half its standing height at some sample; *facing forward*: the heading
never more than 45° from the start's on average (``heading_deviation``) nor at the end
(``heading_change``); a walk's *direction*: its centre of mass's displacement on the floor. The
motions are the best seed's best motion of each search (for Rex, the chain of seeds the last
search continues).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from mosys.bsr.lone_contact import lone_contacts, sliding
from mosys.errors import InputError
from mosys.io.bsr_result import BsrResult
from mosys.paper_tables.bsr import group_by_search, write_table
from mosys.paper_tables.bsr3d import best_seed, budget_sentence, read_3d_result

BODY_LENGTHS = 3.0
TURN = 45.0  # deg
STEPS = 4
FACING = 45.0  # deg
FALLEN = 0.5  # of the standing com height
SINK = 0.01  # m
WALK_ON = 0.5  # m: the second walk covers at least this much


def fell(result: BsrResult) -> bool:
    """Whether the centre of mass went below FALLEN times its standing height."""
    return float(result.attrs["min_com_height"]) < FALLEN * float(
        result.attrs["standing_com_height"]
    )


def walks(result: BsrResult) -> bool:
    """Whether a biped's best motion is a walk: at least STEPS alternating steps, forward, facing
    forward (within FACING at the end and on average), never fallen."""
    terms = result.fitness_terms
    return (
        terms["foot_steps"] >= STEPS
        and terms["distance"] > 0.0
        and abs(terms["heading_change"]) <= FACING
        and terms["heading_deviation"] <= FACING
        and not fell(result)
    )


def physics_ok(result: BsrResult) -> tuple[float, int]:
    """The deepest any endpoint went into the floor (m, >= 0) and the number of lone contacts
    that slid, in the result's best motion."""
    motion = result.motion
    depth = max(0.0, -float(motion.endpoints[..., 1].min()))
    return depth, len(sliding(lone_contacts(motion.t, motion.endpoints)))


def direction(result: BsrResult) -> np.ndarray:
    """The (x, z) displacement of the centre of mass over the best motion, m."""
    com = result.motion.com
    return com[-1, [0, 2]] - com[0, [0, 2]]


def _row(search: str, target: str, measured: str, met: bool, budget: str) -> dict:
    return {
        "search": search,
        "target": target,
        "measured": measured,
        "met": "yes" if met else "no",
        "budget": budget,
    }


def _searches(result_paths: Sequence[str | Path]) -> dict[str, list[BsrResult]]:
    if not result_paths:
        raise InputError("no 3-D BSR result files given")
    return group_by_search(map(read_3d_result, result_paths))


def _need(searches: dict, name: str) -> list[BsrResult]:
    if name not in searches:
        raise InputError(f"no result files of search {name!r} among the files given")
    return searches[name]


def _continued(results: list[BsrResult], follower: BsrResult) -> BsrResult:
    """The seed of a search (results) that ``follower`` continues; InputError if it continues
    another search or a seed not given."""
    name = str(results[0].attrs["name"])
    chain = str(follower.attrs["chain"])
    seed = int(follower.attrs["chain_seed"])
    if chain != name:
        raise InputError(
            f"search {follower.attrs['name']!r} continues {chain!r}, not {name!r}: "
            "check the chain's order"
        )
    for result in results:
        if int(result.attrs["seed"]) == seed:
            return result
    raise InputError(f"no result file of seed {seed} of search {name!r}, which the chain needs")


def targets_frame(
    result_paths: Sequence[str | Path],
    bound: str,
    chain: Sequence[str],
    walk: str,
    time_walk: str,
) -> pd.DataFrame:
    """One row per target: ``bound`` the bounding search, ``chain`` Rex's walk, turn and walk
    again, ``walk`` the sense-based biped walk, ``time_walk`` its time-based twin."""
    searches = _searches(result_paths)
    rows = []
    # Cujo
    best = best_seed(_need(searches, bound))
    motion = best.motion
    heading_rod = list(motion.rod_names).index(motion.heading_rod)
    lengths = float(best.fitness_terms["distance"]) / float(motion.rod_length[heading_rod])
    rows.append(
        _row(
            bound,
            f">= {BODY_LENGTHS:g} body lengths forward without falling",
            f"{lengths:.2f} body lengths (seed {int(best.attrs['seed'])})"
            + (", fell" if fell(best) else ""),
            lengths >= BODY_LENGTHS and not fell(best),
            str(best.attrs["budget"]),
        )
    )
    # Rex: the chain of seeds the last search's best seed continues
    walk_name, turn_name, again_name = chain
    again = best_seed(_need(searches, again_name))
    turn = _continued(_need(searches, turn_name), again)
    first = _continued(_need(searches, walk_name), turn)
    one, two = direction(first), direction(again)
    lengths = np.linalg.norm(one), np.linalg.norm(two)  # m on the floor
    fallen = any(fell(result) for result in (first, turn, again))
    if min(lengths) >= WALK_ON:
        angle = math.degrees(math.acos(np.clip(one @ two / (lengths[0] * lengths[1]), -1.0, 1.0)))
        apart = f"{angle:.0f} deg apart"
    else:  # a few centimetres of shuffling have no direction to compare
        angle, apart = math.nan, f"no direction to compare (a walk under {WALK_ON:g} m)"
    rows.append(
        _row(
            f"{walk_name} -> {turn_name} -> {again_name}",
            f"both walks >= {WALK_ON:g} m on the floor, the second >= {TURN:g} deg from the "
            "first, never fallen",
            f"{apart}; walks {lengths[0]:.2f} m and {lengths[1]:.2f} m (seeds "
            f"{int(first.attrs['seed'])}, {int(turn.attrs['seed'])}, {int(again.attrs['seed'])})"
            + (", fell" if fallen else ""),
            angle >= TURN and not fallen,  # NaN when a walk is too short: not met
            str(again.attrs["budget"]),
        )
    )
    # Bob
    walkers = _need(searches, walk)
    good = [result for result in walkers if walks(result)]
    steps = ", ".join(
        f"seed {int(r.attrs['seed'])}: {int(r.fitness_terms['foot_steps'])}" for r in walkers
    )
    rows.append(
        _row(
            walk,
            f">= {STEPS} alternating steps forward, facing forward, not fallen, in a seed",
            f"{len(good)} of {len(walkers)} seeds ({steps} steps)",
            bool(good),
            str(walkers[0].attrs["budget"]),
        )
    )
    timed = _need(searches, time_walk)
    shares = [sum(map(walks, results)) / len(results) for results in (timed, walkers)]
    medians = [
        float(np.median([r.attrs["best_fitness"] for r in results])) for results in (timed, walkers)
    ]
    bests = [max(float(r.attrs["best_fitness"]) for r in results) for results in (timed, walkers)]
    rows.append(
        _row(
            f"{time_walk} vs {walk}",
            "time-based does worse than sense-based (the paper's finding): walks in fewer of its "
            "seeds and has the lower median fitness",
            f"seeds that walk {sum(map(walks, timed))} of {len(timed)} (time) vs "
            f"{len(good)} of {len(walkers)} (sense); median fitness {medians[0]:.2f} vs "
            f"{medians[1]:.2f}; best fitness {bests[0]:.2f} vs {bests[1]:.2f}",
            shares[0] < shares[1] and medians[0] < medians[1],
            str(walkers[0].attrs["budget"]),
        )
    )
    # physics, every motion
    depth, slid, motions, budgets = 0.0, 0, 0, {}
    for results in searches.values():
        for result in results:
            deepest, count = physics_ok(result)
            depth, slid, motions = max(depth, deepest), slid + count, motions + 1
            budgets.setdefault(str(result.attrs["budget"]), None)
    rows.append(
        _row(
            "every motion",
            f"no endpoint > {SINK * 100:g} cm into the floor; no lone contact slides",
            f"deepest {depth * 1000:.2f} mm; {slid} sliding lone contacts in {motions} motions",
            depth <= SINK and slid == 0,
            ", ".join(budgets),  # the budgets of the motions measured (it was left blank)
        )
    )
    return pd.DataFrame(rows)


def write_bsr3d_targets(
    result_paths: Sequence[str | Path],
    csv_path: str,
    md_path: str,
    bound: str,
    chain: Sequence[str],
    walk: str,
    time_walk: str,
) -> pd.DataFrame:
    """Write the targets table as CSV and Markdown (each atomically); returns the frame."""
    frame = targets_frame(result_paths, bound, chain, walk, time_walk)
    caption = (
        "The 3-D motions against their targets (issue 22, after Auslander et al. 1995, §4), "
        "measured on the best seed's best motion of each search. A body length is the heading "
        "rod's length (Cujo's spine); fallen: the centre of mass below half its standing "
        "height; a walk's direction: its centre of mass's displacement on the floor (a walk "
        f"under {WALK_ON:g} m has none to compare); facing forward: the heading within "
        f"{FACING:g} deg of the start's on average and at the end. "
        f"{budget_sentence(frame)} Targets are set for "
        "the paper's budgets; a reduced budget (ci) runs the same measures.\n\n"
    )
    write_table(frame, caption, csv_path, md_path)
    return frame
