r"""Rigid multi-sphere grains (clumps): the sphere step's kernels with a rigid-body update.

:class:`ClumpSimulation` is a :class:`dem.Simulation` whose spheres belong to rigid grains. Each
step runs three compiled passes (numba; ``docs/dem-clumps.md``, ``docs/dem-speed.md``):

1. :func:`dem._grain_kernels.grain_poses`: sphere centres :math:`x_s = X_g + R(q_g) b_s`,
   velocities :math:`V_g + \omega_g\times(x_s - X_g)` and spins :math:`\omega_g` from the grains;
2. the sphere step's own kernels (:func:`dem._kernels.pair_forces` with the per-pair shear-spring
   history, :func:`dem._kernels.particle_update` for the walls, without its update): the same
   contact law (:func:`dem._contacts.contact_law`), stiffnesses, friction and dashpots
   :math:`c = 2\beta\sqrt{m^* k}`, m* from the two grains' (scaled) masses. The Verlet list leaves
   out pairs of one grain (``VerletList(groups=...)``): contacts only between spheres of
   different grains and with the walls;
3. :func:`dem._grain_kernels.grain_update`: forces and torques :math:`(x_s + r_s n - X_g)\times F`
   summed per grain, then

.. math::

    V \mathrel{+}= F\,\Delta t/(S m), \quad X \mathrel{+}= V\Delta t, \quad L \mathrel{+}= T\Delta t,\quad
    \omega(q) = R\,(S I)^{-1} R^T L,\quad
    q_{1/2} = e^{\omega(q)\Delta t/2} q,\quad q \leftarrow e^{\omega(q_{1/2})\Delta t} q .

L (world frame) is conserved exactly without torque; the kinetic energy of a free asymmetric top
to second order in Δt. Δt as the sphere engine's with the mass of the smallest sphere of any
grain. One-sphere templates reproduce :class:`dem.Simulation` to round-off (the spin goes through
L and the inertia instead of ω += T Δt/I; ``tests/dem/test_dem_clumps.py``).
"""

from __future__ import annotations

import numpy as np

from ._freeze import ActiveRegion
from ._grain_kernels import grain_poses, grain_update
from ._integrate import DemInstabilityError, Simulation
from ._material import SOYBEAN, Material
from ._neighbors import VerletList
from ._rigid import quat_to_matrix

__all__ = ["ClumpSimulation", "GRAIN_SKIN_FRACTION"]

#: Default Verlet skin over the largest sphere radius for grains (spheres: 0.4). A soybean's six
#: spheres lie within 0.8 mm of its centre (radii 2.8-2.9 mm), so two touching grains list up to
#: 36 sphere pairs. The 253-grain `dem.pack --scene box --grain soybean` bed (21 400 steps, the
#: same bits at every skin) takes about a fifth less CPU time at 0.2 than at 0.4, and no less at 0.1.
GRAIN_SKIN_FRACTION = 0.2


