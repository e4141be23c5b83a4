"""Ground contact of the 3-D simulator (``kernels.bsr3d_simulate``), the 1995 paper's friction
carried to 3-D: the impulses at up to ``MAX_CONTACTS`` rod endpoints that would end a step on
the floor (``contact_impulses``).

Several contacts take horizontal impulses in the ratio of their normal impulses, sized so that
their normal-impulse-weighted horizontal velocity and twist about the vertical vanish: a fixed
point over the shares (``_shared_friction``), each iteration a symmetric positive definite solve
whose normal block is inverted once (``_normal_block``); Anderson mixing of the shares
(``_mix_shares``), except for two contacts with no z in their offsets from the centre of mass or
their velocities, which iterate plainly as the 2-D rule does. Contacts whose normal impulse would
pull are dropped one at a time, then each is tried alone, stopped dead (``stop_dead``); where no
set of the friction rule pushes, the normal impulses alone (``frictionless_impulses``). A
compliance of COMPLIANCE of a contact's own response splits the loads a rigid body leaves
undecided (three or more contacts on a plane).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mosys.kernels.rotation3d import apply, cross

MAX_CONTACTS = 4  # the lowest endpoints solved together (a body needs three on a plane)
COMPLIANCE = 1e-6  # of a contact's own response: splits loads the rigid body leaves undecided
FIXED_POINT_ITERATIONS = 50  # of the shared-friction shares
# a twist whose horizontal impulse at some contact exceeds its normal impulse this many times is
# not used (the shares of a contact that barely touches cannot stop a spin): slide only then
TWIST_RATIO = 1.0


@njit(cache=True, inline="always", error_model="numpy")
def spin_per_impulse(r, j, world_inverse, spins):
    """spins[j] (3, 3): column b the body's change of spin (rad/s, world) per unit impulse along
    axis b at a point with offset r[j] (3,) from the centre of mass, for a rigid body of inverse
    inertia world_inverse (3, 3): I⁻¹ [r_j]x (the part of ``response`` that does not depend on
    the point that moves, made once for every point it is paired with)."""
    for b in range(3):
        ex = 1.0 if b == 0 else 0.0
        ey = 1.0 if b == 1 else 0.0
        ez = 1.0 if b == 2 else 0.0
        tx, ty, tz = cross(r[j, 0], r[j, 1], r[j, 2], ex, ey, ez)
        spins[j, 0, b], spins[j, 1, b], spins[j, 2, b] = apply(world_inverse, tx, ty, tz)


@njit(cache=True, inline="always", error_model="numpy")
def response(r, i, j, inverse_mass, spins, responses):
    """responses[i, j] (3, 3): the velocity change at a point with offset r[i] (3,) from the
    centre of mass per unit impulse at a point with offset r[j], for a rigid body of inverse
    mass inverse_mass whose spin per impulse at r[j] is spins[j] (``spin_per_impulse``):
    E/M - [r_i]x I⁻¹ [r_j]x."""
    for b in range(3):
        ex = 1.0 if b == 0 else 0.0
        ey = 1.0 if b == 1 else 0.0
        ez = 1.0 if b == 2 else 0.0
        sx, sy, sz = spins[j, 0, b], spins[j, 1, b], spins[j, 2, b]
        vx, vy, vz = cross(sx, sy, sz, r[i, 0], r[i, 1], r[i, 2])
        responses[i, j, 0, b] = vx + inverse_mass * ex
        responses[i, j, 1, b] = vy + inverse_mass * ey
        responses[i, j, 2, b] = vz + inverse_mass * ez


@njit(cache=True, inline="always", error_model="numpy")
def _mix_shares(weight, active, count, mixing, stored):
    """Anderson mixing of the shared-friction shares: weight (count,) holds the plain update g
    of the active points' shares; mixing[0, :stored] and mixing[1, :stored] the last changes of
    g and of its residual f = g - w, mixing[:2, MAX_CONTACTS - 1] the last g and f. The shares
    become g - ΔG γ with γ the least-squares fit of f by ΔF (for a nearly affine map in n - 1
    free shares, as this one is, that converges in about n iterations where the plain update
    shrinks the residual only 5 to 10 times an iteration). Kept plain when the fit is
    degenerate or a share would not stay positive. mixing[2]: work space."""
    if stored == 0:
        return
    last = MAX_CONTACTS - 1
    for a in range(stored):
        for b in range(a + 1):
            total = 0.0
            for i in range(count):
                if active[i]:
                    total += mixing[1, a, i] * mixing[1, b, i]
            mixing[2, a, b] = total
        total = 0.0
        for i in range(count):
            if active[i]:
                total += mixing[1, a, i] * mixing[1, last, i]
        mixing[2, a, last] = total
    largest = 0.0
    for a in range(stored):
        largest = max(largest, mixing[2, a, a])
    # Cholesky of the normal equations in place, then γ in mixing[2, :stored, last]
    for a in range(stored):
        for b in range(a):
            total = mixing[2, a, b]
            for c in range(b):
                total -= mixing[2, a, c] * mixing[2, b, c]
            mixing[2, a, b] = total / mixing[2, b, b]
        total = mixing[2, a, a]
        for c in range(a):
            total -= mixing[2, a, c] * mixing[2, a, c]
        if not total > 1e-12 * largest:
            return
        mixing[2, a, a] = math.sqrt(total)
        total = mixing[2, a, last]
        for c in range(a):
            total -= mixing[2, a, c] * mixing[2, c, last]
        mixing[2, a, last] = total / mixing[2, a, a]
    for a in range(stored - 1, -1, -1):
        total = mixing[2, a, last]
        for c in range(a + 1, stored):
            total -= mixing[2, c, a] * mixing[2, c, last]
        mixing[2, a, last] = total / mixing[2, a, a]
    for i in range(count):
        if active[i]:
            mixed = weight[i]
            for a in range(stored):
                mixed -= mixing[0, a, i] * mixing[2, a, last]
            if not mixed > 0.0:
                return
    total = 0.0
    for i in range(count):
        if active[i]:
            for a in range(stored):
                weight[i] -= mixing[0, a, i] * mixing[2, a, last]
            total += weight[i]
    for i in range(count):
        weight[i] /= total


@njit(cache=True, inline="always", error_model="numpy")
def cholesky_in_place(system, n, scale):
    """The Cholesky factor L of the symmetric positive definite system[:n, :n] (its lower
    triangle read), into that lower triangle; False where a pivot is at most 1e-12 of ``scale``
    (the largest entry): singular, the factor unfinished."""
    for k in range(n):
        for c in range(k):
            total = system[k, c]
            for p in range(c):
                total -= system[k, p] * system[c, p]
            system[k, c] = total / system[c, c]
        total = system[k, k]
        for p in range(k):
            total -= system[k, p] * system[k, p]
        if not total > 1e-12 * scale:
            return False
        system[k, k] = math.sqrt(total)
    return True


@njit(cache=True, inline="always", error_model="numpy")
def normal_responses(active, count, responses, compliance, system):
    """A: the active contacts' (``active`` (count,), nonzero for one) normal (y) velocity
    responses to one another's normal impulses (from ``responses`` (M, M, 3, 3)), with
    ``compliance`` (s/kg) added to its diagonal, into system[:n, :n] in the contacts' order;
    returns its largest entry (the scale its pivots are judged by)."""
    scale = 0.0
    row = 0
    for i in range(count):
        if not active[i]:
            continue
        column = 0
        for j in range(count):
            if active[j]:
                value = responses[i, j, 1, 1] + (compliance if i == j else 0.0)
                system[row, column] = value
                scale = max(scale, abs(value))
                column += 1
        row += 1
    return scale


@njit(cache=True, error_model="numpy")
def _normal_block(u, r, active, count, responses, system, compliance, pairs):
    """The set-up of ``_shared_friction`` at the active contacts: A⁻¹ into system[:n, :n], N0 =
    A⁻¹ (-u_y) into system[:n, M + 3] and the pairs' terms into ``pairs`` (M = MAX_CONTACTS;
    the layout and the names are ``_shared_friction``'s; ``compliance`` added to A's diagonal).
    Returns the largest entry of A, the scale its pivots are judged by, or -1.0 where A is
    singular."""
    n = 0
    for i in range(count):
        if active[i]:
            n += 1
    rhs = MAX_CONTACTS + 3  # the right-hand sides' and solutions' column
    for i in range(count):
        if not active[i]:
            continue
        for j in range(count):
            if active[j]:
                # B's and D's terms of the pair: the normal (y) response at i and the slide
                # (x, z) and twist response at i (the twist's velocity r_z v_x - r_x v_z) to a
                # slide x, a slide z and a twist at j (a twist's impulse (r_z, 0, -r_x))
                k = responses[i, j]
                twist_x = r[j, 2] * k[0, 0] - r[j, 0] * k[0, 2]
                twist_z = r[j, 2] * k[2, 0] - r[j, 0] * k[2, 2]
                pairs[i, j, 0] = k[1, 0]
                pairs[i, j, 1] = k[1, 2]
                pairs[i, j, 2] = r[j, 2] * k[1, 0] - r[j, 0] * k[1, 2]
                pairs[i, j, 3] = k[0, 0]
                pairs[i, j, 4] = k[2, 0]
                pairs[i, j, 5] = k[2, 2]
                pairs[i, j, 6] = r[i, 2] * k[0, 0] - r[i, 0] * k[2, 0]
                pairs[i, j, 7] = r[i, 2] * k[0, 2] - r[i, 0] * k[2, 2]
                pairs[i, j, 8] = r[i, 2] * twist_x - r[i, 0] * twist_z
    # A; then L in place of A, then A⁻¹ (both triangles) in place of L, and N0 = A⁻¹ (-u_y)
    scale_a = normal_responses(active, count, responses, compliance, system)
    if not cholesky_in_place(system, n, scale_a):
        return -1.0
    for k in range(n):  # L⁻¹, row by row (a row's entries of L are used left to right)
        diagonal = 1.0 / system[k, k]
        for c in range(k):
            total = 0.0
            for p in range(c, k):
                total -= system[k, p] * system[p, c]
            system[k, c] = total * diagonal
        system[k, k] = diagonal
    for i in range(n):  # A⁻¹ = L⁻ᵀ L⁻¹, rows in order (row i of L⁻¹ is not used after it)
        for j in range(i + 1):
            total = 0.0
            for p in range(i, n):
                total += system[p, i] * system[p, j]
            system[i, j] = total
            system[j, i] = total
    row = 0
    for i in range(count):
        if active[i]:
            total = 0.0
            column = 0
            for j in range(count):
                if active[j]:
                    total -= system[row, column] * u[j, 1]
                    column += 1
            system[row, rhs] = total
            row += 1
    return scale_a


@njit(cache=True, error_model="numpy")
def _shared_friction(
    u, r, active, count, impulse, system, mixing, weight, share, twisting, pairs, scale_a
):
    """Impulses at the active contacts (at least two), the paper's friction carried to 3-D: no
    active point sinks; each point's horizontal impulse is its share (its normal impulse over
    their sum) of a common one, a slide (T_x, T_z) plus a twist Γ about the vertical (at offset
    r from the centre of mass: (T_x + Γ r_z, T_z - Γ r_x)); and the normal-weighted horizontal
    velocity and twist (r_z u_x - r_x u_z) of the points vanish after it, so that together they
    neither slide nor spin on the floor (in a vertical plane the twist is 0 and this is the 2-D
    rule). A fixed point over the shares, iterated to 1e-12. The compliance (s/kg, 0: none)
    that ``_normal_block`` adds to each contact's own normal response splits the load of
    contacts that a rigid body leaves undecided (more than three on a plane, several in a
    line). ``twisting``: False leaves the twist out (Γ = 0: slide only, the 2-D rule as it
    is). u, r (count, 3). Returns
    the index of the contact whose normal impulse pulls most (-1: none pulls; -2: the system is
    singular; -3: the shares of a twisting solve did not settle; slide only keeps its last
    iterate, as the 2-D rule does). ``share`` (count,): the shares the points had the step
    before (0: not in contact then), where the iteration starts if every active point had one,
    the shares then mixed (``_mix_shares``), unless there are two with no z in their offsets r or
    velocities u (a figure moving in its x-y plane): those start at even shares and iterate
    plainly, as the 2-D rule does (where the iteration starts can decide whether a normal
    impulse pulls, and a figure in that plane moves as the 2-D simulator moves it).

    How it is solved: the system in the n normal impulses and the m = 3 (2 without the twist)
    tangential unknowns is symmetric positive semi-definite, [[A, B], [Bᵀ, D]] (the body's
    response restricted to those impulses, plus the compliance on A's diagonal). A does not
    depend on the shares, so it is inverted once (by its Cholesky factor; a pivot at most 1e-12
    of its largest entry is singular), and so is N0 = A⁻¹ (-u_y); B is linear in the shares
    and D bilinear, so the terms they sum (``pairs`` (M, M, 9): for each pair of points, the
    normal response at the first to the slides and twist at the second, and the slide and
    twist response at the first to them) are made once too. Each share iteration sums
    them, forms the Schur complement S = D - Bᵀ Y, Y = A⁻¹ B (m × m), and solves S x = b - Bᵀ N0
    by S's adjugate, one division (singular where a pivot of S's Cholesky factor, the ratio of
    two leading minors, is at most 1e-12 of the system's largest entry); the normal impulses are
    N0 - Y x: no chain of divisions and square roots an iteration. system (M + 4, M + 4) holds,
    M = MAX_CONTACTS: A⁻¹ in rows :n, columns :n; B in rows :n, columns M:M + m; Yᵀ in rows M:M
    + m, columns :n, and S beside it; the right-hand sides and solutions (N0, then b and x) in
    column M + 3; the normal impulses in row M + 3, columns :n. A⁻¹, N0 and the pairs' terms
    depend neither on the shares nor on ``twisting``: ``_normal_block`` makes them (scale_a: the
    largest entry of A, which it returns), and a retry without the twist reads the same."""
    n = 0
    known = 0.0
    planar = True  # no z in any active point's offset or velocity: the 2-D rule's case
    for i in range(count):
        if active[i]:
            n += 1
            known = known + share[i] if share[i] > 0.0 and known >= 0.0 else -1.0
            planar = planar and r[i, 2] == 0.0 and u[i, 2] == 0.0
    accelerated = n >= 3 or not planar  # two in the plane iterate plainly, as the 2-D rule does
    for i in range(count):
        if not active[i]:
            weight[i] = 0.0
        elif known > 0.0 and accelerated:  # two in the plane start even, as the 2-D rule does
            weight[i] = share[i] / known
        else:
            weight[i] = 1.0 / n
    m = 3 if twisting else 2
    t = MAX_CONTACTS  # the tangential block's first row and column
    rhs = MAX_CONTACTS + 3  # the right-hand sides' and solutions' column
    normal = MAX_CONTACTS + 3  # the row that keeps the normal impulses
    converged = False
    last = MAX_CONTACTS - 1  # mixing's row of the last update and residual
    for iteration in range(FIXED_POINT_ITERATIONS):
        # B, D (lower triangle) and the tangential right-hand side b at the present shares
        b_x = b_z = b_twist = 0.0
        d_xx = d_zx = d_zz = d_tx = d_tz = d_tt = 0.0
        scale = scale_a
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = 0.0
            for j in range(count):
                if not active[j]:
                    continue
                wj = weight[j]
                s0 += wj * pairs[i, j, 0]
                s1 += wj * pairs[i, j, 1]
                s2 += wj * pairs[i, j, 2]
                s3 += wj * pairs[i, j, 3]
                s4 += wj * pairs[i, j, 4]
                s5 += wj * pairs[i, j, 5]
                s6 += wj * pairs[i, j, 6]
                s7 += wj * pairs[i, j, 7]
                s8 += wj * pairs[i, j, 8]
            wi = weight[i]
            system[row, t] = s0
            system[row, t + 1] = s1
            scale = max(scale, abs(s0), abs(s1))
            d_xx += wi * s3
            d_zx += wi * s4
            d_zz += wi * s5
            b_x -= wi * u[i, 0]
            b_z -= wi * u[i, 2]
            if twisting:
                system[row, t + 2] = s2
                scale = max(scale, abs(s2))
                d_tx += wi * s6
                d_tz += wi * s7
                d_tt += wi * s8
                b_twist -= wi * (r[i, 2] * u[i, 0] - r[i, 0] * u[i, 2])
            row += 1
        system[t, t] = d_xx
        system[t + 1, t] = d_zx
        system[t + 1, t + 1] = d_zz
        system[t, rhs] = b_x
        system[t + 1, rhs] = b_z
        scale = max(scale, abs(d_xx), abs(d_zx), abs(d_zz))
        if twisting:
            system[t + 2, t] = d_tx
            system[t + 2, t + 1] = d_tz
            system[t + 2, t + 2] = d_tt
            system[t + 2, rhs] = b_twist
            scale = max(scale, abs(d_tx), abs(d_tz), abs(d_tt))
        # Y = A⁻¹ B (its transpose in rows M:M + m, columns :n); S = D - Bᵀ Y and b - Bᵀ N0
        for q in range(m):
            for k in range(n):
                total = 0.0
                for p in range(n):
                    total += system[k, p] * system[p, t + q]
                system[t + q, k] = total
        for p in range(m):
            for k in range(n):
                b_kp = system[k, t + p]
                system[t + p, rhs] -= b_kp * system[k, rhs]
                for q in range(p + 1):
                    system[t + p, t + q] -= b_kp * system[t + q, k]
        # S x = b - Bᵀ N0 by S's adjugate; a pivot of S's Cholesky factor (the ratio of its
        # leading minors) at most 1e-12 of the system's largest entry is singular
        s00 = system[t, t]
        s10 = system[t + 1, t]
        s11 = system[t + 1, t + 1]
        minor = s00 * s11 - s10 * s10
        if not (s00 > 1e-12 * scale and minor > 1e-12 * scale * s00):
            return -2
        r0 = system[t, rhs]
        r1 = system[t + 1, rhs]
        if twisting:
            s20 = system[t + 2, t]
            s21 = system[t + 2, t + 1]
            s22 = system[t + 2, t + 2]
            c00 = s11 * s22 - s21 * s21
            c10 = s20 * s21 - s10 * s22
            c20 = s10 * s21 - s11 * s20
            determinant = s00 * c00 + s10 * c10 + s20 * c20
            if not determinant > 1e-12 * scale * minor:
                return -2
            inverse = 1.0 / determinant
            r2 = system[t + 2, rhs]
            system[t, rhs] = (c00 * r0 + c10 * r1 + c20 * r2) * inverse
            system[t + 1, rhs] = (
                c10 * r0 + (s00 * s22 - s20 * s20) * r1 + (s10 * s20 - s00 * s21) * r2
            ) * inverse
            system[t + 2, rhs] = (c20 * r0 + (s10 * s20 - s00 * s21) * r1 + minor * r2) * inverse
        else:
            inverse = 1.0 / minor
            system[t, rhs] = (s11 * r0 - s10 * r1) * inverse
            system[t + 1, rhs] = (s00 * r1 - s10 * r0) * inverse
        # the normal impulses N0 - Y x
        for k in range(n):
            total = system[k, rhs]
            for q in range(m):
                total -= system[t + q, k] * system[t + q, rhs]
            system[normal, k] = total
        total = 0.0
        worst = -1
        worst_value = 0.0
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            value = system[normal, row]
            if value <= worst_value:
                worst_value = value
                worst = i
            total += value
            row += 1
        if worst >= 0:
            return worst
        # the plain update g (each point's share of the normal impulses) and its residual
        # g - w, remembered as changes since the last iteration
        depth = n - 1
        slot = (iteration - 1) % depth
        change = 0.0
        row = 0
        for i in range(count):
            if not active[i]:
                continue
            updated = system[normal, row] / total
            residual = updated - weight[i]
            change = max(change, abs(residual))
            if iteration > 0:
                mixing[0, slot, i] = updated - mixing[0, last, i]
                mixing[1, slot, i] = residual - mixing[1, last, i]
            mixing[0, last, i] = updated
            mixing[1, last, i] = residual
            weight[i] = updated
            row += 1
        if change <= 1e-12:
            converged = True
            break
        if accelerated:
            _mix_shares(weight, active, count, mixing, min(iteration, depth))
    if twisting and not converged:
        return -3
    slide_x = system[t, rhs]
    slide_z = system[t + 1, rhs]
    twist = system[t + 2, rhs] if twisting else 0.0
    row = 0
    for i in range(count):
        if active[i]:
            impulse[i, 0] = weight[i] * (slide_x + twist * r[i, 2])
            impulse[i, 1] = system[normal, row]
            impulse[i, 2] = weight[i] * (slide_z - twist * r[i, 0])
            row += 1
    return -1


@njit(cache=True, inline="always", error_model="numpy")
def stop_dead(u, responses, i):
    """The impulse (x, y, z) that stops contact i (velocity u[i] (3,)) dead, from its own
    response responses[i, i] (3, 3) (symmetric positive definite: solved by its Cholesky
    factor); its y is <= 0 if that would pull the point down."""
    l00 = math.sqrt(responses[i, i, 0, 0])
    l10 = responses[i, i, 1, 0] / l00
    l20 = responses[i, i, 2, 0] / l00
    l11 = math.sqrt(responses[i, i, 1, 1] - l10 * l10)
    l21 = (responses[i, i, 2, 1] - l20 * l10) / l11
    l22 = math.sqrt(responses[i, i, 2, 2] - l20 * l20 - l21 * l21)
    y0 = -u[i, 0] / l00
    y1 = (-u[i, 1] - l10 * y0) / l11
    y2 = (-u[i, 2] - l20 * y0 - l21 * y1) / l22
    z = y2 / l22
    y = (y1 - l21 * z) / l11
    x = (y0 - l10 * y - l20 * z) / l00
    return x, y, z


@njit(cache=True, inline="always", error_model="numpy")
def stop_horizontally(u, responses, i):
    """The horizontal impulse (x, 0, z) that stops contact i's horizontal velocity (u[i] (3,))
    alone, from the x-z block of its own response responses[i, i] (3, 3): the lone contact's
    stop where stopping dead would pull (the point then does not sink)."""
    k = responses[i, i]
    det = k[0, 0] * k[2, 2] - k[0, 2] * k[2, 0]
    px = (-u[i, 0] * k[2, 2] + u[i, 2] * k[0, 2]) / det
    pz = (-u[i, 2] * k[0, 0] + u[i, 0] * k[2, 0]) / det
    return px, 0.0, pz


@njit(cache=True, inline="always", error_model="numpy")
def _others_hold(u, count, responses, impulse, members):
    """True if no touching point outside ``members`` ((count,) 1.0 for a member) sinks after
    the impulses (count, 3)."""
    for i in range(count):
        if members[i]:
            continue
        uy = u[i, 1]
        for j in range(count):
            for b in range(3):
                uy += responses[i, j, 1, b] * impulse[j, b]
        if uy < -1e-9:
            return False
    return True


@njit(cache=True, inline="always", error_model="numpy")
def _twist_too_strong(impulse, active, count):
    """True if some active contact's horizontal impulse exceeds TWIST_RATIO times its normal."""
    for i in range(count):
        if active[i]:
            horizontal = math.sqrt(impulse[i, 0] ** 2 + impulse[i, 2] ** 2)
            if horizontal > TWIST_RATIO * impulse[i, 1]:
                return True
    return False


@njit(cache=True, error_model="numpy")
def frictionless_impulses(u, count, responses, impulse, system, compliance, members):
    """Normal impulses alone (count,) N s into impulse[:, 1] (its x and z 0), the floor's last
    resort when no impulse set of the friction rule pushes: the contacts that push stop
    sinking, and none of the others sinks after them (non-penetration with no friction; for a
    positive definite normal block exactly one such set). The sets are tried largest first;
    ``compliance`` (s/kg) is added to each contact's own normal response in sets of three or
    more (as ``contact_impulses`` does: a rigid body leaves their split undecided). u (count, 3),
    responses (M, M, 3, 3); system (M + 4, M + 4), members (M,): work space. Returns whether
    a set was found (else the impulses are 0)."""
    impulse[:count, :] = 0.0
    for size in range(count, 0, -1):
        for subset in range(1, 1 << count):
            n = 0
            for i in range(count):
                bit = (subset >> i) & 1
                members[i] = bit
                n += bit
            if n != size:
                continue
            added = compliance if n >= 3 else 0.0
            # A_S's Cholesky factor in system[:n, :n], the solution in column M
            scale = normal_responses(members, count, responses, added, system)
            row = 0
            for i in range(count):
                if members[i]:
                    system[row, MAX_CONTACTS] = -u[i, 1]
                    row += 1
            if not cholesky_in_place(system, n, scale):
                continue
            for k in range(n):  # L y = b, then Lᵀ x = y
                total = system[k, MAX_CONTACTS]
                for q in range(k):
                    total -= system[k, q] * system[q, MAX_CONTACTS]
                system[k, MAX_CONTACTS] = total / system[k, k]
            pushing = True
            for k in range(n - 1, -1, -1):
                total = system[k, MAX_CONTACTS]
                for q in range(k + 1, n):
                    total -= system[q, k] * system[q, MAX_CONTACTS]
                system[k, MAX_CONTACTS] = total / system[k, k]
                pushing = pushing and system[k, MAX_CONTACTS] > 0.0
            if not pushing:
                continue
            row = 0
            for i in range(count):
                if members[i]:
                    impulse[i, 1] = system[row, MAX_CONTACTS]
                    row += 1
            if _others_hold(u, count, responses, impulse, members):
                return True
            impulse[:count, 1] = 0.0
    return False


@njit(cache=True, inline="always", error_model="numpy")
def contact_impulses(
    u,
    r,
    count,
    inverse_mass,
    world_inverse,
    impulse,
    responses,
    system,
    mixing,
    shares,
    chosen,
    end_share,
    pairs,
    spins,
):
    """The ground's impulses (count, 3) N s on ``count`` touching endpoints: u (count, 3) their
    velocities m/s, r (count, 3) their offsets from the centre of mass m. First the sinking ones
    together, with shared friction, dropping the one whose normal impulse would pull most and
    trying again while two or more are left; then each sinking one alone, the fastest first,
    stopped dead. The first set whose normal impulses push and after which no other touching
    point sinks is kept. A lone point that stopping dead would pull is stopped horizontally
    alone (``stop_horizontally``; it then rises). Two or more of which no set pushes take
    normal impulses alone (``frictionless_impulses``), as the 2-D rule does for two. Returns
    whether the impulses follow the friction rule (False: the frictionless ones).
    responses (M, M, 3, 3), system (M + 4, M + 4), mixing (3, M, M), shares (3, M), pairs (M, M,
    9), spins (M, 3, 3): work space.
    chosen (count,): the points' endpoint numbers; end_share (E,): each endpoint's share of the
    horizontal impulse the step before, updated (the shared-friction iteration starts from
    it)."""
    impulse[:count, :] = 0.0
    active = shares[0]
    weight = shares[1]
    share = shares[2]
    for i in range(count):
        share[i] = end_share[chosen[i]]
    end_share[:] = 0.0
    n = 0
    for i in range(count):
        active[i] = 1.0 if u[i, 1] < 0.0 else 0.0
        n += int(active[i])
    if n == 0:
        return True
    for j in range(count):
        spin_per_impulse(r, j, world_inverse, spins)
    for i in range(count):
        for j in range(count):
            response(r, i, j, inverse_mass, spins, responses)
    # three or more points: a rigid body often leaves their split undecided
    compliance = 0.0 if n < 3 else COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
    # np.int64 and np.bool_: types, not literals (each literal a signature of its own: the
    # shared friction compiled four times over, 40 s of a cold start)
    points = (u, r, active, np.int64(count), impulse, system, mixing, weight, share)
    while n >= 2:
        scale_a = _normal_block(u, r, active, np.int64(count), responses, system, compliance, pairs)
        worst = -2
        if scale_a >= 0.0:
            worst = _shared_friction(*points, np.bool_(True), pairs, scale_a)
        if worst == -1 and _twist_too_strong(impulse, active, count) or worst == -3:
            # slide only: the paper's rule as it is (on the same normal block)
            worst = _shared_friction(*points, np.bool_(False), pairs, scale_a)
        if worst == -2 and compliance == 0.0:
            # the rigid body leaves the split undecided: a little compliance decides it
            compliance = COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
            continue
        if worst == -1 and _others_hold(u, count, responses, impulse, active):
            for i in range(count):
                end_share[chosen[i]] = weight[i]
            return True
        if worst < 0:
            # still singular, unsettled, or another point would sink: drop the one sinking
            # slowest
            for i in range(count):
                if active[i] and (worst < 0 or u[i, 1] > u[worst, 1]):
                    worst = i
        active[worst] = 0.0
        n -= 1
        impulse[:count, :] = 0.0
    tried = shares[1]
    tried[:count] = 0.0
    for _ in range(count):
        first = -1
        for i in range(count):
            if u[i, 1] < 0.0 and not tried[i] and (first < 0 or u[i, 1] < u[first, 1]):
                first = i
        if first < 0:
            break
        tried[first] = 1.0
        px, py, pz = stop_dead(u, responses, first)
        if py <= 0.0:
            if count == 1:
                # stopping dead would pull: the horizontal stop alone, after which it rises
                # (the lone-contact rule, as in 2-D)
                impulse[0, 0], _, impulse[0, 2] = stop_horizontally(u, responses, 0)
                return True
            continue
        impulse[first, 0] = px
        impulse[first, 1] = py
        impulse[first, 2] = pz
        active[:count] = 0.0
        active[first] = 1.0
        if _others_hold(u, count, responses, impulse, active):
            return True
        impulse[first, :] = 0.0
    # no set pushes under the friction rule: without friction, rather than no impulse (the
    # figure would sink, be lifted out by its position alone and gather a fall's velocity)
    compliance = COMPLIANCE * (responses[0, 0, 0, 0] + responses[0, 0, 1, 1])
    frictionless_impulses(u, count, responses, impulse, system, compliance, active)
    return False
