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
* **Walls only where they can touch.** With each new reference a sphere gets a wall flag: a
  wall lies within r_p + s of its reference. A sphere without one cannot touch a wall while it
  stays within s/2 of its reference (its distance to each wall is at least r_p + s/2), so its
  wall contacts are not evaluated; its wall springs were cleared when it lost the flag, as the
  step would clear them. When the walls move (the container's ``z_offset_m``, new walls) every
  flag is set again.

Rows are kept in ascending order. A pair's history (shear spring, touching flag) sits in both
its slots; it is evaluated from one row, the *evaluator*: min(p, q) when both grains are active,
the active one's row when one is frozen, none when both are (a change of the frozen set copies
each changed pair's history to its new evaluator's slot). A row's leading slots of active
partners below its sphere (``below``, kept with each insert, delete and frozen-set change) are
not read. The step is the engine's own (contact law :func:`dem._contacts.contact_law`, walls
:func:`dem._kernels.wall_contacts`, rigid update :func:`dem._grain_kernels.update_one`: its sums,
then :func:`dem._grain_kernels.advance_one`), one thread. The rows run in ascending order, so a
sphere's force is complete when its row is done (later rows add only to partners above them):
each grain is summed and advanced right after its last sphere, in update_one's operations and
order, bit for bit the trajectories of separate force and update passes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._freeze_kernels import (active_forces, active_poses, in_contact, load_history, pair_dashpots, relist,
                              row_starts, sync_history)
from ._kernels import list_walls
from ._rigid import quat_to_matrix

__all__ = ["ActiveRegion", "FreezePolicy", "FREEZE_DEPTH_LENGTHS"]

