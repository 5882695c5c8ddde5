r"""The compiled time-step kernels (numba): pair forces, then per-particle sums, walls and update.

One step is two passes over flat arrays, each a parallel loop:

1. :func:`pair_forces`, one iteration per Verlet pair (i, j): the contact test
   :math:`|x_j - x_i| < r_i + r_j`, and for touching pairs the contact law
   (:func:`dem._contacts.contact_law`) with the pair's shear-spring history; the force on *i*,
   the torque arm term :math:`\mathbf n \times \mathbf F_t` and the new history are stored per
   pair (history is zeroed for pairs that do not touch).
2. :func:`particle_update`, one iteration per particle: the sum of its pair forces in a fixed
   order (the pairs where it is first, then those where it is second, each in pair order), its
   wall contacts (same contact law, wall by wall), gravity, the sum M of its contacts' rolling
   moments :math:`\mu_r F_n r` (:func:`dem._contacts.rolling_moment`; ``roll``), and, when
   asked, the semi-implicit Euler update of velocity, spin and position, with the rolling torque
   :func:`dem._contacts.rolling_torque` against the spin (a grain's is applied by the grain update).

Every sum runs in that fixed order, so the result does not depend on the number of threads
and equals, bit for bit, the numpy form this replaced (``np.bincount`` over the contacts; see
``docs/dem-speed.md``). Walls are passed as arrays: kind (0 plane, 1 cylinder), the plane
normal, the plane offset :math:`-\mathbf p\cdot\mathbf n` (moving walls shifted by the container
offset), the cylinder (cx, cy, R) and whether the wall moves with the container.
"""

from __future__ import annotations

import numba
import numpy as np

from ._contacts import contact_law, rolling_moment, rolling_torque

__all__ = ["flag_walls", "list_walls", "near_wall", "pair_damping", "pair_forces", "particle_update", "wall_contacts",
           "wall_rolling"]


@numba.njit(parallel=True, cache=True, error_model="numpy")
def pair_damping(ms, pi, pj, beta, kn, ks, cn, ct):
    r"""Dashpot coefficients of every pair, :math:`c = 2\beta\sqrt{m^* k}` with
    :math:`m^* = m_i m_j/(m_i + m_j)` (scaled masses ``ms``); writes ``cn``, ``ct`` (Np,)."""
    for k in numba.prange(pi.shape[0]):
        mi = ms[pi[k]]
        mj = ms[pj[k]]
        meff = mi * mj / (mi + mj)
        cn[k] = 2.0 * beta * np.sqrt(meff * kn)
        ct[k] = 2.0 * beta * np.sqrt(meff * ks)


