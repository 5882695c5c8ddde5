r"""Soft-sphere DEM state and time integration (the four-step loop of STYLE.md item 11).

Each step: (1) candidate pairs from the Verlet list (:mod:`dem._neighbors`, rebuilt when a
particle moved more than skin/2); (2) the linear contact law of :mod:`dem._contacts` for
particle–particle and particle–wall contacts; (3) forces and torques summed per particle in a
fixed order; (4) semi-implicit (symplectic) Euler update of velocities, spins and positions.
Steps 2–4 are the two compiled loops of :mod:`dem._kernels`:

.. math::

    \mathbf v^{n+1/2} = \mathbf v^{n-1/2} + \frac{\mathbf F^n}{m}\Delta t, \quad
    \mathbf x^{n+1} = \mathbf x^n + \mathbf v^{n+1/2}\Delta t, \quad
    \boldsymbol\omega^{n+1/2} = \boldsymbol\omega^{n-1/2} + \frac{\mathbf T^n}{I}\Delta t,
    \quad I = \tfrac25 m r^2 .

Time step: :math:`\Delta t = s\,\sqrt{m_{min}/k_{n}}` with the particle normal stiffness
k_n (≥ the contact stiffness) and a safety factor s (default 0.25).

Quasi-static acceleration (density scaling): ``mass_scale`` S multiplies every mass and
moment of inertia while gravity stays g. Motion under gravity is unchanged, but contact
oscillations are √S slower, so Δt grows by √S; it is equivalent to dividing all
stiffnesses by S (overlaps under load grow S-fold). Used only where the path to a
static state does not matter (radius expansion, settling); its effect is measured in
``dem.bench``.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from ._kernels import pair_damping, pair_forces, particle_update
from ._material import SOYBEAN, Material
from ._neighbors import VerletList, remap_history
from ._threads import ThreadChooser
from ._walls import CylinderWall, PlaneWall

__all__ = ["Simulation", "DemInstabilityError"]

log = logging.getLogger(__name__)

#: Default Verlet skin over the largest radius. Measured (CPU time, same packing bit for bit):
#: 823-sphere 'sediment' pack 6.6e6 particle-steps/s at 0.1 (1138 rebuilds), 8.0e6 at 0.2,
#: 8.1-8.9e6 at 0.4 (283), 9.0e6 at 0.6-0.8; vibrating 1818 spheres at 2 mm: 9.4e6 at 0.1,
#: 1.17e7 at 0.4, 1.11e7 at 0.8.
SKIN_FRACTION = 0.4


class DemInstabilityError(RuntimeError):
    """The simulation blew up (energy growth, NaN, particles through walls)."""




def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class Simulation:
    """State of N spheres in a set of walls, advanced by :meth:`step` / :meth:`run`.

    The attributes ``centers``, ``velocities`` and ``spins`` are the (N, 3) state arrays
    themselves (writable); forces are returned component-first, (3, N) views.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    walls : list of PlaneWall | CylinderWall
    material : Material
    gravity_m_s2 : float
        Magnitude of gravity along −z (9.81; 0 disables).
    mass_scale : float
        Density scaling factor S ≥ 1 (see module notes).
    dt_safety : float
        Safety factor s of the time step.
    skin_m : float | None
        Verlet skin; default :data:`SKIN_FRACTION` · r_max. No result depends on it (only how
        often the list is rebuilt).
    bounds_m : (2, 3) array | None
        Box that every centre must stay in; leaving it raises DemInstabilityError.
    threads : int | None
        Threads of the step kernels; None chooses by timing (:class:`dem._threads.ThreadChooser`).
        The result is the same for any count.
    """

    def __init__(self, centers, radii, walls, material=SOYBEAN, *, gravity_m_s2=9.81, mass_scale=1.0,
                 dt_safety=0.25, skin_m=None, bounds_m=None, threads=None):
        centers = np.array(centers, dtype=float)
        radii = np.array(radii, dtype=float)
        n = len(radii)
        if radii.ndim != 1 or centers.shape != (n, 3):
            raise ValueError(f"centers must be (N, 3) with N = len(radii) = {n}, got {centers.shape}")
        if not np.all(np.isfinite(centers)) or not np.all(radii > 0):
            raise ValueError("centers must be finite and radii positive")
        if not isinstance(material, Material):
            raise TypeError(f"material must be a Material, got {type(material).__name__}")
        if not mass_scale >= 1.0:
            raise ValueError(f"mass_scale must be >= 1, got {mass_scale}")
        if not 0 < dt_safety <= 1:
            raise ValueError(f"dt_safety must be in (0, 1], got {dt_safety}")
        self.material = material
        self.gravity_m_s2 = float(gravity_m_s2)
        self.mass_scale = float(mass_scale)
        self.dt_safety = float(dt_safety)
        self.bounds_m = None if bounds_m is None else np.array(bounds_m, dtype=float)
        self.time_s = 0.0
        self.steps = 0
        self.z_offset_m = 0.0
        self.wall_vz_m_s = 0.0
        self.stats = {"rebuilds": 0}
        self._x = np.ascontiguousarray(centers)
        self._v = np.zeros((n, 3))
        self._w = np.zeros((n, 3))
        self._force = np.zeros((n, 3))
        self._torque = np.zeros((n, 3))
        self._roll = np.zeros(n)
        skin = skin_m if skin_m is not None else SKIN_FRACTION * float(radii.max())
        self.verlet = VerletList(skin)
        self._set_pairs(np.zeros((0, 4)))
        self._set_radii(radii)
        self.set_walls(walls)
        self.threads = ThreadChooser(n, threads=threads)

    # ------------------------------------------------------------------ state
    centers = property(lambda self: self._x, lambda self, v: self._x.__setitem__(slice(None), v))
    velocities = property(lambda self: self._v, lambda self, v: self._v.__setitem__(slice(None), v))
    spins = property(lambda self: self._w, lambda self, v: self._w.__setitem__(slice(None), v))

    def _set_radii(self, radii):
        self.radii = np.asarray(radii, dtype=float)
        m = self.material
        self.mass = m.density_kg_m3 * 4.0 / 3.0 * np.pi * self.radii**3
        self.inertia = 0.4 * self.mass * self.radii**2
        self._dt = self.dt_safety * float(
            np.sqrt(self.mass_scale * self.mass.min() / max(self.material.kn_n_m, self.material.ks_n_m))
        )
        # per-particle factors of the kernels (scaled masses, weight, dt / mass, dt / inertia)
        self._ms = self.mass * self.mass_scale
        self._gforce = self.mass * (self.mass_scale * self.gravity_m_s2)
        self._inv_m = self._dt / (self.mass * self.mass_scale)
        self._inv_i = self._dt / (self.inertia * self.mass_scale)
        self._coef_valid = False

    def set_radii(self, radii):
        """Change radii (radius expansion); masses follow at fixed density."""
        self._set_radii(radii)

    def set_walls(self, walls):
        """Replace the walls (e.g. remove the lid); wall contact history is dropped."""
        self.walls = list(walls)
        nw, n = len(self.walls), self.n
        self._wall_kind = np.zeros(nw, dtype=np.int64)
        self._wall_normal = np.zeros((nw, 3))
        self._wall_cyl = np.zeros((nw, 3))
        self._wall_moves = np.zeros(nw, dtype=np.bool_)
        for k, wall in enumerate(self.walls):
            if isinstance(wall, PlaneWall):
                self._wall_normal[k] = wall.normal
            elif isinstance(wall, CylinderWall):
                self._wall_kind[k] = 1
                self._wall_cyl[k] = (*wall.center_xy_m, wall.radius_m)
            else:
                raise TypeError(f"unknown wall type {type(wall).__name__}")
            self._wall_moves[k] = wall.moves
        self._wall_offset_at = None
        self.wall_shear = np.zeros((nw, n, 3))
        self._wall_fn = np.zeros((nw, n))
        self._wall_touch = np.zeros((nw, n), dtype=np.uint8)

    def _wall_offsets(self):
        """Plane offsets -p·n with the moving planes shifted by ``z_offset_m`` (cached)."""
        if self._wall_offset_at != self.z_offset_m:
            off = np.zeros(len(self.walls))
            for k, wall in enumerate(self.walls):
                if isinstance(wall, PlaneWall):
                    p = np.asarray(wall.point_m, dtype=float).copy()
                    if wall.moves:
                        p[2] += self.z_offset_m
                    off[k] = -float(p @ np.asarray(wall.normal, dtype=float))
            self._wall_offset, self._wall_offset_at = off, self.z_offset_m
        return self._wall_offset

    def set_material(self, material):
        """Replace the material (e.g. restore friction after packing)."""
        self.material = material
        self._set_radii(self.radii)

    @property
    def dt(self):
        """Time step, s: s·sqrt(S m_min / max(k_n, k_s))."""
        return self._dt

    @property
    def n(self):
        return len(self.radii)

    def kinetic_energy(self):
        """Translational + rotational kinetic energy with physical (unscaled) masses, J."""
        v, w = self._v.T, self._w.T
        return float(0.5 * np.sum(self.mass * _dot(v, v)) + 0.5 * np.sum(self.inertia * _dot(w, w)))

    # ------------------------------------------------------------------ forces
    def _set_pairs(self, history):
        """Per-pair arrays for the current Verlet pairs; ``history`` (Np, 4) holds each pair's
        shear spring (m) and whether it touched at the last evaluation."""
        p = self.verlet.pairs
        self._pi, self._pj = p[:, 0].copy(), p[:, 1].copy()
        self.shear = np.ascontiguousarray(history[:, :3])
        self._touch = history[:, 3].astype(np.uint8)
        self._f_pair = np.zeros((len(p), 3))
        self._t_pair = np.zeros((len(p), 3))
        self._fn_pair = np.zeros(len(p))
        self._cn = np.zeros(len(p))
        self._ct = np.zeros(len(p))
        self._coef_valid = False

    def _rebuild(self):
        old_keys = self.verlet.build(self._x, self.radii)
        history = np.column_stack([self.shear, self._touch])
        self._set_pairs(remap_history(old_keys, history, self.verlet.keys))
        self.stats["rebuilds"] += 1

    def _evaluate(self, advance):
        if self.verlet.needs_rebuild(self._x, self.radii):
            self._rebuild()
        t0 = time.perf_counter()
        self._step_kernels(advance)
        self.threads.record(time.perf_counter() - t0)

    def _step_kernels(self, advance):
        """The compiled passes of one evaluation (:mod:`dem._kernels`), timed for the thread choice."""
        mat, dt, vl = self.material, self._dt, self.verlet
        if not self._coef_valid:
            pair_damping(self._ms, self._pi, self._pj, mat.damping_ratio, mat.kn_pp, mat.ks_pp, self._cn, self._ct)
            self._coef_valid = True
        pair_forces(self._x, self._v, self._w, self.radii, self._pi, self._pj, self._cn, self._ct, self.shear,
                    mat.kn_pp, mat.ks_pp, mat.friction, dt, self._f_pair, self._t_pair, self._fn_pair, self._touch)
        particle_update(self._x, self._v, self._w, self.radii, self._ms, self._gforce, vl.first_start,
                        vl.second_start, vl.by_second, self._f_pair, self._t_pair, self._fn_pair, self._touch,
                        self._wall_kind, self._wall_normal, self._wall_offsets(), self._wall_cyl, self._wall_moves,
                        self.wall_vz_m_s, self.wall_shear, self._wall_fn, self._wall_touch, mat.kn_pw, mat.ks_pw,
                        mat.wall_beta, mat.wall_friction, mat.rolling_friction, mat.wall_rolling_friction, dt,
                        self._inv_m, self._inv_i, self._force, self._torque, self._roll, advance)

    def forces(self):
        """Net force and torque on every particle, both (3, N) component-first (scaled masses).

        Evaluating the forces advances the contacts' shear springs (as a step does)."""
        self._evaluate(False)
        return self._force.T, self._torque.T

    @property
    def contact_fn(self):
        """(Nc,) normal forces of the touching particle pairs at the last evaluation, N."""
        return self._fn_pair[self._touch.view(bool)]

    @property
    def last_wall_fn(self):
        """(Nw,) normal forces of the wall contacts at the last evaluation (wall by wall), N."""
        return self._wall_fn[self._wall_touch.view(bool)]

    @property
    def touching_pairs(self):
        """(Nc, 2) pairs in contact at the last force evaluation."""
        return self.verlet.pairs[self._touch.view(bool)]

    def get_state(self):
        """Everything a continued run needs, as arrays: positions, velocities, spins, radii, time,
        step count, container motion and the contact springs (pair keys i*N+j with their
        history, the wall springs). :meth:`set_state` on a Simulation with the same walls and
        material continues bit for bit as if never stopped (the Verlet list is rebuilt, which
        does not change any number)."""
        return {"centers": self._x.copy(), "velocities": self._v.copy(), "spins": self._w.copy(),
                "radii": self.radii.copy(), "time_s": np.float64(self.time_s), "steps": np.int64(self.steps),
                "z_offset_m": np.float64(self.z_offset_m), "wall_vz_m_s": np.float64(self.wall_vz_m_s),
                "pair_keys": self.verlet.keys.copy(), "pair_history": np.column_stack([self.shear, self._touch]),
                "wall_shear": self.wall_shear.copy(), "wall_touch": self._wall_touch.copy()}

    def set_state(self, state):
        """Continue from :meth:`get_state` (same particles, walls and material)."""
        if state["centers"].shape != self._x.shape or state["wall_shear"].shape != self.wall_shear.shape:
            raise ValueError(f"state of {state['centers'].shape[0]} particles and {state['wall_shear'].shape[0]} "
                             f"walls does not fit {self.n} particles and {len(self.walls)} walls")
        self._x[:], self._v[:], self._w[:] = state["centers"], state["velocities"], state["spins"]
        self._set_radii(np.array(state["radii"], dtype=float))
        self.time_s, self.steps = float(state["time_s"]), int(state["steps"])
        self.z_offset_m, self.wall_vz_m_s = float(state["z_offset_m"]), float(state["wall_vz_m_s"])
        self.verlet.build(self._x, self.radii)
        self._set_pairs(remap_history(np.asarray(state["pair_keys"]), np.asarray(state["pair_history"], dtype=float),
                                      self.verlet.keys))
        self.wall_shear[:] = state["wall_shear"]
        self._wall_touch[:] = state["wall_touch"]

    # ------------------------------------------------------------------ stepping
    def step(self):
        """Advance one time step; returns the net force, (3, N) component-first, N."""
        self._evaluate(True)
        self.time_s += self._dt
        self.steps += 1
        return self._force.T

    def unbalanced_force_ratio(self, force):
        r"""Mean unbalanced-force ratio :math:`\overline{|F_{net}|} / \overline{F_n}`.

        Mean magnitude of the net force on the particles over the mean normal contact
        force (particle and wall contacts); 0 means exact static equilibrium.
        """
        fn = np.concatenate([self.contact_fn, self.last_wall_fn])
        if len(fn) == 0 or fn.mean() == 0:
            return float("inf")
        return float(np.mean(np.sqrt(_dot(force, force))) / fn.mean())

    def check_stability(self, *, max_speed_m_s=20.0, max_overlap_fraction=0.5):
        """Raise DemInstabilityError on NaN, runaway speeds, deep overlaps or escapes."""
        bad = ~(np.all(np.isfinite(self._x), axis=1) & np.all(np.isfinite(self._v), axis=1))
        if np.any(bad):
            raise DemInstabilityError(
                f"non-finite position/velocity of particle #{int(np.flatnonzero(bad)[0])} at t = "
                f"{self.time_s:.4g} s (step {self.steps}); reduce dt_safety or mass_scale"
            )
        speed2 = _dot(self._v.T, self._v.T)
        k = int(np.argmax(speed2))
        vmax = float(np.sqrt(speed2[k]))
        if vmax > max_speed_m_s:
            raise DemInstabilityError(
                f"particle #{k} at {self._x[k].round(4).tolist()} m moves at {vmax:.3g} m/s > "
                f"{max_speed_m_s} m/s at t = {self.time_s:.4g} s (step {self.steps}): energy blow-up; "
                "reduce dt_safety or mass_scale"
            )
        pairs = self.touching_pairs
        if len(pairs):
            i, j = pairs[:, 0], pairs[:, 1]
            d = np.linalg.norm(self.centers[j] - self.centers[i], axis=1)
            frac = (self.radii[i] + self.radii[j] - d) / np.minimum(self.radii[i], self.radii[j])
            m = int(np.argmax(frac))
            if frac[m] > max_overlap_fraction:
                raise DemInstabilityError(
                    f"overlap {frac[m]:.2f} of a radius between particles #{int(i[m])} and #{int(j[m])} at "
                    f"t = {self.time_s:.4g} s: particles pass through each other (stiffness too low for "
                    "the load or dt too large)"
                )
        if len(self.last_wall_fn):
            wmax = float(self.last_wall_fn.max()) / self.material.kn_pw / float(self.radii.min())
            if wmax > max_overlap_fraction:
                raise DemInstabilityError(
                    f"wall overlap {wmax:.2f} of a radius at t = {self.time_s:.4g} s: particles are "
                    "pressed through a wall (container too small for the grains, or dt too large)"
                )
        if self.bounds_m is not None:
            lo, hi = self.bounds_m
            out = np.any((self.centers < lo) | (self.centers > hi), axis=1)
            if np.any(out):
                k = int(np.flatnonzero(out)[0])
                raise DemInstabilityError(
                    f"{int(out.sum())} particle(s) left the container (e.g. #{k} at "
                    f"{self.centers[k].round(4).tolist()} m) at t = {self.time_s:.4g} s"
                )

    def run(self, *, duration_s=None, max_steps=None, tol=None, min_steps=0, check_every=200,
            callback=None, grow_from=None, grow_to=None):
        """Advance until ``duration_s`` / ``max_steps`` or until equilibrium.

        Parameters
        ----------
        duration_s : float, optional
            Simulated time to advance, s.
        max_steps : int, optional
        tol : float, optional
            Stop when the mean unbalanced-force ratio is below ``tol`` (checked every
            ``check_every`` steps, after ``min_steps``).
        callback : callable(sim, force) -> None, optional
            Called every ``check_every`` steps (progress output, histories).
        grow_from, grow_to : (N,) arrays, optional
            Radii interpolated linearly from ``grow_from`` to ``grow_to`` over the run
            (needs ``max_steps``): radius expansion.

        Returns
        -------
        dict with ``steps``, ``time_s``, ``ratio``, ``converged``, ``wall_s``.
        """
        if duration_s is None and max_steps is None:
            raise ValueError("give duration_s or max_steps")
        if (grow_from is None) != (grow_to is None):
            raise ValueError("grow_from and grow_to go together")
        if grow_from is not None and max_steps is None:
            raise ValueError("radius growth needs max_steps")
        t0 = time.perf_counter()
        t_end = None if duration_s is None else self.time_s + duration_s
        k = 0
        ratio = float("inf")
        converged = False
        while True:
            if max_steps is not None and k >= max_steps:
                break
            if t_end is not None and self.time_s >= t_end - 1e-15:
                break
            if grow_from is not None:
                s = (k + 1) / max_steps
                self._set_radii(grow_from + s * (grow_to - grow_from))
            force = self.step()
            k += 1
            if k % check_every == 0:
                self.check_stability()
                ratio = self.unbalanced_force_ratio(force)
                if callback is not None:
                    callback(self, force)
                if tol is not None and k >= min_steps and ratio < tol:
                    converged = True
                    break
        self.check_stability()
        return {
            "steps": k,
            "time_s": self.time_s,
            "ratio": ratio,
            "converged": converged,
            "wall_s": time.perf_counter() - t0,
        }
