"""Boxes of a controller's state space (the 1990 paper's regions and a car's arrival box), and
whether a state lies in them."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def inside_region(state, lower, upper, period):
    """True when every entry of ``state`` (S,) lies in [lower, upper] ((S,) each). An entry with
    a period (> 0: an angle, 2π) and finite bounds is compared modulo its period."""
    for i in range(state.shape[0]):
        value = state[i]
        if period[i] > 0.0 and math.isfinite(lower[i]) and math.isfinite(upper[i]):
            value = lower[i] + (value - lower[i]) % period[i]
        if not lower[i] <= value <= upper[i]:
            return False
    return True


@njit(cache=True)
def region_membership(state, region_lower, region_upper, period, out):
    """out (K,) bool: whether ``state`` (S,) lies in each of the K boxes (K, S)."""
    for k in range(region_lower.shape[0]):
        out[k] = inside_region(state, region_lower[k], region_upper[k], period)


@njit(cache=True)
def crossed_a_region_border(state, region_lower, region_upper, period, start_membership, work):
    """True when ``state`` (S,) lies in a different set of the K boxes than
    ``start_membership`` (K,) bool, the run's first state's; work: (K,) bool."""
    region_membership(state, region_lower, region_upper, period, work)
    crossed = False
    for k in range(region_lower.shape[0]):
        crossed |= work[k] != start_membership[k]
    return crossed
