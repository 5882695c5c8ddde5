r"""Poured fills: grains rain over the whole cross-section or run from a centre spout.

A bin is filled by pouring: from a spreader (a uniform rain over the cross-section) or a centre
spout (a pile at its angle of repose whose grains slide down the slope). :func:`pour_grains`
does the same with rigid multi-sphere grains (:class:`dem.clumps.ClumpSimulation`), their real
masses (``FillOptions.mass_scale`` = 1) and the contact friction, restitution and rolling
friction (:func:`dem._contacts.rolling_torque`) of the grain library.

**Entry.** The fall from the drop height H costs no steps: a grain enters just above the bed
surface with the speed of that fall,

.. math:: v_0 = \min\left(\sqrt{2 g H},\; v_t\right),\qquad
          v_t = \sqrt{\frac{4 g d_v (\rho_p - \rho_a)}{3 C_D \rho_a}},

capped at the terminal velocity :math:`v_t` of its volume-equivalent sphere (diameter
:math:`d_v`) in air (:math:`\rho_a` = 1.2 kg/m³, 20 °C) with Newton's drag coefficient
:math:`C_D` = 0.44 (constant for a sphere at 10³ < Re < 2·10⁵; Clift, Grace & Weber 1978,
*Bubbles, Drops and Particles*, ch. 5). A wheat kernel (:math:`d_v` = 4.1 mm) has
:math:`v_t` = 11.2 m/s at Re ≈ 3000: the cap acts only for drops above 6.4 m. Kernels
enter with a random orientation (uniform on SO(3)) and no spin.

**Stream, rate, rest and what is measured** (batches placed in the slab the stream fills, the
default mass flow that raises the surface one grain diameter per rebound flight, the settle to
``tol`` within :func:`rest_steps`, the orientation order S, porosity in 10 layers and a spout's
angle of repose): ``docs/dem-fill.md``, which derives each and gives the measured beds.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ._contacts import restitution_coefficient
from ._freeze import FREEZE_DEPTH_LENGTHS, FreezePolicy
from ._rigid import random_quaternions
from .clumps import ClumpSimulation

__all__ = ["FILL_METHODS", "FillOptions", "AIR_DENSITY_KG_M3", "DRAG_COEFFICIENT", "MAX_DROP_HEIGHT_M",
           "entry_speed", "terminal_velocity", "default_rate", "batch_interval", "pour_grains",
           "rest_steps", "REST_TIME_S", "check_fill_options"]

#: fills of a grain bed: 'rain' (spreader), 'spout' (centre spout), 'grow' (grown in place)
FILL_METHODS = ("rain", "spout", "grow")
#: air at 20 °C, kg/m³
AIR_DENSITY_KG_M3 = 1.2
#: Newton's drag coefficient of a sphere, 10³ < Re < 2e5 (Clift, Grace & Weber 1978)
DRAG_COEFFICIENT = 0.44
#: highest drop height taken, m
MAX_DROP_HEIGHT_M = 10.0
#: gravity, m/s²
G = 9.81
#: simulated time a poured bed gets to come to rest after its last grain, s (the default budget)
REST_TIME_S = 0.5


@dataclass(frozen=True, kw_only=True)
class FillOptions:
    """How a grain bed is filled (module notes).

    Parameters
    ----------
    method : {'rain', 'spout', 'grow'}
        'rain' (default): a spreader, grains over the whole cross-section; 'spout': a centre
        spout; 'grow': grains grown in place and settled (:func:`dem._clump_pack.pack_grains`).
    drop_height_m : float
        Height the grains fall from onto the surface, m, in (0, 10] (default 0.3).
    rate_kg_s : float | None
        Mass flow, kg/s, > 0; None: :func:`default_rate`.
    spout_diameter_m : float | None
        'spout': the spout's diameter, m; None: three kernel lengths.
    mass_scale : float
        Density scaling S >= 1 of the pour (default 1: real masses).
    freeze : bool
        Freeze the settled grains deep in the bed while the pour goes on (default True;
        :mod:`dem._freeze`, ``docs/dem-fill.md`` section Speed); False steps every grain.
    """

    method: str = "rain"
    drop_height_m: float = 0.3
    rate_kg_s: float | None = None
    spout_diameter_m: float | None = None
    mass_scale: float = 1.0
    freeze: bool = True

    def __post_init__(self):
        if self.method not in FILL_METHODS:
            raise ValueError(f"fill must be one of {', '.join(FILL_METHODS)}, got {self.method!r}")
        h = self.drop_height_m
        if not (math.isfinite(h) and 0 < h <= MAX_DROP_HEIGHT_M):
            raise ValueError(f"drop height {h:g} m: must be > 0 and <= {MAX_DROP_HEIGHT_M:g} m")
        if self.rate_kg_s is not None and not (math.isfinite(self.rate_kg_s) and self.rate_kg_s > 0):
            raise ValueError(f"rate {self.rate_kg_s:g} kg/s: must be > 0")
        d = self.spout_diameter_m
        if d is not None and not (math.isfinite(d) and d > 0):
            raise ValueError(f"spout diameter {d:g} m: must be > 0")
        if not (math.isfinite(self.mass_scale) and self.mass_scale >= 1):
            raise ValueError(f"mass scale {self.mass_scale:g}: must be >= 1")
        if not isinstance(self.freeze, bool):
            raise ValueError(f"freeze must be True or False, got {self.freeze!r}")


def terminal_velocity(diameter_m, density_kg_m3):
    r"""Terminal velocity in air of a sphere of diameter ``diameter_m`` (m) and density
    ``density_kg_m3``, m/s: :math:`\sqrt{4 g d (\rho_p - \rho_a)/(3 C_D \rho_a)}`, Newton's
    regime (:data:`DRAG_COEFFICIENT`, :data:`AIR_DENSITY_KG_M3`).

    >>> round(terminal_velocity(4.1e-3, 1240.0), 1)
    11.2
    """
    return float(np.sqrt(4 * G * diameter_m * (density_kg_m3 - AIR_DENSITY_KG_M3)
                         / (3 * DRAG_COEFFICIENT * AIR_DENSITY_KG_M3)))


def entry_speed(drop_height_m, diameter_m, density_kg_m3):
    r"""Speed of a grain reaching the surface from the drop height, :math:`\min(\sqrt{2gH}, v_t)`, m/s.

    >>> round(entry_speed(0.3, 4.1e-3, 1240.0), 3)
    2.426
    """
    return min(math.sqrt(2 * G * drop_height_m), terminal_velocity(diameter_m, density_kg_m3))


def default_rate(area_m2, diameter_m, density_kg_m3, porosity, restitution, speed_m_s):
    r"""Default mass flow, kg/s: the surface rises one grain diameter in a grain's first rebound
    flight, :math:`\dot m = \rho_p(1-\varphi) A\, d_v g / (2 e v_0)` (module notes).

    >>> round(default_rate(1.6e-3, 4.1e-3, 1240.0, 0.402, 0.52, 2.426), 5)
    0.01891
    """
    t_flight = 2 * restitution * speed_m_s / G
    return density_kg_m3 * (1 - porosity) * area_m2 * diameter_m / t_flight


def batch_interval(speed_m_s, bounding_radius_m, drop_height_m):
    """Time between two batches of the stream, s: the stream fills a slab 8 bounding radii thick
    (``speed * tau``), at most half the drop height (:func:`pour_grains` rounds it to whole
    check intervals of steps)."""
    return min(8 * bounding_radius_m, 0.5 * drop_height_m) / speed_m_s


def check_fill_options(fill, container, template):
    """ValueError naming the value when a fill does not fit ``container`` (a spout wider than
    the container or narrower than a grain)."""
    if fill.method != "spout" or fill.spout_diameter_m is None:
        return
    width = min(container.size_m)
    if fill.spout_diameter_m > width:
        raise ValueError(f"spout diameter {fill.spout_diameter_m:g} m is wider than the container "
                         f"({width:g} m)")
    if fill.spout_diameter_m < 2 * template.bounding_radius_m:
        raise ValueError(f"spout diameter {fill.spout_diameter_m:g} m is narrower than a grain "
                         f"({2 * template.bounding_radius_m:.4g} m across)")


def _footprint(container, fill, template):
    """(kind, size) where grain centres enter: ('box', (hx, hy)) or ('disk', radius), m."""
    rb = template.bounding_radius_m
    if fill.method == "spout":
        d = fill.spout_diameter_m if fill.spout_diameter_m is not None else 3 * float(template.extent_m[0])
        d = min(d, min(container.size_m))
        return "disk", max(d / 2 - rb, 0.25 * rb), d
    if container.kind == "box":
        return "box", (container.size_m[0] / 2 - rb, container.size_m[1] / 2 - rb), None
    return "disk", container.size_m[0] / 2 - rb, None


def _sample_lateral(kind, size, n, rng):
    if kind == "box":
        return np.column_stack([rng.uniform(-size[0], size[0], n), rng.uniform(-size[1], size[1], n)])
    rho = size * np.sqrt(rng.random(n))
    phi = rng.uniform(0, 2 * np.pi, n)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi)])


def _place(n, kind, size, z_lo, thickness, rb, old_x, rng, tries=200):
    """n grain centres in the slab [z_lo, z_lo + thickness] over the footprint, bounding spheres
    (radius rb) apart from each other and from the grains ``old_x`` (G, 3)."""
    tree = cKDTree(old_x) if len(old_x) else None
    placed = np.empty((0, 3))
    for _ in range(tries):
        need = n - len(placed)
        if need <= 0:
            break
        m = 4 * need + 8
        c = np.column_stack([_sample_lateral(kind, size, m, rng), z_lo + thickness * rng.random(m)])
        ok = np.ones(m, bool)
        if tree is not None:
            ok &= np.isinf(tree.query(c, k=1, distance_upper_bound=2 * rb)[0])
        for k in np.flatnonzero(ok):
            if len(placed) >= n:
                ok[k:] = False
                break
            if len(placed) and np.min(np.sum((placed - c[k]) ** 2, axis=1)) < (2 * rb) ** 2:
                ok[k] = False
                continue
            placed = np.vstack([placed, c[k]])
    if len(placed) < n:
        raise ValueError(f"the stream is too dense to enter: {n} grains do not fit a slab "
                         f"{thickness:.3g} m thick over the footprint; lower the rate or widen the spout")
    return placed


def _place_stream(n, kind, size, z_lo, thickness, rb, old_x, rng, drop_height_m):
    """:func:`_place`, in a slab up to 8 times thicker (at most the drop height) when the batch
    does not fit: a dense stream (a narrow spout) is spread over a longer stretch of its fall;
    each batch still carries the mass of one batch interval, so the mean rate is kept."""
    t = thickness
    while True:
        try:
            return _place(n, kind, size, z_lo, t, rb, old_x, rng)
        except ValueError:
            if t >= min(8 * thickness, drop_height_m):
                raise
            t = min(2 * t, 8 * thickness, drop_height_m)


def _grown(sim, template, x_new, v_new, q_new, threads=None):
    """A ClumpSimulation holding ``sim``'s grains (state, contact springs, time) plus new ones."""
    g_old, n_old = sim.n_grains, sim.n
    x = np.vstack([sim.X, x_new])
    q = np.vstack([sim.q, q_new])
    new = ClumpSimulation([template], np.zeros(len(x), int), x, q, np.ones(len(x)), sim.walls, sim.material,
                          mass_scale=sim.mass_scale, dt_safety=sim.dt_safety, skin_m=sim.verlet.skin,
                          gravity_m_s2=sim.gravity_m_s2, threads=threads)
    new.V[:g_old], new.V[g_old:] = sim.V, v_new
    new.L[:g_old] = sim.L
    new.time_s, new.steps = sim.time_s, sim.steps
    n_new = new.n
    keys = sim.verlet.keys
    new.verlet.keys = (keys // n_old) * n_new + keys % n_old     # same (i, j), new N: still sorted
    new.shear, new._touch = sim.shear.copy(), sim._touch.copy()  # remapped at the first rebuild
    new.wall_shear[:, :n_old] = sim.wall_shear
    new._wall_touch[:, :n_old] = sim._wall_touch
    new.stats = sim.stats
    new._poses()
    if sim.active is not None:
        new.active = sim.active.grown(new)
    return new


def rest_steps(dt_s, *, rest_time_s=None, min_steps=60_000):
    """Default step budget of a poured bed's rest: :data:`REST_TIME_S` of simulated time at the
    step ``dt_s`` (s), at least ``min_steps``; real masses take 10 times the steps of mass scale 100.

    >>> rest_steps(1e-6), rest_steps(1e-4)
    (500000, 60000)
    """
    t = REST_TIME_S if rest_time_s is None else rest_time_s
    return max(int(min_steps), int(math.ceil(t / dt_s - 1e-9)))


#: largest drift of a grain that freezes over :data:`FREEZE_WINDOW_S`, in volume-equivalent diameters d_v
FREEZE_DRIFT_FRACTION = 0.002
#: window over which a grain must drift less than that before it freezes, s
FREEZE_WINDOW_S = 0.03
#: normal force of an active neighbour, in weights of the frozen grain, that releases it
RELEASE_PUSH_WEIGHTS = 50.0


def freeze_policy(template, v0):
    """The :class:`dem._freeze.FreezePolicy` of a pour (``docs/dem-fill.md`` section Speed): frozen
    below :data:`dem._freeze.FREEZE_DEPTH_LENGTHS` kernel lengths after drifting less than
    :data:`FREEZE_DRIFT_FRACTION` d_v in :data:`FREEZE_WINDOW_S` and moving slower than twice that
    drift per window, released at :data:`RELEASE_PUSH_WEIGHTS` weights; ``v0`` the entry speed
    (grains faster than v0/2 are falling)."""
    length = float(template.extent_m[0])
    drift = FREEZE_DRIFT_FRACTION * 2 * template.equivalent_radius_m
    return FreezePolicy(depth_m=FREEZE_DEPTH_LENGTHS * length, drift_m=drift, window_s=FREEZE_WINDOW_S,
                        speed_m_s=2 * drift / FREEZE_WINDOW_S, push_weights=RELEASE_PUSH_WEIGHTS, cell_m=length,
                        length_m=length, falling_m_s=0.5 * v0)


def pour_grains(container, template, *, material, fill=FillOptions(), n_grains, rng=None, tol=2e-3,
                max_steps=None, check_every=200, progress=None, restitution=None, porosity=0.4, threads=1,
                policy=None):
    r"""Pour ``n_grains`` grains of ``template`` into ``container`` (module notes) and settle.

    Parameters
    ----------
    container : Container
    template : Template
    material : Material
        Density, stiffness, friction and damping (from the grains' restitution).
    fill : FillOptions
        'rain' or 'spout', drop height, rate, spout diameter, mass scale.
    n_grains : int
    rng : numpy.random.Generator | int | None
    tol : float
        Mean unbalanced-force ratio of the rest (after the last grain is in).
    max_steps : int | None
        Step budget of the rest (None: :func:`rest_steps`, 0.5 s of simulated time).
    restitution : float | None
        Grain-grain restitution e of the default rate (None: from ``material.damping_ratio``).
    porosity : float
        Porosity φ of the default rate's bulk density.
    threads : int | None
        Threads of the step kernels (default 1; None: chosen by timing in each batch's
        simulation). A pour makes a new simulation at every batch, and on a shared two-core
        machine two threads stepped a settled 25 000-sphere corn bed at a tenth of one thread's
        particle-steps per CPU-second.
    policy : FreezePolicy | None
        With ``fill.freeze``: when grains freeze and are released (None: :func:`freeze_policy`).

    Returns
    -------
    (ClumpSimulation, dict)
        The settled simulation and the fill record: method, drop height, entry and terminal
        speed, rate (and where it came from), spout diameter, mass scale, fill time and steps,
        the rest stage (``steps``, ``ratio``, ``converged``).
    """
    if fill.method not in ("rain", "spout"):
        raise ValueError(f"pour_grains pours 'rain' or 'spout', got {fill.method!r}")
    check_fill_options(fill, container, template)
    n_grains = int(n_grains)
    if n_grains < 1:
        raise ValueError(f"no grain to pour: n_grains = {n_grains}")
    rng = np.random.default_rng(rng)
    t0, c0 = time.perf_counter(), time.process_time()
    psteps = 0
    rho = material.density_kg_m3
    d_v = 2 * template.equivalent_radius_m
    rb = template.bounding_radius_m
    v0 = entry_speed(fill.drop_height_m, d_v, rho)
    e = float(restitution_coefficient(material.damping_ratio)) if restitution is None else float(restitution)
    if fill.rate_kg_s is None:
        rate = default_rate(container.area_m2, d_v, rho, porosity, e, v0)
        rate_source = (f"default: surface rises one grain diameter ({d_v * 1e3:.2f} mm) per rebound flight "
                       f"2 e v0 / g = {2 * e * v0 / G:.3f} s (e = {e:.3g}, bulk porosity {porosity:.3f})")
    else:
        rate, rate_source = float(fill.rate_kg_s), "given"
    m_grain = rho * template.volume_m3
    kind, size, spout_d = _footprint(container, fill, template)
    if min(np.atleast_1d(size)) <= 0:
        raise ValueError(f"the container ({', '.join(f'{v:g}' for v in container.size_m)} m across) is narrower "
                         f"than a {template.name} grain ({2 * rb:.4g} m across its bounding sphere)")
    area_in = 4 * size[0] * size[1] if kind == "box" else math.pi * size**2
    # the sphere engine's step (ClumpSimulation: its lightest sphere); batches every whole number
    # of check intervals, so progress and checks fall on the same steps as a plain run
    dt = 0.25 * math.sqrt(fill.mass_scale * rho * 4 / 3 * math.pi * float(template.radii.min()) ** 3
                          / max(material.kn_n_m, material.ks_n_m))
    steps_per_batch = check_every * max(1, round(batch_interval(v0, rb, fill.drop_height_m) / dt / check_every))
    tau = steps_per_batch * dt
    per_batch = rate * tau / m_grain
    walls = container.walls(lid=False)
    sim = None
    carry, inserted, batches = 0.0, 0, 0
    while inserted < n_grains:
        carry += per_batch
        k = min(int(carry), n_grains - inserted)
        if k == 0 and sim is None:
            k = 1
        carry -= k
        if k:
            if sim is None:
                surface, old = 0.0, np.empty((0, 3))
            else:
                surface, old = _surface_for_entry(sim, kind, size, rb, v0), sim.X
            x_new = _place_stream(k, kind, size, surface + rb, v0 * tau, rb, old, rng, fill.drop_height_m)
            s = x_new[:, 2] - (surface + rb)
            v_new = np.zeros((k, 3))
            v_new[:, 2] = -np.sqrt(np.maximum(v0**2 - 2 * G * s, 0.0))
            q_new = random_quaternions(k, rng)
            if sim is None:
                sim = ClumpSimulation([template], np.zeros(k, int), x_new, q_new, np.ones(k), walls, material,
                                      mass_scale=fill.mass_scale, threads=threads)
                sim.V[:] = v_new
                lo, hi = container.bounds(rb, headroom=0.0)
                sim.attach_active(lo_m=lo, hi_m=hi, capacity=n_grains * template.n,
                                  policy=(policy or freeze_policy(template, v0)) if fill.freeze else None)
            else:
                sim = _grown(sim, template, x_new, v_new, q_new, threads=threads)
            inserted += k
            batches += 1
        psteps += sim.run(max_steps=steps_per_batch, check_every=check_every, callback=progress)["steps"] * sim.n
    fill_time, fill_steps = sim.time_s, sim.steps
    if max_steps is None:
        max_steps = rest_steps(sim.dt)
    # the rest: the active grains first (the frozen ones are at rest), then every grain released
    # and the whole bed judged (module notes of dem._freeze)
    region = sim.active
    active = {"steps": 0}
    if fill.freeze:
        active = sim.run(max_steps=max_steps, tol=tol, check_every=check_every, callback=progress)
        psteps += active["steps"] * sim.n
    freeze = {"enabled": bool(fill.freeze), "frozen_at_fill_end": region.n_frozen if fill.freeze else 0,
              "freeze_events": region.frozen_events, "release_events": region.released_events,
              "max_push_weights": region.max_push_weights,
              "active_particle_steps": int(region.active_particle_steps), "relists": region.relists,
              "relisted_spheres": region.relisted_spheres, "rest_active_steps": active["steps"]}
    if fill.freeze:
        freeze.update(policy={k: getattr(region.policy, k) for k in region.policy.__dataclass_fields__})
    sim.detach_active()
    rest = sim.run(max_steps=max(max_steps - active["steps"], check_every), tol=tol, check_every=check_every,
                   callback=progress)
    psteps += rest["steps"] * sim.n
    freeze["active_particle_steps"] += rest["steps"] * sim.n
    rest = dict(rest, steps=rest["steps"] + active["steps"])
    record = {"method": fill.method, "drop_height_m": fill.drop_height_m, "entry_speed_m_s": v0,
              "terminal_velocity_m_s": terminal_velocity(d_v, rho),
              "drag_law": (f"Newton's regime, C_D = {DRAG_COEFFICIENT} for a sphere of the kernel's volume "
                           f"(d_v = {d_v * 1e3:.3f} mm) in air of {AIR_DENSITY_KG_M3} kg/m^3 (Clift, Grace & "
                           "Weber 1978)"),
              "rate_kg_s": rate, "rate_source": rate_source,
              "surface_rise_m_s": rate / (rho * (1 - porosity) * container.area_m2),
              "spout_diameter_m": spout_d, "entry_area_m2": area_in, "mass_scale": fill.mass_scale,
              "restitution_pp": e, "batches": batches, "batch_interval_s": tau,
              "fill_time_s": fill_time, "fill_steps": fill_steps,
              "rest": rest, "converged": bool(rest["converged"]), "particle_steps": int(psteps), "freeze": freeze,
              "wall_time_s": time.perf_counter() - t0, "cpu_time_s": time.process_time() - c0}
    return sim, record


def _surface_for_entry(sim, kind, size, rb, v0):
    """Height of the bed surface under the footprint: the highest sphere top of the grains not
    falling at entry speed (|V| < v0 / 2), m; 0 for an empty bin."""
    xs = sim._x
    slow = np.linalg.norm(sim.V, axis=1) < 0.5 * v0
    keep = slow[sim.gid]
    if kind == "disk":
        keep &= np.hypot(xs[:, 0], xs[:, 1]) < size + 2 * rb
    if not np.any(keep):
        return 0.0
    return float(np.max(xs[keep, 2] + sim.radii[keep]))
