"""A population of 3-D BSR controllers evaluated at once: ``run_population`` runs them in parallel,
four at a time in lockstep (``run_lockstep``: the body frames of the four computed in vector
lanes, ``bsr3d_lanes.body_frame_lanes``, the rest of each step lane by lane), the population's
remainder one by one (``bsr3d_controller.run_controller``). Every controller's numbers are those
of its own ``run_controller``, bit for bit, whichever way it ran (tested), so a search's results
do not depend on the population's size or the number of threads, and the best controller's
motion, replayed on its own, is the one the search scored.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from mosys.kernels.borrowed import borrowed, keep_alive
from mosys.kernels.bsr3d_controller import (
    lane_tally,
    measure_senses,
    new_tallies,
    rule_weights,
    run_controller,
    sense_step,
    start_tally,
    tally_step,
    tally_terms,
)
from mosys.kernels.bsr3d_lanes import body_frame_lanes
from mosys.kernels.bsr3d_simulate import (
    JOINTS,
    conjugate,
    joint_trig,
    lane_work,
    new_step_works,
    start_step_work,
    step_deform,
    step_motion,
)
from mosys.kernels.bsr_controller import (
    ControllerArrays,
    RunRecord,
    active_rule,
    segment_rule,
    stop_unsound,
)
from mosys.kernels.lanes import LANES
from mosys.kernels.soundness import state_is_sound


@njit(cache=True, error_model="numpy")
def run_lockstep(
    figure,
    controllers,
    task,
    members,
    starts,
    steps,
    dt,
    senses_out,
    rule_out,
    terms_out,
    taken_out,
    final_out,
):
    """``run_controller`` for the four controllers ``members`` (LANES,) int64 of a population
    (arrays as ``run_population`` takes them) at once, from rule 0, recording no motion: the
    same numbers as four runs of it, bit for bit. Each step deforms every lane's figure, computes
    the four body frames in vector lanes, then moves and measures each lane; a lane whose state
    is not sound stops there (as ``run_controller`` does) and the others go on."""
    figure = borrowed(figure)
    task = borrowed(task)
    controllers = borrowed(controllers)
    parent, hinge, rest, length, mass, com, inertia, joint, endpoints = figure[:9]
    floor = figure.floor
    n_rods = parent.shape[0]
    n_ends = endpoints.shape[0]
    n_joints = figure.joint_min.shape[0]
    n_senses = senses_out.shape[2]
    sensing = n_senses > 0
    time_based = controllers.time_based
    # the body frames' inputs and outputs, lanes last (``body_frame_lanes``): each lane's work
    # reads and writes its rods' and endpoints' frames, ends and velocities there
    own_trig = np.ones((4, n_rods, LANES))
    own_rates = np.zeros((n_joints, LANES))
    own_rod_ends = np.empty((n_rods, 2, 3, LANES))
    own_end_offset = np.empty((n_ends, 3, LANES))
    own_end_velocity = np.empty((n_ends, 3, LANES))
    own_frames = np.empty((n_rods, 3, 3, LANES))
    own_rod_work = np.empty((5, n_rods, 3, LANES))
    own_tensor = np.empty((3, 3, LANES))
    own_spin = np.empty((3, LANES))
    own_states = np.empty((LANES, starts.shape[1]))
    own_works = new_step_works(LANES, n_rods, n_ends)
    own_tallies = new_tallies(LANES, n_ends, task.feet.shape[0])
    own_weights = np.empty((LANES, controllers.side.shape[1]))
    own_raw = np.empty((LANES, n_senses))
    own_filtered = np.empty((LANES, n_senses))
    own_moving = np.zeros(n_rods, np.bool_)  # rods with an angle that is not fixed
    trig = borrowed(own_trig)
    rates = borrowed(own_rates)
    rod_ends = borrowed(own_rod_ends)
    end_offset = borrowed(own_end_offset)
    end_velocity = borrowed(own_end_velocity)
    frames = borrowed(own_frames)
    rod_work = borrowed(own_rod_work)
    tensor = borrowed(own_tensor)
    spin = borrowed(own_spin)
    states = borrowed(own_states)
    works = borrowed(own_works)
    tallies = borrowed(own_tallies)
    weights = borrowed(own_weights)
    raw = borrowed(own_raw)
    filtered = borrowed(own_filtered)
    moving = borrowed(own_moving)
    for k in range(n_rods):
        j = joint[k]
        if j >= 0:
            for a in range(j, j + 2):
                moving[k] |= figure.joint_min[a] != figure.joint_max[a]
    weight = mass.sum() * figure.gravity
    smoothing = 1.0 - math.exp(-dt / task.filter_time) if task.filter_time > 0.0 else 1.0
    rules = np.zeros(LANES, np.int64)
    live = np.ones(LANES, np.bool_)
    no_force = np.zeros(n_ends)
    for lane in range(LANES):
        c = members[lane]
        state = states[lane]
        work = lane_work(
            works,
            lane,
            rod_ends[:, :, :, lane],
            end_offset[:, :, lane],
            end_velocity[:, :, lane],
            frames[:, :, :, lane],
        )
        state[:] = starts[c]
        weights[lane] = rule_weights(controllers.side[c])
        start_step_work(figure, state, work)
        start_tally(state, work, floor, task, lane_tally(tallies, lane))
        if sensing:
            matrices = work.matrices
            conjugate(matrices[0], matrices[2], matrices[3])
            measure_senses(
                state,
                matrices[0],
                matrices[3],
                work.vectors[0, :3],
                work.end_force,
                weight,
                floor,
                task,
                figure.joint_min,
                figure.joint_max,
                filtered[lane],
            )
            senses_out[c, 0] = filtered[lane]
        rule_out[c, 0] = 0
    for n in range(steps):
        running = 0
        for lane in range(LANES):
            if not live[lane]:
                continue
            c = members[lane]
            state = states[lane]
            work = lane_work(
                works,
                lane,
                rod_ends[:, :, :, lane],
                end_offset[:, :, lane],
                end_velocity[:, :, lane],
                frames[:, :, :, lane],
            )
            if not state_is_sound(state):
                taken_out[c] = stop_unsound(
                    n, state, work.end_force, terms_out[c], final_out[c], no_force
                )
                live[lane] = False
                continue
            running += 1
            rule = rules[lane]
            target = controllers.target[c, rule]
            step_deform(figure, state, target, controllers.tau[c, rule], dt, work)
            joint_trig(parent, joint, state[JOINTS : JOINTS + n_joints], work.scratch)
            for k in range(n_rods):
                if n == 0 or moving[k]:
                    for t in range(4):
                        trig[t, k, lane] = work.scratch[k, 5 + t // 2, 1 + t % 2]
            for j in range(n_joints):
                rates[j, lane] = state[JOINTS + n_joints + j]
        if running == 0:
            break
        total_mass = body_frame_lanes(
            parent,
            hinge,
            rest,
            length,
            mass,
            com,
            inertia,
            joint,
            endpoints,
            trig[0],
            trig[1],
            trig[2],
            trig[3],
            rates,
            rod_ends,
            end_offset,
            end_velocity,
            frames,
            rod_work[0],
            rod_work[1],
            rod_work[2],
            rod_work[3],
            rod_work[4],
            tensor,
            spin,
        )
        for lane in range(LANES):
            if not live[lane]:
                continue
            c = members[lane]
            state = states[lane]
            work = lane_work(
                works,
                lane,
                rod_ends[:, :, :, lane],
                end_offset[:, :, lane],
                end_velocity[:, :, lane],
                frames[:, :, :, lane],
            )
            for a in range(3):
                for b in range(3):
                    work.matrices[1, a, b] = tensor[a, b, lane]
                work.vectors[0, a] = spin[a, lane]
            step_motion(figure, state, dt, work, total_mass, False)
            tally_step(state, work, floor, task, lane_tally(tallies, lane))
            if sensing:
                sense_step(state, work, weight, task, figure, smoothing, raw[lane], filtered[lane])
                senses_out[c, n + 1] = filtered[lane]
            if time_based:
                rule = segment_rule((n + 1) * dt, controllers.segment_end[c], controllers.period)
            else:
                rule = active_rule(
                    senses_out[c, n + 1],
                    controllers.center[c],
                    controllers.side[c],
                    weights[lane],
                    rules[lane],
                )
            rules[lane] = rule
            rule_out[c, n + 1] = rule
    for lane in range(LANES):
        if not live[lane]:
            continue
        c = members[lane]
        state = states[lane]
        work = lane_work(
            works,
            lane,
            rod_ends[:, :, :, lane],
            end_offset[:, :, lane],
            end_velocity[:, :, lane],
            frames[:, :, :, lane],
        )
        if not state_is_sound(state):
            taken_out[c] = stop_unsound(
                steps, state, work.end_force, terms_out[c], final_out[c], no_force
            )
            continue
        tally_terms(state, work, task, lane_tally(tallies, lane), steps, terms_out[c])
        final_out[c] = state
        taken_out[c] = steps
    # the owned arrays' last uses: their borrowed views' memory is kept to here
    keep_alive((own_trig, own_rates, own_rod_ends, own_end_offset, own_end_velocity, own_frames))
    keep_alive((own_rod_work, own_tensor, own_spin, own_states, own_weights, own_raw))
    keep_alive((own_filtered, own_moving))
    keep_alive(own_works)
    keep_alive(own_tallies)


@njit(cache=True, parallel=True)
def run_population(
    figure,
    controllers,
    task,
    starts,
    steps,
    dt,
    senses_out,
    rule_out,
    terms_out,
    taken_out,
    final_out,
):
    """``run_controller`` for C controllers at once, in parallel: controllers a ControllerArrays
    whose arrays have a leading axis C, starts (C, S); fills senses_out (C, steps + 1, V),
    rule_out (C, steps + 1), terms_out (C, TERM_COUNT), taken_out (C,) int64 what each run
    returned (steps, or ``blown_up(n)`` < 0: its terms are NaN) and final_out (C, S) each run's
    last state (the unsound one where it stopped). Four at a time in lockstep
    (``run_lockstep``), the remaining C mod 4 one by one; each run's numbers are its own
    ``run_controller``'s, so the results do not depend on C's grouping or the threads."""
    n_rods = figure.parent.shape[0]
    n_ends = figure.endpoints.shape[0]
    population = starts.shape[0]
    groups = population // LANES
    for item in prange(groups + population % LANES):
        if item < groups:
            members = np.arange(item * LANES, (item + 1) * LANES)
            run_lockstep(
                figure,
                controllers,
                task,
                members,
                starts,
                steps,
                dt,
                senses_out,
                rule_out,
                terms_out,
                taken_out,
                final_out,
            )
            continue
        c = groups * LANES + item - groups
        controller = ControllerArrays(
            controllers.time_based,
            controllers.target[c],
            controllers.tau[c],
            controllers.center[c],
            controllers.side[c],
            controllers.segment_end[c],
            controllers.period,
        )
        record = RunRecord(
            senses_out[c],
            rule_out[c],
            terms_out[c],
            np.empty((0, n_rods, 2, 3)),
            np.empty((0, 3)),
            final_out[c],
            np.empty(n_ends),
        )
        taken_out[c] = run_controller(
            figure,
            controller,
            task,
            starts[c],
            np.zeros(n_ends),
            np.bool_(False),  # a bool, not the literal False: the run_controller a call
            steps,  # from Python compiles (a literal is a signature of its own)
            dt,
            record,
        )
