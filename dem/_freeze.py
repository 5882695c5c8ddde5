r"""Stepping the active part of a grain bed: settled grains frozen, a neighbour list kept per sphere.

A poured bed is at rest a few kernel lengths below its surface while grains still rain onto it,
and a falling grain crosses the Verlet skin every few dozen steps. :class:`ActiveRegion` steps a
:class:`dem.clumps.ClumpSimulation` so that neither costs the whole bed (``docs/dem-fill.md``,
section Speed):

* **Frozen grains.** A frozen grain is not integrated (V = L = 0, its spheres fixed) and its
  contacts with other frozen grains are not evaluated; a contact between a frozen and an active
  grain is evaluated as against a fixed wall: the force acts on the active grain, and the frozen
  one records only the largest normal force an active neighbour pushed it with
  (:attr:`ActiveRegion.push_n`), which :class:`FreezePolicy` uses to release it.
* **A neighbour list per sphere.** Each sphere p has a reference position :math:`\mathbf x^{ref}_p`
  and a row of partners: every sphere q of another grain with
  :math:`|\mathbf x^{ref}_p - \mathbf x^{ref}_q| < r_p + r_q + s` (skin s). While every sphere is
  within s/2 of its reference, a pair not listed cannot touch:
  :math:`|\mathbf x_p - \mathbf x_q| \ge |\mathbf x^{ref}_p - \mathbf x^{ref}_q| - s \ge r_p + r_q`.
  A sphere that moves beyond s/2 gets a new reference and its row alone is searched again (a
  linked cell grid over the references, cells 2 r_max + s wide), so a falling grain costs its
  own row, not the bed's list.

Rows are kept in ascending order. Each pair is listed in both rows and carries its contact history (shear spring, touching flag,
normal force) in both slots; it is evaluated from one row only, the *evaluator*: min(p, q) when
both grains are active, the active one's row when one is frozen, none when both are. Whenever
the frozen set changes, each changed pair's history is copied from its old evaluator's slot to
the other, so the new evaluator continues it. The step is the engine's own: the contact law of
:func:`dem._contacts.contact_law`, the walls of :func:`dem._kernels.wall_contacts`, the rigid
update of :func:`dem._grain_kernels.update_one`, one thread, each sphere's forces summed in row
order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ._contacts import contact_law
from ._grain_kernels import pose_one, update_one
from ._kernels import wall_contacts
from ._rigid import quat_to_matrix

__all__ = ["ActiveRegion", "FreezePolicy", "FREEZE_DEPTH_LENGTHS"]

#: depth below the local surface, in kernel lengths, below which a slow grain may freeze
FREEZE_DEPTH_LENGTHS = 4.0


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
def _row_insert(j, i, a, b, nbr, cnt, shear, touch, fn, cn, ct):
    """Put partner i into row j at its place in ascending order, zero history, dashpots a, b."""
    u = cnt[j]
    while u > 0 and nbr[j, u - 1] > i:
        nbr[j, u] = nbr[j, u - 1]
        shear[j, u, 0], shear[j, u, 1], shear[j, u, 2] = shear[j, u - 1, 0], shear[j, u - 1, 1], shear[j, u - 1, 2]
        touch[j, u], fn[j, u], cn[j, u], ct[j, u] = touch[j, u - 1], fn[j, u - 1], cn[j, u - 1], ct[j, u - 1]
        u -= 1
    nbr[j, u] = i
    shear[j, u, 0] = shear[j, u, 1] = shear[j, u, 2] = 0.0
    touch[j, u] = 0
    fn[j, u] = 0.0
    cn[j, u], ct[j, u] = a, b
    cnt[j] += 1


@numba.njit(inline="always", cache=True)
def _row_delete(j, i, nbr, cnt, shear, touch, fn, cn, ct):
    """Take partner i out of row j (the rest keep their order)."""
    n = cnt[j]
    u = _find(nbr[j], n, i)
    for t in range(u, n - 1):
        nbr[j, t] = nbr[j, t + 1]
        shear[j, t, 0], shear[j, t, 1], shear[j, t, 2] = shear[j, t + 1, 0], shear[j, t + 1, 1], shear[j, t + 1, 2]
        touch[j, t], fn[j, t], cn[j, t], ct[j, t] = touch[j, t + 1], fn[j, t + 1], cn[j, t + 1], ct[j, t + 1]
    cnt[j] = n - 1


@numba.njit(cache=True)
def relist(moved, n_moved, first, x, ref, r, gid, ms, skin, lo, cell, dims, head, nxt, prv, cellof,
           nbr, cnt, shear, touch, fn, cn, ct, beta, kn, ks, mark, buf, tmp_j, tmp_h, tmp_c):
    """New reference and row for each sphere ``moved[first:n_moved]`` (module notes), in order.

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
                tmp_h[t, 3], tmp_h[t, 4] = touch[i, s], fn[i, s]
                tmp_c[t, 0], tmp_c[t, 1] = cn[i, s], ct[i, s]
                mark[j] = -1
            else:                           # new: zero history, in j's row too
                meff = ms[i] * ms[j] / (ms[i] + ms[j])
                a = 2.0 * beta * np.sqrt(meff * kn)
                b = 2.0 * beta * np.sqrt(meff * ks)
                tmp_h[t, 0] = tmp_h[t, 1] = tmp_h[t, 2] = tmp_h[t, 3] = tmp_h[t, 4] = 0.0
                tmp_c[t, 0], tmp_c[t, 1] = a, b
                _row_insert(j, i, a, b, nbr, cnt, shear, touch, fn, cn, ct)
        for s in range(cnt[i]):             # dropped: out of j's row
            j = nbr[i, s]
            if mark[j] > 0:
                _row_delete(j, i, nbr, cnt, shear, touch, fn, cn, ct)
            mark[j] = 0
        for t in range(m):
            nbr[i, t] = tmp_j[t]
            shear[i, t, 0], shear[i, t, 1], shear[i, t, 2] = tmp_h[t, 0], tmp_h[t, 1], tmp_h[t, 2]
            touch[i, t] = np.uint8(tmp_h[t, 3])
            fn[i, t] = tmp_h[t, 4]
            cn[i, t], ct[i, t] = tmp_c[t, 0], tmp_c[t, 1]
        cnt[i] = m
    return n_moved