class ClumpSimulation(Simulation):
    """G rigid grains of overlapping spheres in a set of walls.

    The grain state is ``X`` (G, 3) m, ``V`` (G, 3) m/s, ``q`` (G, 4) (w, x, y, z), ``L`` (G, 3)
    world angular momentum with scaled inertia, kg m²/s (all writable in place). The inherited
    ``centers``, ``velocities``, ``spins`` are the spheres' state at the last force evaluation
    (rebuilt from the grains every step; writing them changes nothing).

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
    walls, material, gravity_m_s2, mass_scale, dt_safety, threads : as :class:`dem.Simulation`.
    skin_m : float | None
        Verlet skin, m; default :data:`GRAIN_SKIN_FRACTION` times the largest sphere radius.
    """

    def __init__(self, templates, kind, centers, quaternions, scales, walls, material=SOYBEAN, *,
                 gravity_m_s2=9.81, mass_scale=1.0, dt_safety=0.25, skin_m=None, threads=None):
        if not isinstance(material, Material):
            raise TypeError(f"material must be a Material, got {type(material).__name__}")
        self.templates = list(templates)
        self.kind = np.asarray(kind, dtype=np.int64).ravel()
        g = len(self.kind)
        self.X = np.array(centers, dtype=float).reshape(g, 3)
        self.q = np.array(quaternions, dtype=float).reshape(g, 4)
        self.q /= np.linalg.norm(self.q, axis=1)[:, None]
        self.V = np.zeros((g, 3))
        self.L = np.zeros((g, 3))
        counts = np.array([self.templates[k].n for k in self.kind], dtype=np.int64)
        self.gid = np.repeat(np.arange(g), counts)
        self._start = np.zeros(g + 1, dtype=np.int64)
        np.cumsum(counts, out=self._start[1:])
        self._body0 = np.concatenate([self.templates[k].positions for k in self.kind]).reshape(-1, 3)
        self._r0 = np.concatenate([self.templates[k].radii for k in self.kind])
        self._vol0 = np.array([self.templates[k].volume_m3 for k in self.kind], dtype=float)
        self._inertia0 = np.array([self.templates[k].inertia_unit for k in self.kind], dtype=float).reshape(g, 3)
        self.scales = np.broadcast_to(np.asarray(scales, dtype=float), (g,)).copy()
        self._force_g, self._torque_g = np.zeros((g, 3)), np.zeros((g, 3))
        self.material, self.gravity_m_s2 = material, float(gravity_m_s2)  # read by _set_radii below
        radii = self._r0 * self.scales[self.gid]
        self._arm = np.zeros((len(radii), 3))
        super().__init__(np.zeros((len(radii), 3)), radii, walls, material, gravity_m_s2=gravity_m_s2,
                         mass_scale=mass_scale, dt_safety=dt_safety, threads=threads,
                         skin_m=skin_m if skin_m is not None else GRAIN_SKIN_FRACTION * float(radii.max()))
        self.verlet = VerletList(self.verlet.skin, groups=self.gid)
        self.active = None
        self._poses()

    # ------------------------------------------------------------------ state
    @property
    def n_grains(self):
        return len(self.kind)

    def _set_radii(self, radii):
        """Sphere radii and the grains' masses (from :attr:`scales`), time step, kernel factors."""
        self.radii = np.asarray(radii, dtype=float)
        s = self.scales[self.gid]
        self.body = self._body0 * s[:, None]
        rho = self.material.density_kg_m3
        self.volume_m3 = self._vol0 * self.scales**3
        self.mass = rho * self.volume_m3
        self.inertia = rho * self._inertia0 * self.scales[:, None] ** 5
        m_sphere_min = rho * 4.0 / 3.0 * np.pi * float(self.radii.min()) ** 3
        self._dt = self.dt_safety * float(np.sqrt(self.mass_scale * m_sphere_min /
                                                  max(self.material.kn_n_m, self.material.ks_n_m)))
        self._inv_m_g = self._dt / (self.mass * self.mass_scale)
        self._inertia_s = self.inertia * self.mass_scale
        self._weight = self.mass * (self.mass_scale * self.gravity_m_s2)
        # per sphere: the grain's scaled mass (dashpots); weight and update belong to the grain
        self._ms = (self.mass * self.mass_scale)[self.gid]
        self._gforce = np.zeros(len(self.radii))
        self._inv_m = self._inv_i = self._gforce
        self._coef_valid = False

    def set_scales(self, scales):
        """Grow or shrink grains: positions and radii of every template scale together."""
        self.scales = np.broadcast_to(np.asarray(scales, dtype=float), (self.n_grains,)).copy()
        self._set_radii(self._r0 * self.scales[self.gid])

    def _poses(self):
        grain_poses(self.X, self.V, self.q, self.L, self._inertia_s, self._start, self.body, self._x, self._v,
                    self._w, self._arm)

    def sphere_centers(self):
        """(N, 3) world positions of all spheres, m."""
        self._poses()
        return self._x.copy()

    @property
    def touching_grains(self):
        """(Nc, 2) grain ids of the touching sphere pairs at the last evaluation."""
        return self.gid[self.touching_pairs]

    def omega(self, q=None):
        """(G, 3) angular velocities (world) from L at orientation q (default: the current one)."""
        rot = quat_to_matrix(self.q if q is None else q)
        lb = np.einsum("gji,gj->gi", rot, self.L) / (self.inertia * self.mass_scale)
        return np.einsum("gij,gj->gi", rot, lb)

    def kinetic_energy(self):
        """Translational + rotational kinetic energy with physical masses, J."""
        w = self.omega()
        return float(0.5 * np.sum(self.mass * np.sum(self.V**2, axis=1)) + 0.5 * np.sum(w * self.L) / self.mass_scale)

    def get_state(self):
        """:meth:`dem.Simulation.get_state` plus the grains' X, V, q, L and scales."""
        state = super().get_state()
        state.update(grain_X=self.X.copy(), grain_V=self.V.copy(), grain_q=self.q.copy(), grain_L=self.L.copy(),
                     grain_scales=self.scales.copy())
        return state

    def set_state(self, state):
        """Continue from :meth:`get_state` (same grains, walls and material)."""
        if np.shape(state.get("grain_X")) != self.X.shape:
            raise ValueError(f"state of {np.shape(state.get('grain_X'))} grain centres does not fit "
                             f"{self.n_grains} grains")
        self.X[:], self.V[:], self.q[:], self.L[:] = state["grain_X"], state["grain_V"], state["grain_q"], state["grain_L"]
        self.scales = np.array(state["grain_scales"], dtype=float)
        super().set_state(state)

    # ------------------------------------------------------------------ forces and stepping
    def _step_kernels(self, advance):
        """The sphere step's kernels without their update, then the grains' sums and update."""
        super()._step_kernels(False)
        grain_update(self.X, self.V, self.q, self.L, self._inertia_s, self._start, self._arm, self._force,
                     self._torque, self._roll, self._weight, self._inv_m_g, self._dt, self._force_g, self._torque_g,
                     advance)

    def attach_active(self, *, lo_m, hi_m, capacity=None, policy=None):
        """Step the active grains only, with per-sphere neighbour rows (:class:`dem._freeze.ActiveRegion`,
        box ``lo_m``-``hi_m`` of its cell grid, rows for ``capacity`` spheres); ``policy``
        (:class:`dem._freeze.FreezePolicy`) freezes and releases grains at each check of :meth:`run`."""
        self.active = ActiveRegion(self, capacity=capacity, lo_m=lo_m, hi_m=hi_m)
        self.active.policy = policy
        return self.active

    def detach_active(self):
        """Release every frozen grain and step the whole bed again; the contact springs are kept
        (the Verlet list is rebuilt at the next step from the rows' pairs)."""
        if self.active is None:
            return
        keys, hist = self.active.pair_history()
        self.active = None
        self.verlet.keys = keys
        self.shear = np.ascontiguousarray(hist[:, :3])
        self._touch = hist[:, 3].astype(np.uint8)
        self.verlet._ref = None
        self._coef_valid = False

    def _grain_pass(self, advance):
        self._poses()
        self._evaluate(advance)

    def forces(self):
        """Net force and torque on every grain, (G, 3) each (scaled masses; advances the springs)."""
        self._grain_pass(False)
        return self._force_g.copy(), self._torque_g.copy()

    def step(self):
        """Advance one time step (module notes); returns the net force on the grains, (G, 3)."""
        if self.active is not None:
            force = self.active.step()
            self.time_s += self._dt
            self.steps += 1
            return force
        self._grain_pass(True)
        self.time_s += self._dt
        self.steps += 1
        return self._force_g

    def unbalanced_force_ratio(self, force):
        """Mean |net force| on the grains over the mean normal contact force (0: equilibrium);
        while frozen grains are held (:meth:`attach_active`), over the active grains and their contacts."""
        if self.active is not None:
            return self.active.unbalanced_force_ratio()
        fn = np.concatenate([self.contact_fn, self.last_wall_fn])
        if len(fn) == 0 or fn.mean() == 0:
            return float("inf")
        return float(np.mean(np.linalg.norm(force, axis=1)) / fn.mean())

    def check_stability(self, *, max_speed_m_s=20.0):
        """Raise DemInstabilityError on a non-finite grain state or a grain faster than ``max_speed_m_s``."""
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
                if self.active is not None:
                    self.active.at_check()
                if callback is not None:
                    callback(self, force)
                if tol is not None and ratio < tol:
                    return {"steps": k, "ratio": ratio, "converged": True}
        return {"steps": k, "ratio": ratio, "converged": tol is None}
