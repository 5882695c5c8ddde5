r"""Rigid multi-sphere grains (clumps): a SEPARATE engine beside the sphere :class:`~dem.Simulation`.

Issue 15 wants one code path (a sphere as the one-sphere template); this engine is not yet that
path: the compiled sphere step (:mod:`dem._kernels`) is unchanged and the sphere packings keep
their bits, while this numpy engine steps grains. It uses the same contact law
(:func:`dem.linear_contact_forces`, the array form of the kernels' ``contact_law``), the same
stiffnesses, friction, shear-spring history (per sphere pair, carried over Verlet rebuilds) and
dashpots :math:`c = 2\beta\sqrt{m^* k}`, with m* from the two grains' (scaled) masses. One-sphere
templates reproduce the sphere engine to round-off (``tests/test_dem_clumps.py``).

Each step: sphere centres :math:`x_s = X_g + R(q_g) b_s`; contacts only between spheres of
different grains and with the walls; the contact point of sphere s is :math:`x_s + r_s n`, its
velocity :math:`V_g + \omega_g\times(x_s + r_s n - X_g)`; forces and torques
:math:`(x_s + r_s n - X_g)\times F` summed per grain. Update (semi-implicit Euler for translation,
the angular momentum L in the world frame, the orientation by a midpoint rotation):

.. math::

    V \mathrel{+}= F\,\Delta t/(S m), \quad X \mathrel{+}= V\Delta t, \quad L \mathrel{+}= T\Delta t,\quad
    \omega(q) = R\,(S I)^{-1} R^T L,\quad
    q_{1/2} = e^{\omega(q)\Delta t/2} q,\quad q \leftarrow e^{\omega(q_{1/2})\Delta t} q .

L is conserved exactly without torque; the kinetic energy of a free asymmetric top is conserved
to second order in Δt (measured in ``docs/dem-clumps.md``). Δt as the sphere engine's with the
mass of the smallest sphere of any grain.
"""

from __future__ import annotations

import numpy as np

from ._contacts import linear_contact_forces
from ._integrate import DemInstabilityError
from ._material import SOYBEAN, Material
from ._neighbors import VerletList, remap_history
from ._rigid import quat_exp, quat_multiply, quat_to_matrix
from ._walls import CylinderWall, PlaneWall

__all__ = ["ClumpSimulation"]


def _cross(a, b):
    return np.cross(a, b)