#: depth below the local surface, in kernel lengths, below which a slow grain may freeze
FREEZE_DEPTH_LENGTHS = 4.0


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
        self.below = np.zeros(cap_n, np.int64)
        self.shear = np.zeros((cap_n, width, 3))
        self.touch = np.zeros((cap_n, width), np.uint8)
        self.fn_sum = np.zeros(2)
        self._dash = np.full(2, -1.0)
        self._dash_for = (None, None)
        self.mark = np.zeros(cap_n, np.int64)
        self.moved = np.zeros(cap_n, np.int64)
        self.frozen_s = np.zeros(cap_n, np.bool_)
        self.near = np.ones(cap_n, np.bool_)
        self._walls_at = None
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
            load_history(pairs[:, 0].copy(), pairs[:, 1].copy(), hist, self.nbr, self.cnt, self.shear, self.touch)

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
        for name, fill in (("nbr", 0), ("touch", 0)):
            setattr(self, name, grow(getattr(self, name), fill, (n, width)))
        self.shear = grow(self.shear, 0.0, (n, width, 3))
        for name, fill in (("nxt", -1), ("prv", -1), ("cellof", -1), ("cnt", 0), ("below", 0), ("mark", 0),
                           ("moved", 0), ("frozen_s", False), ("near", True)):
            setattr(self, name, grow(getattr(self, name), fill, (n,)))
        self.ref = grow(self.ref, np.inf, (n, 3))

    def _relist(self, moved, n_moved):
        sim = self.sim
        k = 0
        while True:
            width = self.nbr.shape[1]
            buf, tmp_j, tmp_h = np.empty(2 * width, np.int64), np.empty(width, np.int64), np.empty((width, 4))
            k = relist(moved, n_moved, k, sim._x, self.ref, sim.radii, sim.gid, self.skin, self.lo, self.cell,
                       self.dims, self.head, self.nxt, self.prv, self.cellof, self.nbr, self.cnt, self.shear,
                       self.touch, self.mark, buf, tmp_j, tmp_h, sim._wall_kind, sim._wall_normal, self._walls_at,
                       sim._wall_cyl, sim._wall_touch, sim.wall_shear, self.near, self.frozen_s, self.below)
            if k >= n_moved:
                break
            self._resize(len(self.ref), int(width * 1.5) + 1)   # a row outgrew its width: widen, resume
        self.relists += 1
        self.relisted_spheres += n_moved

    def _relist_all(self, sim):
        """Every row from scratch at the current positions: the spheres enter one by one, each
        row searched against those already in (so every pair is found once, from both rows)."""
        self.head[:] = -1
        self.cellof[:] = -1
        self.cnt[:] = 0
        self.below[:] = 0
        self.ref[:] = np.inf
        sim._poses()
        self._walls_at = sim._wall_offsets()
        self._relist(np.arange(self.n, dtype=np.int64), self.n)

    def grown(self, sim):
        """This region bound to ``sim``: the same grains plus new ones at the end (their rows are
        searched at their first step)."""
        self._attach(sim)
        return self

    def _list_walls(self, offsets):
        """Every sphere's wall flag against the walls at ``offsets`` (after the walls moved, or a new
        simulation bound)."""
        sim = self.sim
        list_walls(np.arange(self.n, dtype=np.int64), self.ref, sim.radii, self.skin, sim._wall_kind,
                   sim._wall_normal, offsets, sim._wall_cyl, sim._wall_touch, sim.wall_shear, self.near)
        self._walls_at = offsets

    def _set_dashpots(self):
        """The pair dashpots when every sphere has the same mass (one value for every pair), else
        none (each pair's from its masses)."""
        sim, mat = self.sim, self.sim.material
        ms = sim._ms
        self._dash[:] = -1.0
        if len(ms) and np.all(ms == ms[0]):
            self._dash[:] = pair_dashpots(float(ms[0]), float(ms[0]), mat.damping_ratio, mat.kn_pp, mat.ks_pp)
        self._dash_for = (mat, ms)

    # -- the step
    def step(self):
        """One step of the active grains (module notes); returns the net force on every grain (G, 3)."""
        sim = self.sim
        self.active_particle_steps += len(self.sidx)
        offsets = sim._wall_offsets()
        if offsets is not self._walls_at:
            self._list_walls(offsets)
        n_moved = active_poses(self.gidx, sim.X, sim.V, sim.q, sim.L, sim._inertia_s, sim._start, sim.body,
                               sim._x, sim._v, sim._w, sim._arm, self.ref, 0.5 * self.skin, self.moved)
        if n_moved:
            self._relist(self.moved, n_moved)
        mat = sim.material
        if self._dash_for[0] is not mat or self._dash_for[1] is not sim._ms:
            self._set_dashpots()
        active_forces(self.sidx, self.frozen_s, sim.gid, sim._x, sim._v, sim._w, sim.radii, sim._ms, self.nbr,
                      self.cnt, self.below, self.shear, self.touch, mat.damping_ratio, self._dash, mat.kn_pp, mat.ks_pp,
                      mat.friction, sim._dt, self.near, sim._wall_kind, sim._wall_normal, offsets, sim._wall_cyl,
                      sim._wall_moves, sim.wall_vz_m_s, sim.wall_shear, sim._wall_fn, sim._wall_touch, mat.kn_pw,
                      mat.ks_pw, mat.wall_beta, mat.wall_friction, sim._force, sim._torque, self.push_n, sim.X,
                      sim.V, sim.q, sim.L, sim._inertia_s, sim._start, sim._arm, sim._weight, sim._inv_m_g,
                      sim._force_g, sim._torque_g, True, mat.rolling_friction, mat.wall_rolling_friction, sim._roll,
                      self.fn_sum)
        return sim._force_g

    def unbalanced_force_ratio(self):
        """Mean |net force| on the active grains over the mean normal force of their contacts
        (grain and wall); inf without contact."""
        sim = self.sim
        total, n = float(self.fn_sum[0]), int(self.fn_sum[1])
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
        sync_history(changed_s, before, self.nbr, self.cnt, self.shear, self.touch)
        row_starts(self.n, self.frozen_s, self.nbr, self.cnt, self.below)
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
        in_contact(region.sidx, region.frozen_s, region.nbr, region.cnt, region.touch, touching)
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
