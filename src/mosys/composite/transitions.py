"""The transition-point search of the 1995 paper's Figure 5.

A transition-point array holds the P - 1 switch ticks of a P-phase composite motion inside its
fixed length (the sum of the guessed phase durations). Q arrays start as copies of the user's
guess (or, without one, equally spaced); each of G generations gives every array H mutations in
turn — one randomly chosen transition point redrawn uniformly a third of the time, else perturbed
by a rounded N(0, PERTURB_FRACTION x length) step (at least one tick) — keeping a mutant that
scores better; then the arrays are ranked and the worse half replaced by the better half. Q x G x
H evaluations in all (the paper: 16 x 16 x 4 = 1,024). A score of nan (a script's expression
divided 0 by 0) ranks as -inf (``bsr.search.ranked``, as a search's fitness): never best.
One seeded generator draws every random number in a fixed order, so a seed gives the same
result every time.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from mosys.bsr.search import ranked
from mosys.io.progress import Progress

PERTURB_FRACTION = 0.05
RANDOMIZE = 1.0 / 3.0


@dataclass(frozen=True)
class TransitionSearch:
    """What the search found: the best phase durations (P,) ticks and their score, the score of
    the starting guess, the best score after each generation (G,), and the simulations run."""

    durations: np.ndarray
    score: float
    guess_durations: np.ndarray
    guess_score: float
    best_by_generation: np.ndarray
    simulations: int


def equal_split(length: int, phases: int) -> np.ndarray:
    """``length`` ticks in ``phases`` equal durations (P,), the last taking the remainder."""
    durations = np.full(phases, length // phases, np.int64)
    durations[-1] += length - durations.sum()
    return durations


def durations_of(switches: np.ndarray, length: int) -> np.ndarray:
    """Phase durations (P,) ticks from sorted switch ticks (P - 1,) in a motion of ``length``."""
    return np.diff(np.concatenate([[0], switches, [length]])).astype(np.int64)


def search_transitions(
    evaluate: Callable[[np.ndarray], float],
    guess: Sequence[int] | None,
    phases: int,
    length: int | None = None,
    q: int = 16,
    g: int = 16,
    h: int = 4,
    seed: int = 1,
) -> TransitionSearch:
    """Figure 5. ``evaluate(durations)`` scores phase durations (P,) ticks (higher is better);
    ``guess``: the user's durations (their sum is the motion's length), or None for equally
    spaced switches in ``length`` ticks."""
    if guess is not None:
        start = np.asarray(guess, np.int64)
        length = int(start.sum())
    else:
        if length is None:
            raise ValueError("without a guess, the motion's length in ticks is needed")
        start = equal_split(length, phases)
    if start.shape != (phases,) or np.any(start < 0) or length < 1:
        raise ValueError(f"durations {start.tolist()} do not make {phases} phases")
    rng = np.random.default_rng(seed)
    switches = np.cumsum(start)[:-1]
    population = np.repeat(switches[None, :], q, axis=0)
    guess_score = float(evaluate(start))
    scores = np.full(q, guess_score)  # identical arrays: one evaluation scores them all
    simulations = 1
    best_by_generation = []
    progress = Progress("transition search", g, "generations")
    for generation in range(g):
        for k in range(q):
            for _ in range(h):
                mutant = population[k].copy()
                if mutant.size:
                    i = int(rng.integers(mutant.size))
                    if rng.random() < RANDOMIZE:
                        mutant[i] = rng.integers(0, length + 1)
                    else:
                        step = int(round(rng.normal(0.0, PERTURB_FRACTION * length)))
                        mutant[i] = np.clip(mutant[i] + (step or rng.choice([-1, 1])), 0, length)
                    mutant.sort()
                score = float(evaluate(durations_of(mutant, length)))
                simulations += 1
                if ranked(score) > ranked(scores[k]):
                    population[k], scores[k] = mutant, score
        order = np.argsort(-ranked(scores), kind="stable")
        half = q // 2
        population[order[q - half :]] = population[order[:half]]
        scores[order[q - half :]] = scores[order[:half]]
        best_by_generation.append(float(scores[order[0]]))
        progress.update(generation + 1, f"best score {scores[order[0]]:.4g}")
    progress.finish(f"best score {scores[order[0]]:.4g}")
    best = int(np.argmax(ranked(scores)))
    return TransitionSearch(
        durations=durations_of(population[best], length),
        score=float(scores[best]),
        guess_durations=start,
        guess_score=guess_score,
        best_by_generation=np.array(best_by_generation),
        simulations=simulations,
    )