# ---------------------------------------------------------------------------- the step
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
def active_forces(gidx, sidx, frozen, gid, x, v, w, r, ms, nbr, cnt, shear, touch, fn, cn, ct, kn, ks, mu, dt,
                  wall_kind, wall_normal, wall_offset, wall_cyl, wall_moves, wall_vz, wall_shear, wall_fn,
                  wall_touch, kn_w, ks_w, beta_w, mu_w, force_s, torque_s, push, X, V, q, L, inertia, start, arm,
                  weight, inv_m, force_g, torque_g, advance):
    """Contact forces of the active spheres ``sidx`` (each pair from its evaluator's row), their
    walls, and the sums and update of the active grains ``gidx`` (module notes). ``push`` (G,)
    gets, for each frozen grain, the largest normal force of an active neighbour, N."""
    for a in range(sidx.shape[0]):
        p = sidx[a]
        force_s[p, 0] = force_s[p, 1] = force_s[p, 2] = 0.0
        torque_s[p, 0] = torque_s[p, 1] = torque_s[p, 2] = 0.0
    for a in range(sidx.shape[0]):
        i = sidx[a]
        ri = r[i]
        # rows before i have added their pairs with i (i > their owner); none after it does
        fx, fy, fz = force_s[i, 0], force_s[i, 1], force_s[i, 2]
        tqx, tqy, tqz = torque_s[i, 0], torque_s[i, 1], torque_s[i, 2]
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        vi0, vi1, vi2 = v[i, 0], v[i, 1], v[i, 2]
        wi0, wi1, wi2 = w[i, 0] * ri, w[i, 1] * ri, w[i, 2] * ri
        for s in range(cnt[i]):
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
                    fn[i, s] = 0.0
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
            out = contact_law(rsum - dist, nx, ny, nz, vx, vy, vz, shear[i, s, 0], shear[i, s, 1], shear[i, s, 2],
                              kn, ks, cn[i, s], ct[i, s], mu, dt)
            fn[i, s] = out[3]
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
        wfx, wfy, wfz, wtx, wty, wtz, hits = wall_contacts(i, x, v, w, r, ms, wall_kind, wall_normal, wall_offset,
                                                           wall_cyl, wall_moves, wall_vz, wall_shear, wall_fn,
                                                           wall_touch, kn_w, ks_w, beta_w, mu_w, dt)
        if hits:
            fx += wfx
            fy += wfy
            fz += wfz
            tqx += wtx
            tqy += wty
            tqz += wtz
        force_s[i, 0], force_s[i, 1], force_s[i, 2] = fx, fy, fz
        torque_s[i, 0], torque_s[i, 1], torque_s[i, 2] = tqx, tqy, tqz
    for a in range(gidx.shape[0]):
        update_one(gidx[a], X, V, q, L, inertia, start, arm, force_s, torque_s, weight, inv_m, dt, force_g,
                   torque_g, advance)