@numba.njit(parallel=True, cache=True, error_model="numpy")
def pair_forces(x, v, w, r, pi, pj, cn, ct, shear, kn, ks, mu, dt, f_pair, t_pair, fn_pair, touch):
    """Contact forces of all Verlet pairs (step 1 of the module notes); writes the outputs.

    ``x, v, w`` (N, 3) positions, velocities, spins; ``pi, pj`` (Np,) pair members; ``cn, ct``
    (Np,) dashpot coefficients (:func:`pair_damping`); ``shear`` (Np, 3) history, updated in
    place; outputs ``f_pair`` (Np, 3) force on i, ``t_pair`` (Np, 3) n x F_t, ``fn_pair`` (Np,)
    normal force, ``touch`` (Np,) uint8.
    """
    for k in numba.prange(pi.shape[0]):
        i = pi[k]
        j = pj[k]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        dz = x[j, 2] - x[i, 2]
        dist2 = dx * dx + dy * dy + dz * dz
        rsum = r[i] + r[j]
        if not dist2 < rsum * rsum:
            if touch[k]:  # contact lost: history starts again from zero (only written then)
                touch[k] = 0
                shear[k, 0] = 0.0
                shear[k, 1] = 0.0
                shear[k, 2] = 0.0
            continue
        touch[k] = 1
        dist = np.sqrt(dist2)
        nx = dx / dist
        ny = dy / dist
        nz = dz / dist
        # relative velocity of the contact point: v_i - v_j + (w_i r_i + w_j r_j) x n
        ax = w[i, 0] * r[i] + w[j, 0] * r[j]
        ay = w[i, 1] * r[i] + w[j, 1] * r[j]
        az = w[i, 2] * r[i] + w[j, 2] * r[j]
        vx = v[i, 0] - v[j, 0] + (ay * nz - az * ny)
        vy = v[i, 1] - v[j, 1] + (az * nx - ax * nz)
        vz = v[i, 2] - v[j, 2] + (ax * ny - ay * nx)
        out = contact_law(rsum - dist, nx, ny, nz, vx, vy, vz, shear[k, 0], shear[k, 1], shear[k, 2],
                          kn, ks, cn[k], ct[k], mu, dt)
        f_pair[k, 0], f_pair[k, 1], f_pair[k, 2], fn_pair[k] = out[0], out[1], out[2], out[3]
        ftx, fty, ftz = out[4], out[5], out[6]
        shear[k, 0], shear[k, 1], shear[k, 2] = out[7], out[8], out[9]
        t_pair[k, 0] = ny * ftz - nz * fty
        t_pair[k, 1] = nz * ftx - nx * ftz
        t_pair[k, 2] = nx * fty - ny * ftx


@numba.njit(inline="always", cache=True, error_model="numpy")
def wall_contacts(p, x, v, w, r, ms, wall_kind, wall_normal, wall_offset, wall_cyl, wall_moves, wall_vz, wall_shear,
                  wall_fn, wall_touch, kn_w, ks_w, beta, mu_w, dt):
    """Wall contacts of particle ``p`` (the walls' part of :func:`particle_update`, wall by wall):
    returns its wall force and torque (fx, fy, fz, tx, ty, tz) and the number of walls touched;
    writes the wall springs, ``wall_fn`` and ``wall_touch`` of ``p``."""
    rp = r[p]
    wfx = wfy = wfz = 0.0
    wtx = wty = wtz = 0.0
    hits = 0
    for m in range(wall_kind.shape[0]):
        if wall_kind[m] == 0:
            d = wall_offset[m]
            if wall_normal[m, 0] != 0.0:
                d = d + wall_normal[m, 0] * x[p, 0]
            if wall_normal[m, 1] != 0.0:
                d = d + wall_normal[m, 1] * x[p, 1]
            if wall_normal[m, 2] != 0.0:
                d = d + wall_normal[m, 2] * x[p, 2]
            ov = rp - d
            nx, ny, nz = -wall_normal[m, 0], -wall_normal[m, 1], -wall_normal[m, 2]
        else:
            ddx = x[p, 0] - wall_cyl[m, 0]
            ddy = x[p, 1] - wall_cyl[m, 1]
            rho = np.sqrt(ddx * ddx + ddy * ddy)
            ov = rp - (wall_cyl[m, 2] - rho)
            rh = max(rho, 1e-300)
            nx, ny, nz = ddx / rh, ddy / rh, 0.0
        if not ov > 0.0:
            if wall_touch[m, p]:
                wall_touch[m, p] = 0
                wall_shear[m, p, 0] = 0.0
                wall_shear[m, p, 1] = 0.0
                wall_shear[m, p, 2] = 0.0
            continue
        hits += 1
        wall_touch[m, p] = 1
        ax, ay, az = w[p, 0] * rp, w[p, 1] * rp, w[p, 2] * rp
        vwz = wall_vz if wall_moves[m] else 0.0
        vx = v[p, 0] - 0.0 + (ay * nz - az * ny)
        vy = v[p, 1] - 0.0 + (az * nx - ax * nz)
        vz = v[p, 2] - vwz + (ax * ny - ay * nx)
        cn = 2.0 * beta * np.sqrt(ms[p] * kn_w)
        ct = 2.0 * beta * np.sqrt(ms[p] * ks_w)
        out = contact_law(ov, nx, ny, nz, vx, vy, vz, wall_shear[m, p, 0], wall_shear[m, p, 1],
                          wall_shear[m, p, 2], kn_w, ks_w, cn, ct, mu_w, dt)
        wfx += out[0]
        wfy += out[1]
        wfz += out[2]
        wall_fn[m, p] = out[3]
        ftx, fty, ftz = out[4], out[5], out[6]
        wall_shear[m, p, 0], wall_shear[m, p, 1], wall_shear[m, p, 2] = out[7], out[8], out[9]
        wtx += (ny * ftz - nz * fty) * rp
        wty += (nz * ftx - nx * ftz) * rp
        wtz += (nx * fty - ny * ftx) * rp
    return wfx, wfy, wfz, wtx, wty, wtz, hits


