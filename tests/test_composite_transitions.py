"""The transition-point search of Figure 5 on scores whose best durations are known."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mosys.composite.transitions import durations_of, search_transitions
from mosys.io.composite_result import decode_scores, encode_scores


def peaked(best: np.ndarray):
    """A score with its single maximum at the durations ``best``."""
    return lambda durations: -float(np.abs(np.asarray(durations) - best).sum())


def test_it_finds_the_best_durations_from_a_careless_guess():
    best = np.array([120, 60, 169])
    found = search_transitions(peaked(best), [159, 90, 100], 3)
    assert found.durations.sum() == 349
    assert np.abs(found.durations - best).max() <= 2  # within two ticks of the best
    assert found.guess_score == -138.0 and found.score >= -4.0
    assert found.simulations == 1 + 16 * 16 * 4
    assert np.all(np.diff(found.best_by_generation) >= 0)


def test_without_a_guess_it_starts_equally_spaced():
    seen = []

    def score(durations):
        seen.append(tuple(durations))
        return 0.0

    search_transitions(score, None, 4, length=100, q=2, g=1, h=1)
    assert seen[0] == (25, 25, 25, 25)


def test_a_seed_gives_the_same_search():
    score = peaked(np.array([30, 30, 40]))
    one = search_transitions(score, [10, 10, 80], 3, q=4, g=3, h=2, seed=5)
    two = search_transitions(score, [10, 10, 80], 3, q=4, g=3, h=2, seed=5)
    np.testing.assert_array_equal(one.best_by_generation, two.best_by_generation)
    np.testing.assert_array_equal(one.durations, two.durations)


def test_durations_of_switches():
    np.testing.assert_array_equal(durations_of(np.array([3, 3, 9]), 10), [3, 0, 6, 1])


def test_a_nan_score_is_never_ranked_best():
    """Issue 27: a script whose score divides 0 by 0 for some durations. The guess scores nan;
    every numeric score beats it, nan never replaces a number, and the best is a number."""
    best = np.array([30, 50, 20])
    score = peaked(best)

    def evaluate(durations: np.ndarray) -> float:
        return math.nan if durations[0] % 3 == 0 else score(durations)  # the guess: 33 % 3 == 0

    found = search_transitions(evaluate, [33, 33, 34], 3, q=8, g=10, h=4, seed=2)
    assert math.isnan(found.guess_score)
    assert math.isfinite(found.score)
    assert np.isfinite(found.best_by_generation).all()
    assert found.durations[0] % 3 != 0


def test_non_finite_scores_are_strict_json_and_read_back():
    scores = {"a": 1.5, "b": math.nan, "c": math.inf, "d": -math.inf}
    text = encode_scores(scores)
    assert text == '{"a": 1.5, "b": "nan", "c": "inf", "d": "-inf"}'
    json.loads(text, parse_constant=lambda name: pytest.fail(f"non-strict JSON {name}"))
    back = decode_scores(text)
    assert back["a"] == 1.5 and math.isnan(back["b"]) and back["c"] == math.inf
    assert back["d"] == -math.inf