@numba.njit(inline="always", cache=True)
def _evaluator(i, j, frozen):
    if frozen[i]:
        return -1 if frozen[j] else j
    if frozen[j]:
        return i
    return min(i, j)


@numba.njit(cache=True)
def sync_history(changed, frozen_before, nbr, cnt, shear, touch, fn):
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
                touch[j, u], fn[j, u] = touch[i, s], fn[i, s]
            else:
                shear[i, s, 0], shear[i, s, 1], shear[i, s, 2] = shear[j, u, 0], shear[j, u, 1], shear[j, u, 2]
                touch[i, s], fn[i, s] = touch[j, u], fn[j, u]


@numba.njit(cache=True)
def _load_history(pi, pj, hist, nbr, cnt, shear, touch):
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
def _in_contact(sidx, frozen, nbr, cnt, touch, out):
    """``out`` (N,) bool: the spheres in contact with a sphere of another grain (from the
    evaluating rows of the active spheres ``sidx``; frozen spheres count as in contact)."""
    for a in range(sidx.shape[0]):
        i = sidx[a]
        for s in range(cnt[i]):
            j = nbr[i, s]
            if (j > i or frozen[j]) and touch[i, s]:
                out[i] = True
                out[j] = True


@numba.njit(cache=True)
def _contact_sums(sidx, frozen, nbr, cnt, touch, fn):
    """(sum, count) of the normal forces of the touching pairs evaluated from the rows ``sidx``."""
    total, n = 0.0, 0
    for a in range(sidx.shape[0]):
        i = sidx[a]
        for s in range(cnt[i]):
            j = nbr[i, s]
            if (j > i or frozen[j]) and touch[i, s]:
                total += fn[i, s]
                n += 1
    return total, n