@numba.njit(inline="always", cache=True, error_model="numpy")
def wall_rolling(p, wall_touch, wall_fn, mu_rw, rp):
    """Sum of the rolling moments (:func:`dem._contacts.rolling_moment`) of the wall contacts of
    particle ``p`` (radius ``rp``, m) at the last evaluation, N·m."""
    m = 0.0
    for k in range(wall_touch.shape[0]):
        if wall_touch[k, p]:
            m += rolling_moment(mu_rw, wall_fn[k, p], rp)
    return m


@numba.njit(inline="always", cache=True)
def near_wall(x0, x1, x2, reach, wall_kind, wall_normal, wall_offset, wall_cyl):
    """Whether a wall lies closer than ``reach`` (m) to the point (x0, x1, x2) (distances as in
    :func:`wall_contacts`)."""
    for m in range(wall_kind.shape[0]):
        if wall_kind[m] == 0:
            d = wall_offset[m]
            if wall_normal[m, 0] != 0.0:
                d = d + wall_normal[m, 0] * x0
            if wall_normal[m, 1] != 0.0:
                d = d + wall_normal[m, 1] * x1
            if wall_normal[m, 2] != 0.0:
                d = d + wall_normal[m, 2] * x2
        else:
            ddx = x0 - wall_cyl[m, 0]
            ddy = x1 - wall_cyl[m, 1]
            d = wall_cyl[m, 2] - np.sqrt(ddx * ddx + ddy * ddy)
        if not d >= reach:
            return True
    return False


@numba.njit(inline="always", cache=True)
def flag_walls(p, ref, r, skin, wall_kind, wall_normal, wall_offset, wall_cyl, wall_touch, wall_shear, near):
    """``near[p]``: a wall within r_p + skin of sphere p's reference; without one its wall
    springs and touching flags are cleared (no wall touches it: the step would clear them)."""
    hit = near_wall(ref[p, 0], ref[p, 1], ref[p, 2], r[p] + skin, wall_kind, wall_normal, wall_offset, wall_cyl)
    near[p] = hit
    if not hit:
        for m in range(wall_kind.shape[0]):
            wall_touch[m, p] = 0
            wall_shear[m, p, 0] = wall_shear[m, p, 1] = wall_shear[m, p, 2] = 0.0


@numba.njit(cache=True)
def list_walls(idx, ref, r, skin, wall_kind, wall_normal, wall_offset, wall_cyl, wall_touch, wall_shear, near):
    """:func:`flag_walls` for the spheres ``idx`` (all of them after the walls moved)."""
    for a in range(idx.shape[0]):
        flag_walls(idx[a], ref, r, skin, wall_kind, wall_normal, wall_offset, wall_cyl, wall_touch, wall_shear,
                   near)