class ClumpSimulation:
    """G rigid grains of overlapping spheres in a set of walls.

    Parameters
    ----------
    templates : list of Template
        The grain kinds (:mod:`dem.templates`), body frames.
    kind : (G,) int
        Template index of each grain.
    centers : (G, 3) array, m
    quaternions : (G, 4) array
        Orientations (w, x, y, z), body to world.
    scales : (G,) array
        Size of each grain relative to its template (growth scales the whole template).
    walls, material, gravity_m_s2, mass_scale, dt_safety : as :class:`dem.Simulation`.
    """

    def __init__(self, templates, kind, centers, quaternions, scales, walls, material=SOYBEAN, *,
                 gravity_m_s2=9.81, mass_scale=1.0, dt_safety=0.25, skin_m=None):
        if not isinstance(material, Material):
            raise TypeError(f"material must be a Material, got {type(material).__name__}")
        self.templates = list(templates)
        self.kind = np.asarray(kind, dtype=np.int64)
        g = len(self.kind)
        self.X = np.array(centers, dtype=float).reshape(g, 3)
        self.q = np.array(quaternions, dtype=float).reshape(g, 4)
        self.q /= np.linalg.norm(self.q, axis=1)[:, None]
        self.V = np.zeros((g, 3))
        self.L = np.zeros((g, 3))  # world-frame angular momentum (scaled inertia)
        self.material, self.gravity_m_s2 = material, float(gravity_m_s2)
        self.mass_scale, self.dt_safety = float(mass_scale), float(dt_safety)
        counts = np.array([self.templates[k].n for k in self.kind])
        self.gid = np.repeat(np.arange(g), counts)
        self._body0 = np.concatenate([self.templates[k].positions for k in self.kind]).reshape(-1, 3)
        self._r0 = np.concatenate([self.templates[k].radii for k in self.kind])
        self.time_s, self.steps = 0.0, 0
        self.stats = {"rebuilds": 0}
        self.set_scales(scales)
        skin = skin_m if skin_m is not None else 0.4 * float(self.radii.max())
        self.verlet = VerletList(skin)
        self._keys, self._hist = np.zeros(0, dtype=np.int64), np.zeros((0, 3))
        self.set_walls(walls)

    # ------------------------------------------------------------------ state
    @property
    def n_grains(self):
        return len(self.kind)

    def set_scales(self, scales):
        """Grow or shrink grains: positions and radii of every template scale together."""
        self.scales = np.broadcast_to(np.asarray(scales, dtype=float), (self.n_grains,)).copy()
        s = self.scales[self.gid]
        self.body = self._body0 * s[:, None]
        self.radii = self._r0 * s
        rho = self.material.density_kg_m3
        vol = np.array([self.templates[k].volume_m3 for k in self.kind]) * self.scales**3
        self.volume_m3 = vol
        self.mass = rho * vol
        self.inertia = rho * np.array([self.templates[k].inertia_unit for k in self.kind]) * self.scales[:, None] ** 5
        m_sphere_min = rho * 4.0 / 3.0 * np.pi * float(self.radii.min()) ** 3
        self.dt = self.dt_safety * float(np.sqrt(self.mass_scale * m_sphere_min /
                                                 max(self.material.kn_n_m, self.material.ks_n_m)))
        self._inv_m = self.dt / (self.mass * self.mass_scale)

    def set_material(self, material):
        self.material = material
        self.set_scales(self.scales)

    def set_walls(self, walls):
        self.walls = list(walls)
        for w in self.walls:
            if not isinstance(w, (PlaneWall, CylinderWall)):
                raise TypeError(f"unknown wall type {type(w).__name__}")
        self.wall_shear = np.zeros((len(self.walls), len(self.radii), 3))

    def sphere_centers(self):
        """(N, 3) world positions of all spheres, m."""
        return self.X[self.gid] + np.einsum("nij,nj->ni", quat_to_matrix(self.q)[self.gid], self.body)

    def omega(self, q=None):
        """(G, 3) angular velocities (world) from L at orientation q (default: the current one)."""
        rot = quat_to_matrix(self.q if q is None else q)
        lb = np.einsum("gji,gj->gi", rot, self.L) / (self.inertia * self.mass_scale)
        return np.einsum("gij,gj->gi", rot, lb)

    def kinetic_energy(self):
        """Translational + rotational kinetic energy with physical masses, J."""
        w = self.omega()
        return float(0.5 * np.sum(self.mass * np.sum(self.V**2, axis=1)) + 0.5 * np.sum(w * self.L) / self.mass_scale)

    # ------------------------------------------------------------------ forces
    def forces(self):
        """Net force and torque on every grain, (G, 3) each (scaled masses; advances the springs)."""
        x = self.sphere_centers()
        if self.verlet.needs_rebuild(x, self.radii):
            self.verlet.build(x, self.radii)
            self.stats["rebuilds"] += 1
        m, dt, g = self.material, self.dt, self.n_grains
        pairs = self.verlet.pairs
        pi, pj = pairs[:, 0], pairs[:, 1]
        keep = self.gid[pi] != self.gid[pj]
        pi, pj = pi[keep], pj[keep]
        keys = pi * len(self.radii) + pj
        d = x[pj] - x[pi]
        dist = np.sqrt(np.sum(d * d, axis=1))
        touch = dist < self.radii[pi] + self.radii[pj]
        pi, pj, keys, d, dist = pi[touch], pj[touch], keys[touch], d[touch], dist[touch]
        shear = remap_history(self._keys, self._hist, keys)
        n = d / dist[:, None]
        gi, gj = self.gid[pi], self.gid[pj]
        w = self.omega()
        arm_i = x[pi] + self.radii[pi, None] * n - self.X[gi]
        arm_j = x[pj] - self.radii[pj, None] * n - self.X[gj]
        v_rel = (self.V[gi] + _cross(w[gi], arm_i)) - (self.V[gj] + _cross(w[gj], arm_j))
        ms = self.mass * self.mass_scale
        meff = ms[gi] * ms[gj] / (ms[gi] + ms[gj])
        cn, ct = 2.0 * m.damping_ratio * np.sqrt(meff * m.kn_pp), 2.0 * m.damping_ratio * np.sqrt(meff * m.ks_pp)
        f, fn, _, xi = linear_contact_forces(self.radii[pi] + self.radii[pj] - dist, n.T, v_rel.T, shear.T,
                                             kn=m.kn_pp, ks=m.ks_pp, cn=cn, ct=ct, mu=m.friction, dt=dt)
        f = f.T
        self._keys, self._hist, self.contact_fn = keys, np.ascontiguousarray(xi.T), fn
        self.touching_grains = np.column_stack([gi, gj])
        force, torque = np.zeros((g, 3)), np.zeros((g, 3))
        ti, tj = _cross(arm_i, f), _cross(arm_j, -f)
        for c in range(3):
            force[:, c] = np.bincount(gi, f[:, c], g) - np.bincount(gj, f[:, c], g)
            torque[:, c] = np.bincount(gi, ti[:, c], g) + np.bincount(gj, tj[:, c], g)
        wall_fn = []
        for k, wall in enumerate(self.walls):
            if isinstance(wall, PlaneWall):
                nrm = np.asarray(wall.normal, dtype=float)
                ov = self.radii - (x @ nrm - float(np.asarray(wall.point_m, dtype=float) @ nrm))
                nw = np.broadcast_to(-nrm, x.shape)
            else:
                dd = x[:, :2] - np.asarray(wall.center_xy_m, dtype=float)
                rho = np.maximum(np.sqrt(np.sum(dd * dd, axis=1)), 1e-300)
                ov = self.radii - (wall.radius_m - rho)
                nw = np.column_stack([dd / rho[:, None], np.zeros(len(x))])
            hit = ov > 0
            self.wall_shear[k, ~hit] = 0.0
            s = np.flatnonzero(hit)
            if len(s) == 0:
                continue
            gs = self.gid[s]
            arm = x[s] + self.radii[s, None] * nw[s] - self.X[gs]
            vr = self.V[gs] + _cross(w[gs], arm)
            cn, ct = 2.0 * m.damping_ratio * np.sqrt(ms[gs] * m.kn_pw), 2.0 * m.damping_ratio * np.sqrt(ms[gs] * m.ks_pw)
            fw, fnw, _, xiw = linear_contact_forces(ov[s], np.ascontiguousarray(nw[s].T), vr.T, self.wall_shear[k, s].T,
                                                    kn=m.kn_pw, ks=m.ks_pw, cn=cn, ct=ct, mu=m.wall_friction, dt=dt)
            self.wall_shear[k, s] = xiw.T
            tw = _cross(arm, fw.T)
            for c in range(3):
                force[:, c] += np.bincount(gs, fw[c], g)
                torque[:, c] += np.bincount(gs, tw[:, c], g)
            wall_fn.append(fnw)
        self.last_wall_fn = np.concatenate(wall_fn) if wall_fn else np.zeros(0)
        force[:, 2] -= self.mass * (self.mass_scale * self.gravity_m_s2)
        return force, torque

    # ------------------------------------------------------------------ stepping
    def step(self):
        """Advance one time step (module notes); returns the net force on the grains, (G, 3)."""
        force, torque = self.forces()
        dt = self.dt
        self.V += force * self._inv_m[:, None]
        self.X += self.V * dt
        self.L += torque * dt
        q_half = quat_multiply(quat_exp(self.omega() * (0.5 * dt)), self.q)
        q = quat_multiply(quat_exp(self.omega(q_half) * dt), self.q)
        self.q = q / np.linalg.norm(q, axis=1)[:, None]
        self.time_s += dt
        self.steps += 1
        return force

    def unbalanced_force_ratio(self, force):
        """Mean |net force| on the grains over the mean normal contact force (0: equilibrium)."""
        fn = np.concatenate([self.contact_fn, self.last_wall_fn])
        if len(fn) == 0 or fn.mean() == 0:
            return float("inf")
        return float(np.mean(np.linalg.norm(force, axis=1)) / fn.mean())

    def check_stability(self, *, max_speed_m_s=20.0):
        if not (np.all(np.isfinite(self.X)) and np.all(np.isfinite(self.V))):
            raise DemInstabilityError(f"non-finite grain state at t = {self.time_s:.4g} s; reduce dt_safety")
        vmax = float(np.sqrt(np.max(np.sum(self.V**2, axis=1))))
        if vmax > max_speed_m_s:
            raise DemInstabilityError(f"a grain moves at {vmax:.3g} m/s at t = {self.time_s:.4g} s: energy blow-up")

    def run(self, *, max_steps, tol=None, check_every=200, grow_from=None, grow_to=None, callback=None):
        """Advance ``max_steps`` steps (or until the unbalanced-force ratio < ``tol``); optional growth
        of the grain scales from ``grow_from`` to ``grow_to`` over the run."""
        ratio, k = float("inf"), 0
        for k in range(1, max_steps + 1):
            if grow_from is not None:
                self.set_scales(grow_from + (k / max_steps) * (grow_to - grow_from))
            force = self.step()
            if k % check_every == 0:
                self.check_stability()
                ratio = self.unbalanced_force_ratio(force)
                if callback is not None:
                    callback(self, force)
                if tol is not None and ratio < tol:
                    return {"steps": k, "ratio": ratio, "converged": True}
        return {"steps": k, "ratio": ratio, "converged": tol is None}
