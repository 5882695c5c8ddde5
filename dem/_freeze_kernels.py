r"""The compiled kernels of :mod:`dem._freeze`: the linked cell grid over the reference positions,
the per-sphere rows (sorted insert and delete with the contact history), the re-search of the
rows of moved spheres (:func:`relist`), the poses of active grains (:func:`active_poses`), the
active step's contact forces (:func:`active_forces`, one evaluator per pair) and the history
hand-over when the frozen set changes (:func:`sync_history`). The scheme and its argument are in
:mod:`dem._freeze`'s docstring.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ._contacts import contact_law, rolling_moment
from ._grain_kernels import finish_grain, pose_one
from ._kernels import flag_walls, wall_contacts, wall_rolling

__all__ = ["active_forces", "active_poses", "in_contact", "load_history", "pair_dashpots", "relist", "row_starts",
           "sync_history"]


# ---------------------------------------------------------------------------- the cell grid
@numba.njit(inline="always", cache=True)
def _cell(x0, x1, x2, lo, cell, dims):
    c0 = min(max(int(math.floor((x0 - lo[0]) / cell)), 0), dims[0] - 1)
    c1 = min(max(int(math.floor((x1 - lo[1]) / cell)), 0), dims[1] - 1)
    c2 = min(max(int(math.floor((x2 - lo[2]) / cell)), 0), dims[2] - 1)
    return (c0 * dims[1] + c1) * dims[2] + c2


@numba.njit(inline="always", cache=True)
def _grid_remove(p, head, nxt, prv, cellof):
    c = cellof[p]
    if c < 0:
        return
    if prv[p] >= 0:
        nxt[prv[p]] = nxt[p]
    else:
        head[c] = nxt[p]
    if nxt[p] >= 0:
        prv[nxt[p]] = prv[p]
    cellof[p] = -1


@numba.njit(inline="always", cache=True)
def _grid_insert(p, c, head, nxt, prv, cellof):
    nxt[p] = head[c]
    prv[p] = -1
    if head[c] >= 0:
        prv[head[c]] = p
    head[c] = p
    cellof[p] = c


@numba.njit(cache=True)
def _scan(i, xi0, xi1, xi2, ref, r, gid, skin, lo, cell, dims, head, nxt, buf):
    """Partners of sphere i at reference (xi0, xi1, xi2): spheres of other grains within
    r_i + r_j + skin of it, written to ``buf``; returns their count (-1 when ``buf`` is full)."""
    c = _cell(xi0, xi1, xi2, lo, cell, dims)
    c2 = c % dims[2]
    c1 = (c // dims[2]) % dims[1]
    c0 = c // (dims[1] * dims[2])
    k = 0
    gi = gid[i]
    ri = r[i] + skin
    for a in range(max(c0 - 1, 0), min(c0 + 2, dims[0])):
        for b in range(max(c1 - 1, 0), min(c1 + 2, dims[1])):
            for z in range(max(c2 - 1, 0), min(c2 + 2, dims[2])):
                j = head[(a * dims[1] + b) * dims[2] + z]
                while j >= 0:
                    if j != i and gid[j] != gi:
                        dx = ref[j, 0] - xi0
                        dy = ref[j, 1] - xi1
                        dz = ref[j, 2] - xi2
                        reach = ri + r[j]
                        if dx * dx + dy * dy + dz * dz < reach * reach:
                            if k >= buf.shape[0]:
                                return -1
                            buf[k] = j
                            k += 1
                    j = nxt[j]
    return k


@numba.njit(inline="always", cache=True)
def _find(row, n, i):
    for s in range(n):
        if row[s] == i:
            return s
    return -1


@numba.njit(inline="always", cache=True)
def _row_insert(j, i, nbr, cnt, shear, touch, frozen, below):
    """Put partner i into row j at its place in ascending order, zero history (``below[j]`` kept
    a count of leading slots that hold active partners below j)."""
    u = cnt[j]
    while u > 0 and nbr[j, u - 1] > i:
        nbr[j, u] = nbr[j, u - 1]
        shear[j, u, 0], shear[j, u, 1], shear[j, u, 2] = shear[j, u - 1, 0], shear[j, u - 1, 1], shear[j, u - 1, 2]
        touch[j, u] = touch[j, u - 1]
        u -= 1
    nbr[j, u] = i
    shear[j, u, 0] = shear[j, u, 1] = shear[j, u, 2] = 0.0
    touch[j, u] = 0
    cnt[j] += 1
    if u <= below[j]:
        if i < j and not frozen[i]:
            below[j] += 1
        else:
            below[j] = u


@numba.njit(inline="always", cache=True)
def _row_delete(j, i, nbr, cnt, shear, touch, below):
    """Take partner i out of row j (the rest keep their order)."""
    n = cnt[j]
    u = _find(nbr[j], n, i)
    if u < below[j]:
        below[j] -= 1
    for t in range(u, n - 1):
        nbr[j, t] = nbr[j, t + 1]
        shear[j, t, 0], shear[j, t, 1], shear[j, t, 2] = shear[j, t + 1, 0], shear[j, t + 1, 1], shear[j, t + 1, 2]
        touch[j, t] = touch[j, t + 1]
    cnt[j] = n - 1


@numba.njit(cache=True)
def relist(moved, n_moved, first, x, ref, r, gid, skin, lo, cell, dims, head, nxt, prv, cellof,
           nbr, cnt, shear, touch, mark, buf, tmp_j, tmp_h, wall_kind, wall_normal, wall_offset, wall_cyl, wall_touch, wall_shear, near, frozen, below):
    """New reference, row and wall flag (:func:`dem._kernels.flag_walls`) for each sphere
    ``moved[first:n_moved]`` (module notes), in order.

    Pairs kept keep their slots' history; new pairs start from zero (they did not touch: their
    references were farther apart than the reach); pairs dropped leave both rows. Returns the
    index of the first sphere not done (``n_moved`` when all are): a row that would outgrow
    ``nbr``'s width stops the pass, to be resumed after the caller widens the rows.
    """
    cap = nbr.shape[1]
    for k in range(first, n_moved):
        i = moved[k]
        m = _scan(i, x[i, 0], x[i, 1], x[i, 2], ref, r, gid, skin, lo, cell, dims, head, nxt, buf)
        if m < 0 or m > cap:
            return k
        for s in range(m):
            if cnt[buf[s]] >= cap:
                return k
        # reference and cell
        ref[i, 0], ref[i, 1], ref[i, 2] = x[i, 0], x[i, 1], x[i, 2]
        flag_walls(i, ref, r, skin, wall_kind, wall_normal, wall_offset, wall_cyl, wall_touch, wall_shear, near)
        c = _cell(x[i, 0], x[i, 1], x[i, 2], lo, cell, dims)
        if cellof[i] != c:
            _grid_remove(i, head, nxt, prv, cellof)
            _grid_insert(i, c, head, nxt, prv, cellof)
        for s in range(cnt[i]):
            mark[nbr[i, s]] = s + 1
        for s in range(1, m):               # the row in ascending order (a dozen or two: insertion sort)
            v = buf[s]
            t = s - 1
            while t >= 0 and buf[t] > v:
                buf[t + 1] = buf[t]
                t -= 1
            buf[t + 1] = v
        for t in range(m):
            j = buf[t]
            tmp_j[t] = j
            s = mark[j] - 1
            if s >= 0:                      # kept: its history moves with it
                tmp_h[t, 0], tmp_h[t, 1], tmp_h[t, 2] = shear[i, s, 0], shear[i, s, 1], shear[i, s, 2]
                tmp_h[t, 3] = touch[i, s]
                mark[j] = -1
            else:                           # new: zero history, in j's row too
                tmp_h[t, 0] = tmp_h[t, 1] = tmp_h[t, 2] = tmp_h[t, 3] = 0.0
                _row_insert(j, i, nbr, cnt, shear, touch, frozen, below)
        for s in range(cnt[i]):             # dropped: out of j's row
            j = nbr[i, s]
            if mark[j] > 0:
                _row_delete(j, i, nbr, cnt, shear, touch, below)
            mark[j] = 0
        for t in range(m):
            nbr[i, t] = tmp_j[t]
            shear[i, t, 0], shear[i, t, 1], shear[i, t, 2] = tmp_h[t, 0], tmp_h[t, 1], tmp_h[t, 2]
            touch[i, t] = np.uint8(tmp_h[t, 3])
        cnt[i] = m
        below[i] = _below(i, frozen, nbr, m)
    return n_moved


@numba.njit(inline="always", cache=True)
def _below(i, frozen, nbr, n):
    """Leading slots of row i (``n`` partners, ascending) that hold active partners below i."""
    u = 0
    while u < n and nbr[i, u] < i and not frozen[nbr[i, u]]:
        u += 1
    return u


@numba.njit(cache=True)
def row_starts(n, frozen, nbr, cnt, below):
    """``below[:n]`` of every row (:func:`_below`), after the frozen set changed."""
    for i in range(n):
        below[i] = _below(i, frozen, nbr, cnt[i])


# ---------------------------------------------------------------------------- the step
@numba.njit(inline="always", cache=True, error_model="numpy")
def pair_dashpots(mi, mj, beta, kn, ks):
    r"""Normal and shear dashpots of a pair of masses ``mi``, ``mj`` (kg), N·s/m:
    :math:`c = 2\beta\sqrt{m^* k}`, :math:`m^* = m_i m_j/(m_i + m_j)` (the operations of
    :func:`dem._kernels.pair_damping`, so the same bits)."""
    meff = mi * mj / (mi + mj)
    return 2.0 * beta * np.sqrt(meff * kn), 2.0 * beta * np.sqrt(meff * ks)



@numba.njit(cache=True, error_model="numpy")
def active_poses(gidx, X, V, q, L, inertia, start, body, x, v, w, arm, ref, half_skin, moved):
    """Sphere state of the active grains ``gidx`` (:func:`dem._grain_kernels.pose_one`); the
    spheres farther than ``half_skin`` from their reference are written to ``moved``; returns
    their count."""
    n = 0
    h2 = half_skin * half_skin
    for a in range(gidx.shape[0]):
        g = gidx[a]
        pose_one(g, X, V, q, L, inertia, start, body, x, v, w, arm)
        for s in range(start[g], start[g + 1]):
            dx = x[s, 0] - ref[s, 0]
            dy = x[s, 1] - ref[s, 1]
            dz = x[s, 2] - ref[s, 2]
            if not dx * dx + dy * dy + dz * dz <= h2:     # also a new sphere (reference at infinity)
                moved[n] = s
                n += 1
    return n


@numba.njit(cache=True, error_model="numpy")
def active_forces(sidx, frozen, gid, x, v, w, r, ms, nbr, cnt, below, shear, touch, beta, dash, kn, ks, mu, dt,
                  near, wall_kind, wall_normal, wall_offset, wall_cyl, wall_moves, wall_vz, wall_shear, wall_fn,
                  wall_touch, kn_w, ks_w, beta_w, mu_w, force_s, torque_s, push, X, V, q, L, inertia, start, arm,
                  weight, inv_m, force_g, torque_g, advance, mu_r, mu_rw, roll_s, fn_sum):
    """Contact forces of the active spheres ``sidx`` (ascending; each pair from its evaluator's
    row, the row's first ``below`` slots skipped), their walls (of the spheres ``near`` one), and
    the sums and update of their grains (module notes). ``push`` (G,) gets, for each frozen
    grain, the largest normal force of an active neighbour, N; ``fn_sum`` (2,) the sum of the
    normal forces of the touching pairs evaluated, N, and their count. The dashpots of a pair
    are :func:`pair_dashpots` of its masses, or ``dash`` (2,) when every sphere has the same
    mass (``dash[0]`` < 0 otherwise). ``roll_s`` (N,) gets each
    active sphere's summed rolling moment (pair contacts ``mu_r``, walls ``mu_rw``;
    :func:`dem._contacts.rolling_moment`), N·m, which the grain's sums turn into the torque
    against its spin (:func:`dem._grain_kernels.grain_rolling`).

    A sphere's force is complete when its row is done (the rows after it add only to partners
    above them), so each grain is summed (:func:`dem._grain_kernels.update_one`'s sums, in
    sphere order) and advanced (:func:`dem._grain_kernels.finish_grain`) after its last sphere.
    """
    for a in range(sidx.shape[0]):
        p = sidx[a]
        force_s[p, 0] = force_s[p, 1] = force_s[p, 2] = 0.0
        torque_s[p, 0] = torque_s[p, 1] = torque_s[p, 2] = 0.0
        roll_s[p] = 0.0
    rolling = mu_r > 0.0 or mu_rw > 0.0
    gfx = gfy = gfz = gtx = gty = gtz = gmr = 0.0
    total_fn, n_fn = 0.0, 0
    for a in range(sidx.shape[0]):
        i = sidx[a]
        ri = r[i]
        # rows before i have added their pairs with i (i > their owner); none after it does
        fx, fy, fz = force_s[i, 0], force_s[i, 1], force_s[i, 2]
        tqx, tqy, tqz = torque_s[i, 0], torque_s[i, 1], torque_s[i, 2]
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        vi0, vi1, vi2 = v[i, 0], v[i, 1], v[i, 2]
        wi0, wi1, wi2 = w[i, 0] * ri, w[i, 1] * ri, w[i, 2] * ri
        for s in range(below[i], cnt[i]):
            j = nbr[i, s]
            fj = frozen[j]
            if j < i and not fj:
                continue                     # evaluated from j's row
            dx = x[j, 0] - xi0
            dy = x[j, 1] - xi1
            dz = x[j, 2] - xi2
            dist2 = dx * dx + dy * dy + dz * dz
            rsum = ri + r[j]
            if not dist2 < rsum * rsum:
                if touch[i, s]:
                    touch[i, s] = 0
                    shear[i, s, 0] = shear[i, s, 1] = shear[i, s, 2] = 0.0
                continue
            touch[i, s] = 1
            dist = np.sqrt(dist2)
            nx = dx / dist
            ny = dy / dist
            nz = dz / dist
            ax = wi0 + w[j, 0] * r[j]
            ay = wi1 + w[j, 1] * r[j]
            az = wi2 + w[j, 2] * r[j]
            vx = vi0 - v[j, 0] + (ay * nz - az * ny)
            vy = vi1 - v[j, 1] + (az * nx - ax * nz)
            vz = vi2 - v[j, 2] + (ax * ny - ay * nx)
            if dash[0] >= 0.0:
                c_n, c_t = dash[0], dash[1]
            else:
                c_n, c_t = pair_dashpots(ms[i], ms[j], beta, kn, ks)
            out = contact_law(rsum - dist, nx, ny, nz, vx, vy, vz, shear[i, s, 0], shear[i, s, 1], shear[i, s, 2],
                              kn, ks, c_n, c_t, mu, dt)
            total_fn += out[3]
            n_fn += 1
            ftx, fty, ftz = out[4], out[5], out[6]
            shear[i, s, 0], shear[i, s, 1], shear[i, s, 2] = out[7], out[8], out[9]
            tx = ny * ftz - nz * fty
            ty = nz * ftx - nx * ftz
            tz = nx * fty - ny * ftx
            fx += out[0]
            fy += out[1]
            fz += out[2]
            tqx += tx * ri
            tqy += ty * ri
            tqz += tz * ri
            if rolling:
                roll_s[i] += rolling_moment(mu_r, out[3], ri)
                if not fj:
                    roll_s[j] += rolling_moment(mu_r, out[3], r[j])
            if fj:
                g = gid[j]
                if out[3] > push[g]:
                    push[g] = out[3]
            else:
                force_s[j, 0] -= out[0]
                force_s[j, 1] -= out[1]
                force_s[j, 2] -= out[2]
                torque_s[j, 0] += tx * r[j]
                torque_s[j, 1] += ty * r[j]
                torque_s[j, 2] += tz * r[j]
        if near[i]:
            wfx, wfy, wfz, wtx, wty, wtz, hits = wall_contacts(i, x, v, w, r, ms, wall_kind, wall_normal,
                                                               wall_offset, wall_cyl, wall_moves, wall_vz, wall_shear,
                                                               wall_fn, wall_touch, kn_w, ks_w, beta_w, mu_w, dt)
            if hits:
                fx += wfx
                fy += wfy
                fz += wfz
                tqx += wtx
                tqy += wty
                tqz += wtz
                if rolling:
                    roll_s[i] += wall_rolling(i, wall_touch, wall_fn, mu_rw, ri)
        force_s[i, 0], force_s[i, 1], force_s[i, 2] = fx, fy, fz
        torque_s[i, 0], torque_s[i, 1], torque_s[i, 2] = tqx, tqy, tqz
        # the grain's sums, sphere by sphere (update_one's order and operations)
        g = gid[i]
        if i == start[g]:
            gfx = gfy = gfz = 0.0
            gtx = gty = gtz = gmr = 0.0
        gfx += fx
        gfy += fy
        gfz += fz
        gtx += (arm[i, 1] * fz - arm[i, 2] * fy) + tqx
        gty += (arm[i, 2] * fx - arm[i, 0] * fz) + tqy
        gtz += (arm[i, 0] * fy - arm[i, 1] * fx) + tqz
        gmr += roll_s[i]
        if i == start[g + 1] - 1:
            finish_grain(g, gfx, gfy, gfz, gtx, gty, gtz, gmr, X, V, q, L, inertia, weight, inv_m, dt, force_g,
                         torque_g, advance)
    fn_sum[0], fn_sum[1] = total_fn, n_fn


@numba.njit(inline="always", cache=True)
def _evaluator(i, j, frozen):
    if frozen[i]:
        return -1 if frozen[j] else j
    if frozen[j]:
        return i
    return min(i, j)


@numba.njit(cache=True)
def sync_history(changed, frozen_before, nbr, cnt, shear, touch):
    """Copy each pair of the spheres ``changed`` from its evaluator's slot under ``frozen_before``
    to the other slot (module notes)."""
    for a in range(changed.shape[0]):
        i = changed[a]
        for s in range(cnt[i]):
            j = nbr[i, s]
            e = _evaluator(i, j, frozen_before)
            if e < 0:
                continue
            u = _find(nbr[j], cnt[j], i)
            if e == i:
                shear[j, u, 0], shear[j, u, 1], shear[j, u, 2] = shear[i, s, 0], shear[i, s, 1], shear[i, s, 2]
                touch[j, u] = touch[i, s]
            else:
                shear[i, s, 0], shear[i, s, 1], shear[i, s, 2] = shear[j, u, 0], shear[j, u, 1], shear[j, u, 2]
                touch[i, s] = touch[j, u]


@numba.njit(cache=True)
def load_history(pi, pj, hist, nbr, cnt, shear, touch):
    """Put the history ``hist`` (P, 4: shear spring, touching) of pairs (pi, pj) into both slots."""
    for k in range(pi.shape[0]):
        if hist[k, 3] == 0.0:
            continue
        i, j = pi[k], pj[k]
        s = _find(nbr[i], cnt[i], j)
        if s >= 0:
            shear[i, s, 0], shear[i, s, 1], shear[i, s, 2] = hist[k, 0], hist[k, 1], hist[k, 2]
            touch[i, s] = 1
        s = _find(nbr[j], cnt[j], i)
        if s >= 0:
            shear[j, s, 0], shear[j, s, 1], shear[j, s, 2] = hist[k, 0], hist[k, 1], hist[k, 2]
            touch[j, s] = 1


@numba.njit(cache=True)
def in_contact(sidx, frozen, nbr, cnt, touch, out):
    """``out`` (N,) bool: the spheres in contact with a sphere of another grain (from the
    evaluating rows of the active spheres ``sidx``; frozen spheres count as in contact)."""
    for a in range(sidx.shape[0]):
        i = sidx[a]
        for s in range(cnt[i]):
            j = nbr[i, s]
            if (j > i or frozen[j]) and touch[i, s]:
                out[i] = True
                out[j] = True