@numba.njit(parallel=True, cache=True, error_model="numpy")
def particle_update(x, v, w, r, ms, gforce, first_start, second_start, by_second, f_pair, t_pair, fn_pair, touch,
                    wall_kind, wall_normal, wall_offset, wall_cyl, wall_moves, wall_vz, wall_shear, wall_fn,
                    wall_touch, kn_w, ks_w, beta, mu_w, mu_r, mu_rw, dt, inv_m, inv_i, force, torque, roll, advance):
    """Net force and torque on every particle (step 2 of the module notes), and the update.

    ``first_start`` (N+1,), ``second_start`` (N+1,), ``by_second`` (Np,): the particle's pairs
    (:class:`dem._neighbors.VerletList`); ``gforce`` (N,) weight with scaled mass; walls as in
    the module notes, ``wall_shear`` (Nw, N, 3) history, ``wall_fn``/``wall_touch`` (Nw, N)
    written; ``mu_r``, ``mu_rw`` coefficients of rolling friction of pair and wall contacts;
    ``inv_m``, ``inv_i`` (N,) Δt over scaled mass / moment of inertia; ``force``, ``torque``
    (N, 3) and ``roll`` (N,) (the rolling moment M, N·m) written; ``advance``: also update v, w,
    x, with the rolling torque in ``torque`` (against the spin ω* = ω + T ``inv_i`` the step gives
    without it, limited to stop that spin, M_stop = |ω*|/``inv_i``).
    """
    n = x.shape[0]
    rolling = mu_r > 0.0 or mu_rw > 0.0
    for p in numba.prange(n):
        fx = fy = fz = 0.0
        tx = ty = tz = 0.0
        mr = 0.0
        rp = r[p]
        for k in range(first_start[p], first_start[p + 1]):
            if touch[k]:
                fx += f_pair[k, 0]
                fy += f_pair[k, 1]
                fz += f_pair[k, 2]
                tx += t_pair[k, 0] * rp
                ty += t_pair[k, 1] * rp
                tz += t_pair[k, 2] * rp
                if rolling:
                    mr += rolling_moment(mu_r, fn_pair[k], rp)
        for s in range(second_start[p], second_start[p + 1]):
            k = by_second[s]
            if touch[k]:
                fx -= f_pair[k, 0]
                fy -= f_pair[k, 1]
                fz -= f_pair[k, 2]
                tx += t_pair[k, 0] * rp
                ty += t_pair[k, 1] * rp
                tz += t_pair[k, 2] * rp
                if rolling:
                    mr += rolling_moment(mu_r, fn_pair[k], rp)
        # walls: summed apart, wall by wall, then added (one fixed order: the same bits always)
        wfx, wfy, wfz, wtx, wty, wtz, hits = wall_contacts(p, x, v, w, r, ms, wall_kind, wall_normal, wall_offset,
                                                           wall_cyl, wall_moves, wall_vz, wall_shear, wall_fn,
                                                           wall_touch, kn_w, ks_w, beta, mu_w, dt)
        if hits:
            fx += wfx
            fy += wfy
            fz += wfz
            tx += wtx
            ty += wty
            tz += wtz
        fz -= gforce[p]
        if rolling:
            mr += wall_rolling(p, wall_touch, wall_fn, mu_rw, rp)
            if advance and mr > 0.0:        # against the spin the step gives without it
                wx, wy, wz = w[p, 0] + tx * inv_i[p], w[p, 1] + ty * inv_i[p], w[p, 2] + tz * inv_i[p]
                rx, ry, rz = rolling_torque(mr, wx, wy, wz, np.sqrt(wx * wx + wy * wy + wz * wz) / inv_i[p])
                tx += rx
                ty += ry
                tz += rz
        roll[p] = mr
        force[p, 0], force[p, 1], force[p, 2] = fx, fy, fz
        torque[p, 0], torque[p, 1], torque[p, 2] = tx, ty, tz
        if advance:
            v[p, 0] += fx * inv_m[p]
            v[p, 1] += fy * inv_m[p]
            v[p, 2] += fz * inv_m[p]
            w[p, 0] += tx * inv_i[p]
            w[p, 1] += ty * inv_i[p]
            w[p, 2] += tz * inv_i[p]
            x[p, 0] += v[p, 0] * dt
            x[p, 1] += v[p, 1] * dt
            x[p, 2] += v[p, 2] * dt
