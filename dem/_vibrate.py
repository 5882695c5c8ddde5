r"""Vertical sinusoidal vibration of a settled bed (thesis 3.2 and Appendix C).

The floor and side walls of the bin move together,

.. math:: z_w(t) = A \sin(\omega t), \qquad \dot z_w(t) = A\omega\cos(\omega t),
          \qquad \Gamma = A\omega^2 / g \quad (\text{thesis Eq. 3.11}),

for ``duration_s``; the walls then stop at z = 0 and the bed settles to equilibrium
(mean unbalanced-force ratio below ``tol``) before the final measurement. Porosity
histories are measured in the floor's frame: measurement spheres (B1–B5) and the
interior region (two mean diameters from the walls, the floor and the initial surface).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from ._integrate import SOYBEAN
from ._measure import Region, porosity_in_region, porosity_in_spheres, sphere_volume
from ._container import default_measure_spheres, make_simulation
from ._summary import summarize, surface_height

__all__ = ["vibrate_bed", "VibrationResult", "intensity_g"]

log = logging.getLogger(__name__)
G = 9.81


def intensity_g(freq_hz, amplitude_m):
    r"""Vibration intensity Γ = A (2π f)² / g (thesis: 2 mm at 15 Hz → 1.81 g).

    >>> round(float(intensity_g(15, 0.002)), 2)
    1.81
    """
    return float(amplitude_m) * (2 * np.pi * float(freq_hz)) ** 2 / G


@dataclass
class VibrationResult:
    """Histories (one row per record time) and the final, re-settled packing."""

    times_s: np.ndarray
    porosity_spheres: np.ndarray
    porosity_interior: np.ndarray
    porosity_global: np.ndarray
    centers: np.ndarray
    radii: np.ndarray
    snapshots: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)


def _shifted(region, dz):
    lo = (region.lo[0], region.lo[1], region.lo[2] + dz)
    hi = (region.hi[0], region.hi[1], region.hi[2] + dz)
    return Region(region.kind, lo, hi, region.radius, region.center_xy)


def vibrate_bed(centers, radii, container, *, freq_hz=15.0, amplitude_m=0.002, duration_s=1.0, material=SOYBEAN,
            mass_scale=100.0, dt_safety=0.25, record_every_s=None, snapshot_times_s=(), measure_spheres=None,
            tol=1e-3, max_settle_steps=100000, progress=None, check_every=200):
    """Vibrate a packing vertically and record its porosity.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    container : Container
    freq_hz : float
        f (thesis: 15 Hz).
    amplitude_m : float
        A (thesis: 0.5–4 mm).
    duration_s : float
        Vibration time (thesis: 16 s).
    mass_scale : float
        Density scaling S (equivalent to stiffnesses divided by S; 1 = physical).
    record_every_s : float, optional
        History interval; default a quarter period.
    snapshot_times_s : sequence of float
        Times at which a copy of the centres is kept.
    tol : float
        Equilibrium criterion of the final settling (after the walls stop).

    Returns
    -------
    VibrationResult
    """
    if not freq_hz > 0 or not amplitude_m >= 0 or not duration_s > 0:
        raise ValueError(f"need freq_hz > 0, amplitude_m >= 0, duration_s > 0; got {freq_hz}, {amplitude_m}, "
                         f"{duration_s}")
    centers = np.array(centers, dtype=float)
    radii = np.array(radii, dtype=float)
    omega = 2 * np.pi * freq_hz
    record_every_s = record_every_s or 0.25 / freq_hz
    if measure_spheres is None:
        measure_spheres = default_measure_spheres(container)
    mc, mr = measure_spheres
    surface0 = surface_height(centers, radii, container)
    dmean = 2 * float(radii.mean())
    region0 = container.interior(2 * dmean, surface0)
    vp = float(sphere_volume(radii).sum())
    sim = make_simulation(container, centers, radii, material=material, lid=False, mass_scale=mass_scale,
                          dt_safety=dt_safety)
    sim.bounds_m[1, 2] += 2 * amplitude_m + 0.1  # bed may dilate upwards
    sim.bounds_m[0, 2] -= amplitude_m
    t0 = time.perf_counter()
    times, ps, pi, pg = [], [], [], []
    snaps = {}
    pending = sorted(float(t) for t in snapshot_times_s)

    def record():
        dz = sim.z_offset_m
        shifted = sim.centers - [0, 0, dz]
        times.append(sim.time_s)
        ps.append(porosity_in_spheres(shifted, radii, mc, mr))
        pi.append(porosity_in_region(shifted, radii, region0))
        pg.append(1.0 - vp / (container.area_m2 * surface_height(shifted, radii, container)))

    record()
    next_rec = record_every_s
    dt = sim.dt
    n_steps = int(np.ceil(duration_s / dt))
    for k in range(n_steps):
        t = sim.time_s + dt  # wall state at the end of this step
        sim.z_offset_m = amplitude_m * np.sin(omega * sim.time_s)
        sim.wall_vz_m_s = amplitude_m * omega * np.cos(omega * sim.time_s)
        sim.step()
        if (k + 1) % check_every == 0:
            sim.check_stability(max_speed_m_s=20.0 + 10 * amplitude_m * omega)
            if progress is not None:
                progress("vibrate", sim, None)
        if sim.time_s >= next_rec - 1e-12:
            record()
            next_rec += record_every_s
        while pending and sim.time_s >= pending[0] - 1e-12:
            snaps[pending.pop(0)] = (sim.centers - [0, 0, sim.z_offset_m]).copy()
        del t
    vib_wall = time.perf_counter() - t0
    vib_steps = sim.steps
    sim.z_offset_m = 0.0
    sim.wall_vz_m_s = 0.0
    settle = sim.run(max_steps=max_settle_steps, tol=tol, check_every=check_every,
                     callback=None if progress is None else (lambda s, f: progress("settle", s, f)))
    record()
    summary = summarize(sim.centers, radii, container, material=material, measure_spheres=measure_spheres)
    ps_a = np.array(ps)
    summary.update({
        "freq_hz": freq_hz, "amplitude_m": amplitude_m, "intensity_g": intensity_g(freq_hz, amplitude_m),
        "duration_s": duration_s, "mass_scale": mass_scale, "dt_s": dt, "vibration_steps": int(vib_steps),
        "vibration_wall_s": vib_wall, "settle": settle,
        "particle_steps_per_s": (vib_steps + settle["steps"]) * len(radii) / (time.perf_counter() - t0),
        "initial": {"porosity_interior": pi[0], "porosity_global": pg[0], "porosity_spheres_mean": float(ps_a[0].mean())},
        "final": {"porosity_interior": pi[-1], "porosity_global": pg[-1], "porosity_spheres_mean": float(ps_a[-1].mean())},
        "minimum_during": {"porosity_interior": float(np.min(pi)), "porosity_spheres_mean": float(ps_a.mean(axis=1).min())},
        "interior_region_fixed": region0.to_dict(),
    })
    return VibrationResult(np.array(times), ps_a, np.array(pi), np.array(pg), sim.centers.copy(), radii,
                           snaps, summary)