# ---------------------------------------------------------------------------- the region
class ActiveRegion:
    """The per-sphere neighbour rows and the frozen set of a :class:`dem.clumps.ClumpSimulation`
    (module notes); :meth:`step` replaces the simulation's step while it is attached.

    Parameters
    ----------
    sim : ClumpSimulation
        Its current contact springs are taken over (nothing frozen at first).
    capacity : int
        Spheres the rows are allocated for (grains added later up to this count need no copy).
    lo_m, hi_m : (3,) arrays
        Box of the cell grid, m (centres outside it go to its edge cells: still correct, slower).
    width : int
        Partners a row holds at first (a row that needs more widens every row by half).
    """

    def __init__(self, sim, *, capacity=None, lo_m, hi_m, width=24):
        n = sim.n
        cap_n = max(int(capacity or n), n)
        self.skin = float(sim.verlet.skin)
        self.cell = 2.0 * float(np.max(sim.radii)) + self.skin
        self.lo = np.asarray(lo_m, float) - self.cell
        hi = np.asarray(hi_m, float) + self.cell
        self.dims = np.maximum(np.ceil((hi - self.lo) / self.cell).astype(np.int64), 1)
        self.head = np.full(int(np.prod(self.dims)), -1, np.int64)
        self.nxt = np.full(cap_n, -1, np.int64)
        self.prv = np.full(cap_n, -1, np.int64)
        self.cellof = np.full(cap_n, -1, np.int64)
        self.ref = np.full((cap_n, 3), np.inf)
        self.nbr = np.zeros((cap_n, width), np.int64)
        self.cnt = np.zeros(cap_n, np.int64)
        self.shear = np.zeros((cap_n, width, 3))
        self.touch = np.zeros((cap_n, width), np.uint8)
        self.fn = np.zeros((cap_n, width))
        self.cn = np.zeros((cap_n, width))
        self.ct = np.zeros((cap_n, width))
        self.mark = np.zeros(cap_n, np.int64)
        self.moved = np.zeros(cap_n, np.int64)
        self.frozen_s = np.zeros(cap_n, np.bool_)
        self.frozen_g = np.zeros(0, np.bool_)
        self.push_n = np.zeros(0)
        self.n = 0
        self.relists = 0
        self.relisted_spheres = 0
        self.policy = None
        self.anchor_X = np.zeros((0, 3))
        self.anchor_q = np.zeros((0, 4))
        self.anchor_t = np.zeros(0)
        self.max_push_weights = 0.0
        self.frozen_events = 0
        self.released_events = 0
        self.active_particle_steps = 0
        self._attach(sim)
        # rows from scratch at the current positions, then the springs of sim's listed pairs
        self._relist_all(sim)
        vl = sim.verlet
        if len(vl.keys):
            pairs = np.column_stack([vl.keys // sim.n, vl.keys % sim.n])
            hist = np.column_stack([sim.shear, sim._touch]).astype(float)
            _load_history(pairs[:, 0].copy(), pairs[:, 1].copy(), hist, self.nbr, self.cnt, self.shear, self.touch)

    # -- bookkeeping
    def _attach(self, sim):
        """Bind to ``sim`` (the same grains, possibly more at the end)."""
        n, g = sim.n, sim.n_grains
        if n > len(self.ref):
            self._resize(n, self.nbr.shape[1])
        self.sim = sim
        self.n = n
        fg = np.zeros(g, np.bool_)
        fg[:len(self.frozen_g)] = self.frozen_g
        self.frozen_g = fg
        push = np.zeros(g)
        push[:len(self.push_n)] = self.push_n
        self.push_n = push
        k = len(self.anchor_t)
        self.anchor_X = np.vstack([self.anchor_X, sim.X[k:]])
        self.anchor_q = np.vstack([self.anchor_q, sim.q[k:]])
        self.anchor_t = np.concatenate([self.anchor_t, np.full(g - k, sim.time_s)])
        self.frozen_s[:n] = fg[sim.gid]
        self._indices()

    def _indices(self):
        self.gidx = np.flatnonzero(~self.frozen_g).astype(np.int64)
        self.sidx = np.flatnonzero(~self.frozen_s[:self.n]).astype(np.int64)

    def _resize(self, n, width):
        """Rows for ``n`` spheres, ``width`` partners each (contents kept)."""
        old_n, old_w = self.nbr.shape

        def grow(a, fill, shape):
            b = np.full(shape, fill, a.dtype)
            b[tuple(slice(0, s) for s in a.shape)] = a
            return b

        n = max(n, old_n)
        for name, fill in (("nbr", 0), ("touch", 0), ("fn", 0.0), ("cn", 0.0), ("ct", 0.0)):
            setattr(self, name, grow(getattr(self, name), fill, (n, width)))
        self.shear = grow(self.shear, 0.0, (n, width, 3))
        for name, fill in (("nxt", -1), ("prv", -1), ("cellof", -1), ("cnt", 0), ("mark", 0), ("moved", 0),
                           ("frozen_s", False)):
            setattr(self, name, grow(getattr(self, name), fill, (n,)))
        self.ref = grow(self.ref, np.inf, (n, 3))

    def _relist(self, moved, n_moved):
        sim, mat = self.sim, self.sim.material
        width = self.nbr.shape[1]
        buf = np.empty(2 * width, np.int64)
        k = 0
        while True:
            tmp_j = np.empty(width, np.int64)
            tmp_h = np.empty((width, 5))
            tmp_c = np.empty((width, 2))
            k = relist(moved, n_moved, k, sim._x, self.ref, sim.radii, sim.gid, sim._ms, self.skin, self.lo,
                       self.cell, self.dims, self.head, self.nxt, self.prv, self.cellof, self.nbr, self.cnt,
                       self.shear, self.touch, self.fn, self.cn, self.ct, mat.damping_ratio, mat.kn_pp, mat.ks_pp,
                       self.mark, buf, tmp_j, tmp_h, tmp_c)
            if k >= n_moved:
                break
            width = int(width * 1.5) + 1          # a row outgrew its width: widen, resume
            self._resize(len(self.ref), width)
            buf = np.empty(2 * width, np.int64)
        self.relists += 1
        self.relisted_spheres += n_moved

    def _relist_all(self, sim):
        """Every row from scratch at the current positions: the spheres enter one by one, each
        row searched against those already in (so every pair is found once, from both rows)."""
        self.head[:] = -1
        self.cellof[:] = -1
        self.cnt[:] = 0
        self.ref[:] = np.inf
        sim._poses()
        self._relist(np.arange(self.n, dtype=np.int64), self.n)

    def grown(self, sim):
        """This region bound to ``sim``: the same grains plus new ones at the end (their rows are
        searched at their first step)."""
        self._attach(sim)
        return self

    # -- the step
    def step(self):
        """One step of the active grains (module notes); returns the net force on every grain (G, 3)."""
        sim = self.sim
        self.active_particle_steps += len(self.sidx)
        n_moved = active_poses(self.gidx, sim.X, sim.V, sim.q, sim.L, sim._inertia_s, sim._start, sim.body,
                               sim._x, sim._v, sim._w, sim._arm, self.ref, 0.5 * self.skin, self.moved)
        if n_moved:
            self._relist(self.moved, n_moved)
        mat = sim.material
        active_forces(self.gidx, self.sidx, self.frozen_s, sim.gid, sim._x, sim._v, sim._w, sim.radii, sim._ms,
                      self.nbr, self.cnt, self.shear, self.touch, self.fn, self.cn, self.ct, mat.kn_pp, mat.ks_pp,
                      mat.friction, sim._dt, sim._wall_kind, sim._wall_normal, sim._wall_offsets(), sim._wall_cyl,
                      sim._wall_moves, sim.wall_vz_m_s, sim.wall_shear, sim._wall_fn, sim._wall_touch, mat.kn_pw,
                      mat.ks_pw, mat.wall_beta, mat.wall_friction, sim._force, sim._torque, self.push_n, sim.X,
                      sim.V, sim.q, sim.L, sim._inertia_s, sim._start, sim._arm, sim._weight, sim._inv_m_g,
                      sim._force_g, sim._torque_g, True)
        return sim._force_g

    def unbalanced_force_ratio(self):
        """Mean |net force| on the active grains over the mean normal force of their contacts
        (grain and wall); inf without contact."""
        sim = self.sim
        total, n = _contact_sums(self.sidx, self.frozen_s, self.nbr, self.cnt, self.touch, self.fn)
        wt = sim._wall_touch[:, self.sidx].view(bool)
        wf = sim._wall_fn[:, self.sidx][wt]
        n += len(wf)
        total += float(wf.sum())
        if n == 0 or total == 0 or len(self.gidx) == 0:
            return float("inf")
        return float(np.mean(np.linalg.norm(sim._force_g[self.gidx], axis=1)) / (total / n))

    # -- freezing
    def at_check(self):
        """Apply :attr:`policy` (a :class:`FreezePolicy`, or None: nothing freezes)."""
        if self.policy is not None:
            n_new, n_rel = self.policy.update(self)
            self.frozen_events += n_new
            self.released_events += n_rel

    @property
    def n_frozen(self):
        return int(self.frozen_g.sum())

    def set_frozen(self, frozen_g):
        """Freeze or release grains (``frozen_g`` (G,) bool): histories move to their new
        evaluators; a grain frozen now stops (V = L = 0, its spheres at rest in place)."""
        sim = self.sim
        frozen_g = np.asarray(frozen_g, bool)
        changed_g = np.flatnonzero(frozen_g != self.frozen_g)
        if len(changed_g) == 0:
            return
        before = self.frozen_s.copy()
        self.frozen_g = frozen_g.copy()
        self.frozen_s[:self.n] = frozen_g[sim.gid]
        changed_s = np.flatnonzero(before[:self.n] != self.frozen_s[:self.n]).astype(np.int64)
        sync_history(changed_s, before, self.nbr, self.cnt, self.shear, self.touch, self.fn)
        newly = changed_g[frozen_g[changed_g]]
        sim.V[newly] = 0.0
        sim.L[newly] = 0.0
        self.push_n[changed_g] = 0.0
        if len(newly):
            active_poses(newly.astype(np.int64), sim.X, sim.V, sim.q, sim.L, sim._inertia_s, sim._start, sim.body,
                         sim._x, sim._v, sim._w, sim._arm, self.ref, np.inf, self.moved)
            sim._force[changed_s[self.frozen_s[changed_s]]] = 0.0
        self._indices()

    def pair_history(self):
        """Every listed pair (i < j) with its history, after releasing all grains:
        (keys i*N+j sorted, (P, 4) shear spring and touching flag)."""
        self.set_frozen(np.zeros(self.sim.n_grains, bool))
        n = self.n
        cnt = self.cnt[:n]
        i = np.repeat(np.arange(n, dtype=np.int64), cnt)
        mask = np.arange(self.nbr.shape[1])[None, :] < cnt[:, None]
        j = self.nbr[:n][mask]
        sh = self.shear[:n][mask]
        tc = self.touch[:n][mask]
        own = i < j
        keys = i[own] * n + j[own]
        order = np.argsort(keys)
        return keys[order], np.column_stack([sh[own][order], tc[own][order]])

    def pairs(self):
        """(P, 2) listed pairs i < j (no grain frozen or not), sorted."""
        n = self.n
        cnt = self.cnt[:n]
        i = np.repeat(np.arange(n, dtype=np.int64), cnt)
        mask = np.arange(self.nbr.shape[1])[None, :] < cnt[:, None]
        j = self.nbr[:n][mask]
        own = i < j
        p = np.column_stack([i[own], j[own]])
        return p[np.lexsort((p[:, 1], p[:, 0]))]


@dataclass(frozen=True, kw_only=True)
class FreezePolicy:
    r"""When a grain freezes and when it is released (``docs/dem-fill.md``, section Speed).

    At each check of :meth:`dem.clumps.ClumpSimulation.run` an active grain freezes when

    * its centre lies more than ``depth_m`` below the local surface (the highest sphere top of
      the grains on the bed, touching another grain or a wall and not falling, over the 3 x 3
      lateral cells ``cell_m`` wide around it), and
    * over the last ``window_s`` it moved less than ``drift_m``, its centre and the tips of its
      long axis alike (:math:`|\Delta\mathbf X|` and :math:`\theta\,\ell/2`, θ the angle it
      turned, ℓ the kernel length), and it moves now slower than ``speed_m_s`` (centre,
      :math:`|\mathbf V|`, and tips, :math:`|\boldsymbol\omega|\,\ell/2`).

    A grain that drifts more starts its window again. A frozen grain is released when an active
    neighbour pushes it with a normal force above ``push_weights`` times its (scaled) weight.

    Parameters
    ----------
    depth_m : float
        Freezing depth below the local surface, m.
    drift_m : float
        Largest displacement over the window, m.
    window_s : float
        The window, s.
    speed_m_s : float
        Largest speed at freezing, m/s.
    push_weights : float
        Release force over the grain's weight.
    cell_m : float
        Lateral cell of the local surface, m.
    length_m : float
        Kernel length ℓ, m.
    falling_m_s : float
        Grains faster than this are falling (not part of the surface), m/s.
    """

    depth_m: float
    drift_m: float
    window_s: float
    speed_m_s: float
    push_weights: float
    cell_m: float
    length_m: float
    falling_m_s: float

    def update(self, region):
        """Freeze and release grains of ``region`` at a check (its anchors: where and when each
        grain's window began). Returns (grains frozen now, grains released)."""
        sim = region.sim
        frozen = region.frozen_g.copy()
        push = region.push_n / sim._weight
        if frozen.any():
            region.max_push_weights = max(region.max_push_weights, float(push[frozen].max()))
        release = frozen & (push > self.push_weights)
        region.push_n[:] = 0.0
        frozen[release] = False
        now = sim.time_s
        region.anchor_t[release] = now          # a released grain starts a new window
        region.anchor_X[release] = sim.X[release]
        region.anchor_q[release] = sim.q[release]
        act = np.flatnonzero(~frozen)
        if len(act):
            tip = 0.5 * self.length_m
            drift = np.linalg.norm(sim.X[act] - region.anchor_X[act], axis=1)
            turn = 2.0 * np.arccos(np.clip(np.abs(np.sum(sim.q[act] * region.anchor_q[act], axis=1)), 0.0, 1.0))
            moved = ~((drift <= self.drift_m) & (turn * tip <= self.drift_m))
            restart = act[moved]
            region.anchor_X[restart] = sim.X[restart]
            region.anchor_q[restart] = sim.q[restart]
            region.anchor_t[restart] = now
            cand = act[~moved & (now - region.anchor_t[act] >= self.window_s)]
            if len(cand):
                v = np.linalg.norm(sim.V[cand], axis=1)
                w = np.linalg.norm(_omega_of(sim, cand), axis=1) * tip
                cand = cand[(v < self.speed_m_s) & (w < self.speed_m_s)]
            if len(cand):
                depth = self._local_surface(region, sim.X[cand, :2]) - sim.X[cand, 2]
                frozen[cand[depth > self.depth_m]] = True
        n_new = int(np.sum(frozen & ~region.frozen_g))
        region.set_frozen(frozen)
        return n_new, int(release.sum())

    def _local_surface(self, region, xy):
        """Highest sphere top of the grains on the bed (touching another grain or a wall, not
        falling: a kernel in a rebound's flight is not the surface) over the 3 x 3 cells around
        each point, m."""
        sim = region.sim
        xs, r = sim._x, sim.radii
        touching = region.frozen_s[:sim.n].copy()
        _in_contact(region.sidx, region.frozen_s, region.nbr, region.cnt, region.touch, touching)
        touching |= sim._wall_touch.any(axis=0).astype(bool)
        on_bed = np.zeros(sim.n_grains, bool)
        on_bed[sim.gid[touching]] = True
        keep = (on_bed & (np.linalg.norm(sim.V, axis=1) < self.falling_m_s))[sim.gid]
        lo = np.min(xs[:, :2], axis=0) - self.cell_m
        nc = np.floor((np.max(xs[:, :2], axis=0) + self.cell_m - lo) / self.cell_m).astype(int) + 1
        top = np.full((nc[0] + 2, nc[1] + 2), -np.inf)
        ij = np.floor((xs[keep, :2] - lo) / self.cell_m).astype(int) + 1
        np.maximum.at(top, (ij[:, 0], ij[:, 1]), xs[keep, 2] + r[keep])
        loc = top.copy()
        for a in (-1, 0, 1):
            for b in (-1, 0, 1):
                loc[1:-1, 1:-1] = np.maximum(loc[1:-1, 1:-1], top[1 + a:nc[0] + 1 + a, 1 + b:nc[1] + 1 + b])
        gij = np.floor((xy - lo) / self.cell_m).astype(int) + 1
        return loc[gij[:, 0], gij[:, 1]]


def _omega_of(sim, g):
    """(len(g), 3) angular velocities of grains ``g``, rad/s."""
    rot = quat_to_matrix(sim.q[g])
    lb = np.einsum("gji,gj->gi", rot, sim.L[g]) / (sim.inertia[g] * sim.mass_scale)
    return np.einsum("gij,gj->gi", rot, lb)
