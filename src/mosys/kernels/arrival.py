"""Whether a vehicle braking from its state comes to rest in its arrival box: where both the
lookahead runtime (``kernels.lookahead``) and the DP's exit transitions (``kernels.dp_exits``) end a
segment at the destination."""

from __future__ import annotations

import math

from numba import njit

from mosys.kernels.regions import inside_region


@njit(cache=True)
def braking_stop(state, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, stop):
    """Into stop (d,): the controller state where full braking from model state ``state`` ends.
    Braking, steering held, the front wheels roll s = v|v| / 2a: the heading turns by
    s sin(steer) / wheelbase and the reference point moves s along the mean of the start and end
    heading, plus steer; the speed ends at 0."""
    speed = state[vehicle_slot[4]]
    steer = state[vehicle_slot[3]]
    distance = speed * abs(speed) / (2.0 * wheel_radius * brake)
    turn = distance * math.sin(steer) / wheelbase
    direction = state[vehicle_slot[2]] + 0.5 * turn + steer
    for k in range(state_slot.shape[0]):
        slot = state_slot[k]
        stop[k] = state[slot]
        if slot == vehicle_slot[0]:
            stop[k] += distance * math.cos(direction)
        elif slot == vehicle_slot[1]:
            stop[k] += distance * math.sin(direction)
        elif slot == vehicle_slot[2]:
            stop[k] += turn
        elif slot == vehicle_slot[4]:
            stop[k] = 0.0


@njit(cache=True)
def braking_seconds(state, vehicle_slot, wheel_radius, brake):
    """The seconds a vehicle takes to brake to rest from model state ``state`` (wheel_radius m,
    brake rad/s², as ``braking_stop``)."""
    return abs(state[vehicle_slot[4]]) / (wheel_radius * brake)


@njit(cache=True)
def stops_in_box(state, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, box, stop):
    """True when the state where full braking from ``state`` ends (``braking_stop``) lies in the
    arrival box (``box`` (3, d): lower, upper and period over the controller's axes, as
    ``inside_region`` takes them). stop: (d,) work array, the controller state where it stops."""
    braking_stop(state, vehicle_slot, wheelbase, wheel_radius, brake, state_slot, stop)
    return inside_region(stop, box[0], box[1], box[2])
