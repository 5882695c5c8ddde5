r"""The packing procedures of :func:`pack_bed` (thesis 3.1, Appendices A–B).

``'lid'``: generate N spheres (Eq. 3.10) at radii divided by m₀ below the fill height, expand
them by the multiplier of Eqs. 3.5–3.7, :math:`m^3 = (1-φ)/(1-φ_0)`, under a lid at
(1 + ``lid_headroom``) × the fill height, cycle under the lid, remove it and settle to
equilibrium. ``lid_headroom = 0`` with ``open_top=False`` is Appendix A's closed box (global
porosity φ by construction, with forced overlaps).

``'sediment'`` (the rect-bin default, :data:`~dem._container.SCENE_DEFAULTS`): the same
expansion without friction in the whole box under the lid, frictionless sedimentation,
annealed taps :math:`z = A(t)\sin 2\pi f t` of the container, then Table 3.1 friction restored,
lid removed, settle. Friction 0.47 in a bin three grains thick locks a loose structure (interior
porosity 0.452 with ``'lid'``); this procedure reaches 0.4152 with overlaps below 1 % of a radius.

The steps in full, what Appendix A's script does, and the measurements behind the defaults:
``docs/dem-packing.md``. Equilibrium is a mean unbalanced-force ratio below ``tol``; all stages
use density scaling S (``mass_scale``, see :mod:`dem._integrate`).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ._container import Container, make_simulation
from ._fill import check_fill, check_sphere_count, generate_spheres, thesis_particle_count
from ._material import SOYBEAN
from ._measure import sphere_volume
from ._summary import interior_porosity, overlap_fractions, summarize

__all__ = ["PROCEDURES", "PackOptions", "PackResult", "RunOptions", "pack_bed"]

log = logging.getLogger(__name__)


@dataclass
class PackResult:
    """A finished packing and how it was made."""

    centers: np.ndarray
    radii: np.ndarray
    container: Container
    summary: dict = field(default_factory=dict)


PROCEDURES = ("lid", "sediment")


@dataclass(frozen=True, kw_only=True)
class PackOptions:
    r"""The packing procedure of :func:`pack_bed` (module notes; defaults: Appendix B's ``'lid'``).

    Parameters
    ----------
    procedure : {'lid', 'sediment'}
        'lid' (default): expansion and closed stage under the lid with the material's friction
        (or ``packing_friction``), then settling (Appendices A–B). 'sediment': frictionless
        sedimentation and taps, friction restored for the last settle (the default of
        ``--scene rect-bin``); ``packing_friction`` (default 0 here) applies to particle and
        wall contacts.
    initial_multiplier : float
        m₀ >= 1: generation radii are the nominal ones divided by m₀ (default 1.4, Appendix A).
    grow_steps : int
        Steps over which the radii grow to their final size (default 3000).
    lid_headroom : float
        The lid sits at (1 + lid_headroom) × the fill height during expansion (default 0.2:
        Appendix B's 0.05 m above a 0.25 m fill); 0 is Appendix A's closed box.
    packing_friction : float | None
        Particle friction during expansion and the closed stage (default None: the material's
        for 'lid', 0 for 'sediment'); the material's friction is restored for the last settle.
    open_top : bool
        Remove the lid and settle again before measuring (default True, Appendix A).
    sediment_steps : int
        'sediment': steps of frictionless settling after the expansion (default 3000).
    tap_freq_hz, tap_amplitude_m, tap_duration_s : float
        'sediment': container motion :math:`z = A \sin 2\pi f t` (Hz, m, s; default 30 Hz,
        1.6 mm, 0.6 s), run for round(f · duration) whole periods (at least one); A = 0 or
        duration 0 skips it.
    tap_settle_steps : int
        'sediment': frictionless steps after the taps (default 3000).
    tap_decay : bool
        'sediment': amplitude falls linearly from ``tap_amplitude_m`` to 0 (default True).
    """

    procedure: str = "lid"
    initial_multiplier: float = 1.4
    grow_steps: int = 3000
    lid_headroom: float = 0.2
    packing_friction: float | None = None
    open_top: bool = True
    sediment_steps: int = 3000
    tap_freq_hz: float = 30.0
    tap_amplitude_m: float = 1.6e-3
    tap_duration_s: float = 0.6
    tap_settle_steps: int = 3000
    tap_decay: bool = True

    def __post_init__(self):
        if self.procedure not in PROCEDURES:
            raise ValueError(f"procedure must be one of {PROCEDURES}, got {self.procedure!r}")
        if not self.initial_multiplier >= 1.0:
            raise ValueError(f"initial_multiplier must be >= 1, got {self.initial_multiplier}")
        if not (self.grow_steps >= 1 and self.lid_headroom >= 0):
            raise ValueError(f"grow_steps must be >= 1 and lid_headroom >= 0, got {self.grow_steps}, "
                             f"{self.lid_headroom}")
        if self.packing_friction is not None and not self.packing_friction >= 0:
            raise ValueError(f"packing_friction must be >= 0, got {self.packing_friction}")
        if self.procedure == "sediment" and not (
                self.lid_headroom > 0 and self.sediment_steps >= 0 and self.tap_duration_s >= 0
                and self.tap_amplitude_m >= 0 and self.tap_freq_hz > 0 and self.tap_settle_steps >= 0):
            raise ValueError("procedure 'sediment' needs lid_headroom > 0, tap_freq_hz > 0 and non-negative "
                             "sediment_steps, tap_duration_s, tap_amplitude_m, tap_settle_steps (Appendix A's "
                             "closed box is procedure 'lid' with lid_headroom 0)")


@dataclass(frozen=True, kw_only=True)
class RunOptions:
    """How the stages of :func:`pack_bed` run.

    Parameters
    ----------
    mass_scale : float
        Density scaling S >= 1 of every stage (default 100; 1 = physical masses).
    dt_safety : float
        Time step as this fraction of the lightest sphere's critical step (default 0.25).
    tol : float
        Mean unbalanced-force ratio that counts as equilibrium, each stage (default 2e-3).
    max_steps : int
        Step limit per equilibrium stage (default 200 000).
    check_every : int
        Steps between equilibrium checks and progress calls (default 200).
    settle_time_s : float | None
        Settle for this simulated time instead of until ``tol`` (default None; used to compare
        density scalings at equal physical time).
    """

    mass_scale: float = 100.0
    dt_safety: float = 0.25
    tol: float = 2e-3
    max_steps: int = 200_000
    check_every: int = 200
    settle_time_s: float | None = None

    def __post_init__(self):
        if not self.mass_scale >= 1.0:
            raise ValueError(f"mass_scale must be >= 1, got {self.mass_scale}")
        if not 0 < self.dt_safety <= 1:
            raise ValueError(f"dt_safety must be in (0, 1], got {self.dt_safety}")
        if not (self.tol > 0 and self.max_steps >= 1 and self.check_every >= 1):
            raise ValueError(f"need tol > 0, max_steps >= 1 and check_every >= 1, got {self.tol}, "
                             f"{self.max_steps}, {self.check_every}")
        if self.settle_time_s is not None and not self.settle_time_s > 0:
            raise ValueError(f"settle_time_s must be > 0, got {self.settle_time_s}")


def pack_bed(container, *, material=SOYBEAN, porosity=0.408, n_particles=None, rng=None,
             options=PackOptions(), run=RunOptions(), measure_spheres=None, progress=None):
    """Make a settled packing in ``container`` (procedures: module notes and ``docs/dem-packing.md``).

    Parameters
    ----------
    container : Container
    material : Material
    porosity : float
        Target porosity φ of the closed volume (default 0.408, thesis Table 3.1).
    n_particles : int, optional
        Default: thesis Eq. 3.10.
    rng : numpy.random.Generator | int | None
        Seed or generator; the same seed gives the same packing.
    options : PackOptions
        The procedure and its stages.
    run : RunOptions
        Mass scale, time step, equilibrium tolerance and step limit.
    measure_spheres : ((M, 3) array, float) | None
        Centres and radius of measurement spheres (default: thesis B1–B5).
    progress : callable(stage, sim, force) | None
        Called every ``run.check_every`` steps.

    Returns
    -------
    PackResult
    """
    if not isinstance(container, Container):
        raise TypeError(f"container must be a Container, got {type(container).__name__}")
    if not isinstance(options, PackOptions) or not isinstance(run, RunOptions):
        raise TypeError(f"options must be PackOptions and run RunOptions, got {type(options).__name__}, "
                        f"{type(run).__name__}")
    check_fill(container, porosity, material)
    rng = np.random.default_rng(rng)
    n = thesis_particle_count(container, porosity, material) if n_particles is None else int(n_particles)
    if n < 1:
        raise ValueError(f"no sphere fits: n_particles = {n}")
    check_sphere_count(n, "spheres (thesis Eq. 3.10)" if n_particles is None else "spheres")
    o = options
    procedure, initial_multiplier, lid_headroom, packing_friction = (o.procedure, o.initial_multiplier,
                                                                     o.lid_headroom, o.packing_friction)
    mass_scale, tol, max_steps, check_every = run.mass_scale, run.tol, run.max_steps, run.check_every
    t_wall = time.perf_counter()
    r_lo = material.radius_min_m / initial_multiplier
    r_hi = material.radius_max_m / initial_multiplier
    lid_height = container.fill_height_m * (1 + lid_headroom)
    # 'lid' generates below the fill height (Appendices A-B); 'sediment' in the whole box under the lid,
    # so that the expanded spheres are a dilute suspension that settles without being forced together
    gen_box = container if procedure == "lid" else replace(container, fill_height_m=lid_height)
    centers, r0 = generate_spheres(gen_box, n, r_lo, r_hi, rng)
    phi0 = 1.0 - sphere_volume(r0).sum() / container.volume_m3
    mult = ((1.0 - porosity) / (1.0 - phi0)) ** (1.0 / 3.0)  # thesis Eq. 3.7
    log.info("generated %d spheres, porosity %.4f, radius multiplier %.4f", n, phi0, mult)
    if procedure == "lid":
        mat_pack = material if packing_friction is None else replace(material, friction=float(packing_friction))
    else:
        mu = 0.0 if packing_friction is None else float(packing_friction)
        mat_pack = replace(material, friction=mu, wall_friction=mu)
    sim = make_simulation(container, centers, r0, material=mat_pack, lid=True, lid_height_m=lid_height,
                          mass_scale=mass_scale, dt_safety=run.dt_safety)
    stages = {}

    def cb(stage):
        return None if progress is None else (lambda s, f: progress(stage, s, f))

    stages["expand"] = sim.run(max_steps=o.grow_steps, grow_from=r0, grow_to=r0 * mult, check_every=check_every,
                               callback=cb("expand"))
    if procedure == "lid":
        # closed stage: relax the expanded assembly under the lid before opening the top, so that
        # elastic energy stored by the expansion cannot launch spheres out of the bin. Appendix A's
        # closed box (lid_headroom = 0) is cycled to the full criterion, otherwise to 1e-2.
        tol_closed = tol if (lid_headroom == 0 and packing_friction is None) else max(tol, 1e-2)
        stages["closed"] = sim.run(max_steps=max_steps, tol=tol_closed, check_every=check_every,
                                   callback=cb("closed"))
        stages["closed"]["max_overlap_fraction"] = float(np.max(overlap_fractions(sim)))
    else:
        # frictionless sedimentation for a fixed number of steps (a frictionless bed under
        # viscous damping alone creeps towards the force criterion very slowly), then taps
        stages["sediment"] = sim.run(max_steps=o.sediment_steps, check_every=check_every, callback=cb("sediment"))
        stages["sediment"]["porosity_interior"] = interior_porosity(sim, container)
        stages["tap"] = _tap(sim, o.tap_freq_hz, o.tap_amplitude_m, o.tap_duration_s, check_every, cb("tap"),
                             decay=o.tap_decay)
        stages["tap_settle"] = sim.run(max_steps=o.tap_settle_steps, check_every=check_every,
                                       callback=cb("tap_settle"))
        stages["tap_settle"]["porosity_interior"] = interior_porosity(sim, container)
        stages["tap_settle"]["max_overlap_fraction"] = float(np.max(overlap_fractions(sim)))
        for name in ("sediment", "tap", "tap_settle"):
            stages[name]["converged"] = True  # fixed-length stages
    sim.set_material(material)
    if o.open_top:
        sim.set_walls(container.walls(lid=False))
    if run.settle_time_s is None:
        stages["settle"] = sim.run(max_steps=max_steps, tol=tol, check_every=check_every, callback=cb("settle"))
    else:
        stages["settle"] = sim.run(duration_s=run.settle_time_s, check_every=check_every, callback=cb("settle"))
        stages["settle"]["converged"] = True
    for name, st in stages.items():
        if name != "expand" and not st["converged"]:
            log.warning("stage %s stopped at the step limit (ratio %.3g > tol %.3g)", name, st["ratio"], tol)
    wall_s = time.perf_counter() - t_wall
    summary = summarize(sim.centers, sim.radii, container, material=material, measure_spheres=measure_spheres)
    steps = sum(st["steps"] for st in stages.values())
    summary.update({
        "target_porosity": porosity,
        "initial_porosity": float(phi0),
        "radius_multiplier": float(mult),
        "mass_scale": float(mass_scale),
        "dt_s": sim.dt,
        "dt_physical_s": sim.dt / np.sqrt(mass_scale),
        "simulated_time_s": sim.time_s,
        "steps": int(steps),
        "stages": stages,
        "tol_unbalanced_ratio": tol,
        "wall_time_s": wall_s,
        "particle_steps_per_s": steps * n / wall_s,
        "neighbour_rebuilds": int(sim.stats["rebuilds"]),
        "max_overlap_fraction": float(np.max(overlap_fractions(sim))),
        "mean_overlap_fraction": float(np.mean(overlap_fractions(sim))),
        "procedure": procedure,
        "final_friction": {"particle": sim.material.friction, "wall": sim.material.wall_friction},
        "material": {k: getattr(material, k) for k in material.__dataclass_fields__},
    })
    return PackResult(sim.centers.copy(), sim.radii.copy(), container, summary)


def _tap(sim, freq_hz, amplitude_m, duration_s, check_every, callback, decay=False):
    r"""Vertical sinusoidal motion of the container, :math:`z_w = A\sin(2\pi f t)`, for a whole
    number of periods (at least one when A·duration > 0) so the floor ends where it started."""
    t0 = time.perf_counter()
    n_cycles = int(round(duration_s * freq_hz))
    if amplitude_m == 0 or duration_s == 0:
        n_cycles = 0
    elif n_cycles == 0:
        n_cycles = 1
    period = 1.0 / freq_hz
    omega = 2 * np.pi * freq_hz
    start = sim.time_s
    k = 0
    t_end = n_cycles * period
    while n_cycles and sim.time_s - start < t_end:
        t = sim.time_s - start
        if decay:  # amplitude falling linearly to zero (annealed tapping)
            a, da = amplitude_m * (1 - t / t_end), -amplitude_m / t_end
        else:
            a, da = amplitude_m, 0.0
        sim.z_offset_m = a * np.sin(omega * t)
        sim.wall_vz_m_s = a * omega * np.cos(omega * t) + da * np.sin(omega * t)
        force = sim.step()
        k += 1
        if k % check_every == 0:
            sim.check_stability()
            if callback is not None:
                callback(sim, force)
    sim.z_offset_m = 0.0
    sim.wall_vz_m_s = 0.0
    return {"steps": k, "time_s": sim.time_s, "cycles": n_cycles, "freq_hz": float(freq_hz),
            "duration_s": sim.time_s - start, "amplitude_m": float(amplitude_m), "decay": bool(decay),
            "intensity_g": float(amplitude_m * omega**2 / 9.81), "wall_s": time.perf_counter() - t0}

