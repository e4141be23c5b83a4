"""The 3-D BSR simulator's pieces for LANES controllers in lockstep (``kernels.lanes``;
``bsr3d_controller.run_lockstep`` runs them): so far the body frame, the rest of a step is
computed lane by lane.

Arrays hold lanes last and contiguous, flattened: a quantity of shape S per controller is an
array of prod(S) * LANES float64, element (index, lane) at ``index * LANES + lane``.
"""

from __future__ import annotations

from numba import njit

from mosys.kernels.lanes import LANES, add, divide, load, multiply, splat, store, subtract


@njit(cache=True, inline="always")
def _cross(ax, ay, az, bx, by, bz):
    return (
        subtract(multiply(ay, bz), multiply(az, by)),
        subtract(multiply(az, bx), multiply(ax, bz)),
        subtract(multiply(ax, by), multiply(ay, bx)),
    )


@njit(cache=True, inline="always")
def _at(index):
    """The flat offset of lane 0 of element ``index``."""
    return index * LANES


@njit(cache=True)
def body_frame_lanes(
    figure, trig, theta_rate, rod_ends, end_offset, end_velocity, frames, rod_work, tensor, spin
):
    """``bsr3d_simulate.body_frame`` for LANES controllers of one figure (a FigureArrays3D) at
    once, lanes last.

    Per controller (each flattened, lanes last): trig (4, N): each rod's joint angles' cosine
    and sine of θ, then of ψ (the root's unread); theta_rate (J) rad/s. Fills rod_ends (N, 2,
    3), end_offset, end_velocity (E, 3), frames (N, 3, 3), tensor (3, 3), spin (3) as
    ``body_frame`` does, and works in rod_work (5, N, 3): each rod's angular velocity, proximal
    end and its velocity, centre of mass and its velocity. Returns the total mass, kg. The same
    numbers as ``body_frame`` lane by lane, to rounding (its sums in the same order): bit for
    bit (tested)."""
    parent, hinge, rest, length, mass, com, inertia, joint, endpoints = figure[:9]
    cosine_theta, sine_theta, cosine_psi, sine_psi = trig[0], trig[1], trig[2], trig[3]
    omega, proximal, proximal_velocity = rod_work[0], rod_work[1], rod_work[2]
    centre, centre_velocity = rod_work[3], rod_work[4]
    n = parent.shape[0]
    zero = splat(0.0)
    mass_x = mass_y = mass_z = momentum_x = momentum_y = momentum_z = zero
    total_mass = 0.0
    for k in range(n):
        p = parent[k]
        if p < 0:
            for a in range(3):
                for b in range(3):
                    store(frames, _at((k * 3 + a) * 3 + b), splat(rest[k, a, b]))
                store(omega, _at(k * 3 + a), zero)
                store(proximal, _at(k * 3 + a), zero)
                store(proximal_velocity, _at(k * 3 + a), zero)
        else:
            j = joint[k]
            reach = splat(hinge[k])
            hx = multiply(reach, load(frames, _at(p * 9)))
            hy = multiply(reach, load(frames, _at(p * 9 + 3)))
            hz = multiply(reach, load(frames, _at(p * 9 + 6)))
            wx = load(omega, _at(p * 3))
            wy = load(omega, _at(p * 3 + 1))
            wz = load(omega, _at(p * 3 + 2))
            vx, vy, vz = _cross(wx, wy, wz, hx, hy, hz)
            for a, h, v in ((0, hx, vx), (1, hy, vy), (2, hz, vz)):
                store(proximal, _at(k * 3 + a), add(load(proximal, _at(p * 3 + a)), h))
                velocity = add(load(proximal_velocity, _at(p * 3 + a)), v)
                store(proximal_velocity, _at(k * 3 + a), velocity)
            ct = load(cosine_theta, _at(k))
            st = load(sine_theta, _at(k))
            cp = load(cosine_psi, _at(k))
            sp = load(sine_psi, _at(k))
            rate_theta = load(theta_rate, _at(j))
            rate_psi = load(theta_rate, _at(j + 1))
            for a in range(3):
                # row a of A = frames[p] @ rest[k], then of A @ Rz(θ) @ Ry(ψ)
                f0 = load(frames, _at(p * 9 + a * 3))
                f1 = load(frames, _at(p * 9 + a * 3 + 1))
                f2 = load(frames, _at(p * 9 + a * 3 + 2))
                a0 = add(
                    add(multiply(f0, splat(rest[k, 0, 0])), multiply(f1, splat(rest[k, 1, 0]))),
                    multiply(f2, splat(rest[k, 2, 0])),
                )
                a1 = add(
                    add(multiply(f0, splat(rest[k, 0, 1])), multiply(f1, splat(rest[k, 1, 1]))),
                    multiply(f2, splat(rest[k, 2, 1])),
                )
                a2 = add(
                    add(multiply(f0, splat(rest[k, 0, 2])), multiply(f1, splat(rest[k, 1, 2]))),
                    multiply(f2, splat(rest[k, 2, 2])),
                )
                b0 = add(multiply(ct, a0), multiply(st, a1))
                b1 = subtract(multiply(ct, a1), multiply(st, a0))
                store(frames, _at(k * 9 + a * 3), subtract(multiply(cp, b0), multiply(sp, a2)))
                store(frames, _at(k * 9 + a * 3 + 1), b1)
                store(frames, _at(k * 9 + a * 3 + 2), add(multiply(sp, b0), multiply(cp, a2)))
                turning = add(
                    add(load(omega, _at(p * 3 + a)), multiply(a2, rate_theta)),
                    multiply(b1, rate_psi),
                )
                store(omega, _at(k * 3 + a), turning)
        arm = splat(com[k] * length[k])
        m = splat(mass[k])
        ux = load(frames, _at(k * 9))
        uy = load(frames, _at(k * 9 + 3))
        uz = load(frames, _at(k * 9 + 6))
        vx, vy, vz = _cross(
            load(omega, _at(k * 3)),
            load(omega, _at(k * 3 + 1)),
            load(omega, _at(k * 3 + 2)),
            multiply(arm, ux),
            multiply(arm, uy),
            multiply(arm, uz),
        )
        gx = add(load(proximal, _at(k * 3)), multiply(arm, ux))
        gy = add(load(proximal, _at(k * 3 + 1)), multiply(arm, uy))
        gz = add(load(proximal, _at(k * 3 + 2)), multiply(arm, uz))
        cvx = add(load(proximal_velocity, _at(k * 3)), vx)
        cvy = add(load(proximal_velocity, _at(k * 3 + 1)), vy)
        cvz = add(load(proximal_velocity, _at(k * 3 + 2)), vz)
        store(centre, _at(k * 3), gx)
        store(centre, _at(k * 3 + 1), gy)
        store(centre, _at(k * 3 + 2), gz)
        store(centre_velocity, _at(k * 3), cvx)
        store(centre_velocity, _at(k * 3 + 1), cvy)
        store(centre_velocity, _at(k * 3 + 2), cvz)
        total_mass += mass[k]
        mass_x = add(mass_x, multiply(m, gx))
        mass_y = add(mass_y, multiply(m, gy))
        mass_z = add(mass_z, multiply(m, gz))
        momentum_x = add(momentum_x, multiply(m, cvx))
        momentum_y = add(momentum_y, multiply(m, cvy))
        momentum_z = add(momentum_z, multiply(m, cvz))
    total = splat(total_mass)
    cx = divide(mass_x, total)
    cy = divide(mass_y, total)
    cz = divide(mass_z, total)
    cvx = divide(momentum_x, total)
    cvy = divide(momentum_y, total)
    cvz = divide(momentum_z, total)
    t00 = t11 = t22 = t01 = t02 = t12 = s0 = s1 = s2 = zero
    for k in range(n):
        m = splat(mass[k])
        i_rod = splat(inertia[k])
        rx = subtract(load(centre, _at(k * 3)), cx)
        ry = subtract(load(centre, _at(k * 3 + 1)), cy)
        rz = subtract(load(centre, _at(k * 3 + 2)), cz)
        ux = load(frames, _at(k * 9))
        uy = load(frames, _at(k * 9 + 3))
        uz = load(frames, _at(k * 9 + 6))
        squared = add(
            multiply(m, add(add(multiply(rx, rx), multiply(ry, ry)), multiply(rz, rz))), i_rod
        )
        t00 = add(
            t00,
            subtract(
                subtract(squared, multiply(multiply(m, rx), rx)), multiply(multiply(i_rod, ux), ux)
            ),
        )
        t11 = add(
            t11,
            subtract(
                subtract(squared, multiply(multiply(m, ry), ry)), multiply(multiply(i_rod, uy), uy)
            ),
        )
        t22 = add(
            t22,
            subtract(
                subtract(squared, multiply(multiply(m, rz), rz)), multiply(multiply(i_rod, uz), uz)
            ),
        )
        t01 = subtract(t01, add(multiply(multiply(m, rx), ry), multiply(multiply(i_rod, ux), uy)))
        t02 = subtract(t02, add(multiply(multiply(m, rx), rz), multiply(multiply(i_rod, ux), uz)))
        t12 = subtract(t12, add(multiply(multiply(m, ry), rz), multiply(multiply(i_rod, uy), uz)))
        hx, hy, hz = _cross(
            rx,
            ry,
            rz,
            subtract(load(centre_velocity, _at(k * 3)), cvx),
            subtract(load(centre_velocity, _at(k * 3 + 1)), cvy),
            subtract(load(centre_velocity, _at(k * 3 + 2)), cvz),
        )
        wx = load(omega, _at(k * 3))
        wy = load(omega, _at(k * 3 + 1))
        wz = load(omega, _at(k * 3 + 2))
        along = add(add(multiply(ux, wx), multiply(uy, wy)), multiply(uz, wz))
        s0 = add(s0, add(multiply(m, hx), multiply(i_rod, subtract(wx, multiply(along, ux)))))
        s1 = add(s1, add(multiply(m, hy), multiply(i_rod, subtract(wy, multiply(along, uy)))))
        s2 = add(s2, add(multiply(m, hz), multiply(i_rod, subtract(wz, multiply(along, uz)))))
        ln = splat(length[k])
        for a, c, u in ((0, cx, ux), (1, cy, uy), (2, cz, uz)):
            end = subtract(load(proximal, _at(k * 3 + a)), c)
            store(rod_ends, _at(k * 6 + a), end)
            store(rod_ends, _at(k * 6 + 3 + a), add(end, multiply(ln, u)))
    for index, value in enumerate((t00, t01, t02, t01, t11, t12, t02, t12, t22)):
        store(tensor, _at(index), value)
    store(spin, _at(0), s0)
    store(spin, _at(1), s1)
    store(spin, _at(2), s2)
    for e in range(endpoints.shape[0]):
        k = endpoints[e, 0]
        end = endpoints[e, 1]
        reach = splat(length[k] * end)
        vx, vy, vz = _cross(
            load(omega, _at(k * 3)),
            load(omega, _at(k * 3 + 1)),
            load(omega, _at(k * 3 + 2)),
            multiply(reach, load(frames, _at(k * 9))),
            multiply(reach, load(frames, _at(k * 9 + 3))),
            multiply(reach, load(frames, _at(k * 9 + 6))),
        )
        for a, v, c in ((0, vx, cvx), (1, vy, cvy), (2, vz, cvz)):
            store(end_offset, _at(e * 3 + a), load(rod_ends, _at(k * 6 + end * 3 + a)))
            velocity = subtract(add(load(proximal_velocity, _at(k * 3 + a)), v), c)
            store(end_velocity, _at(e * 3 + a), velocity)
    return total_mass
