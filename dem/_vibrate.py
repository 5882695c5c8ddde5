r"""Vertical sinusoidal vibration of a settled bed (thesis 3.2 and Appendix C).

The floor and side walls of the bin move together,

.. math:: z_w(t) = A \sin(\omega t), \qquad \dot z_w(t) = A\omega\cos(\omega t),
          \qquad \Gamma = A\omega^2 / g \quad (\text{thesis Eq. 3.11}),

for ``duration_s`` (to the end of its half period: the walls pass z = 0 there); the walls then
stop at z = 0 and the bed settles to equilibrium
(mean unbalanced-force ratio below ``tol``) before the final measurement. Porosity
histories are measured in the floor's frame: measurement spheres (B1–B5) and the
interior region (two mean diameters from the walls, the floor and the initial surface).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ._material import SOYBEAN
from ._measure import porosity_in_region, porosity_in_spheres, sphere_volume
from ._container import default_measure_spheres, make_simulation
from ._procedures import RunOptions
from ._summary import summarize, surface_height

__all__ = ["vibrate_bed", "VibrationOptions", "VibrationResult", "intensity_g", "rest_motion",
           "REST_PROBE_S", "SETTLE_RUN"]

log = logging.getLogger(__name__)
G = 9.81
#: fewest time steps a vibration period must have (1e6 Hz gave 0.07 of a step per period)
MIN_STEPS_PER_PERIOD = 20


def intensity_g(freq_hz, amplitude_m):
    r"""Vibration intensity Γ = A (2π f)² / g (thesis: 2 mm at 15 Hz → 1.81 g).

    >>> round(float(intensity_g(15, 0.002)), 2)
    1.81
    """
    return float(amplitude_m) * (2 * np.pi * float(freq_hz)) ** 2 / G


def _positive(name, value, *, zero=False):
    """``float(value)`` if finite and > 0 (>= 0 with ``zero``), else ValueError naming it."""
    v = float(value)
    if not math.isfinite(v) or v < 0 or (v == 0 and not zero):
        raise ValueError(f"{name} must be finite and {'>=' if zero else '>'} 0, got {value!r}")
    return v


@dataclass(frozen=True, kw_only=True)
class VibrationOptions:
    r"""The walls' motion, when it may stop early, and what :func:`vibrate_bed` records.

    Parameters
    ----------
    freq_hz : float
        f, > 0 (default 15 Hz, the thesis's).
    amplitude_m : float
        A, >= 0 (default 2 mm; thesis: 0.5–4 mm); 0 is a control run (the bed at rest for the
        same time).
    duration_s : float
        Vibration time, > 0 (default 1 s; thesis: 16 s).
    steady_window_s : float, optional
        Stop the vibration early once the global porosity has been steady this long (> 0): the
        means of the window's two halves differ by less than ``steady_tol`` including two
        standard errors (per-period values that still fluctuate are not steady). Default None:
        vibrate for ``duration_s``.
    steady_tol : float
        Porosity change that counts as steady, > 0 (default 1e-3).
    record_every_s : float, optional
        History interval, > 0; default None: a quarter period.
    snapshot_times_s : sequence of float
        Times (s, >= 0) at which a copy of the centres is kept (default none).
    rest_tol : float, optional
        Refuse (ValueError) a packing that is not at rest: one whose spheres move on average
        more than ``rest_tol`` (> 0) mean radii in :data:`REST_PROBE_S` with the walls still
        (:func:`rest_motion`; settled beds: below 0.003, unsettled ones 0.02–0.6). Default None:
        no check.

    >>> round(VibrationOptions(freq_hz=15.0, amplitude_m=0.002).intensity_g, 2)
    1.81
    """

    freq_hz: float = 15.0
    amplitude_m: float = 0.002
    duration_s: float = 1.0
    steady_window_s: float | None = None
    steady_tol: float = 1e-3
    record_every_s: float | None = None
    snapshot_times_s: tuple = ()
    rest_tol: float | None = None

    def __post_init__(self):
        put = object.__setattr__
        put(self, "freq_hz", _positive("freq_hz", self.freq_hz))
        put(self, "amplitude_m", _positive("amplitude_m", self.amplitude_m, zero=True))
        put(self, "duration_s", _positive("duration_s", self.duration_s))
        put(self, "steady_tol", _positive("steady_tol", self.steady_tol))
        for name in ("steady_window_s", "record_every_s", "rest_tol"):
            if getattr(self, name) is not None:
                put(self, name, _positive(name, getattr(self, name)))
        put(self, "snapshot_times_s", tuple(_positive("snapshot_times_s", t, zero=True)
                                            for t in self.snapshot_times_s))

    @property
    def intensity_g(self) -> float:
        """Γ = A (2π f)² / g (thesis Eq. 3.11)."""
        return intensity_g(self.freq_hz, self.amplitude_m)


#: How :func:`vibrate_bed` runs by default: the packing's mass scaling and time step, and the
#: final settling to a mean unbalanced-force ratio of 1e-3 within 100 000 steps.
SETTLE_RUN = RunOptions(tol=1e-3, max_steps=100_000)


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
    motion: dict = field(default_factory=dict)  # floor_z_m, bed_z_m (mean centre height) at the records


#: Simulated time of the rest probe, s (:func:`rest_motion`).
REST_PROBE_S = 0.02


def rest_motion(centers, radii, container, *, material=SOYBEAN, mass_scale=100.0, probe_s=REST_PROBE_S):
    """Mean displacement of the spheres, in mean radii, over ``probe_s`` with the walls still.

    A packing read from a file has lost its contact springs and velocities, so its force
    balance alone cannot say whether it is at rest; its motion can. Measured over 0.02 s: rect-bin
    packed by ``dem.pack`` 0.0004, a 200-sphere box settled to a force ratio 0.08: 0.003; a bed
    stopped at ratio 0.4: 0.023; spheres in the air: 0.56.
    """
    sim = make_simulation(container, centers, radii, material=material, lid=False, mass_scale=mass_scale)
    sim.run(duration_s=probe_s)
    return float(np.mean(np.linalg.norm(sim.centers - np.asarray(centers), axis=1)) / np.mean(radii))


def vibrate_bed(centers, radii, container, *, vibration=VibrationOptions(), run=SETTLE_RUN,
                material=SOYBEAN, measure_spheres=None, threads=None, progress=None,
                checkpoint=None, checkpoint_every_s=None, resume=None):
    """Vibrate a packing vertically and record its porosity.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    container : Container
    vibration : VibrationOptions
        The walls' motion, the early stop and what is recorded (default: 2 mm at 15 Hz for
        1 s).
    run : RunOptions
        Mass scaling S (equivalent to stiffnesses divided by S; 1 = physical), time-step
        safety, and the final settling after the walls stop: ``tol`` (mean unbalanced-force
        ratio), ``max_steps``, ``check_every`` (default :data:`SETTLE_RUN`: S = 100, tol 1e-3,
        100 000 steps); ``settle_time_s`` is not taken (the bed settles to ``tol``).
    material : Material
        Contact law and density (default soybeans).
    measure_spheres : (centres (M, 3), radii (M,)), optional
        Measurement spheres (default :func:`dem.default_measure_spheres` of the container).
    threads : int, optional
        Threads of the step (default: chosen by timing; the result does not depend on it).
    progress : callable(stage, sim, force), optional
        Called every ``run.check_every`` steps.
    checkpoint : callable(dict) -> None, optional
        Called every ``checkpoint_every_s`` of simulated vibration with what ``resume`` takes.
    resume : dict, optional
        A checkpoint of an interrupted run of the same arguments: the run goes on from it and
        ends with the numbers of an uninterrupted run.

    Returns
    -------
    VibrationResult
    """
    if not isinstance(vibration, VibrationOptions):
        raise TypeError(f"vibration must be a VibrationOptions, got {type(vibration).__name__}")
    if not isinstance(run, RunOptions):
        raise TypeError(f"run must be a RunOptions, got {type(run).__name__}")
    if run.settle_time_s is not None:
        raise ValueError("vibrate_bed settles to run.tol after the vibration; settle_time_s is "
                         "not taken")
    freq_hz, amplitude_m, duration_s = vibration.freq_hz, vibration.amplitude_m, vibration.duration_s
    steady_window_s, steady_tol = vibration.steady_window_s, vibration.steady_tol
    record_every_s, snapshot_times_s = vibration.record_every_s, vibration.snapshot_times_s
    rest_tol = vibration.rest_tol
    mass_scale, dt_safety, tol = run.mass_scale, run.dt_safety, run.tol
    max_settle_steps, check_every = run.max_steps, run.check_every
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
                          dt_safety=dt_safety, threads=threads)
    if sim.dt * freq_hz > 1.0 / MIN_STEPS_PER_PERIOD:
        raise ValueError(f"a frequency of {freq_hz:g} Hz is not resolved by the time step "
                         f"{sim.dt:.3g} s ({1 / (sim.dt * freq_hz):.3g} steps a period, at least "
                         f"{MIN_STEPS_PER_PERIOD})")
    sim.bounds_m[1, 2] += 2 * amplitude_m + 0.1  # bed may dilate upwards
    sim.bounds_m[0, 2] -= amplitude_m
    if resume is None and rest_tol is not None:
        moved = rest_motion(centers, radii, container, material=material, mass_scale=mass_scale)
        if not moved <= rest_tol:
            raise ValueError(f"the packing is not at rest: with the walls still its spheres moved {moved:.3g} mean "
                             f"radii on average in {REST_PROBE_S} s (at rest: below {rest_tol:g}); settle it first")
    t0 = time.perf_counter()
    hist = {"times_s": [], "porosity_spheres": [], "porosity_interior": [], "porosity_global": [],
            "floor_z_m": [], "bed_z_m": []}
    snaps = {}
    pending = sorted(float(t) for t in snapshot_times_s)
    next_rec, next_ckpt, stop = record_every_s, checkpoint_every_s, "duration"
    if resume is not None:
        sim.set_state(resume["state"])
        hist = {k: list(v) for k, v in resume["history"].items()}
        snaps = {float(t): np.asarray(x) for t, x in resume["snapshots"].items()}
        pending = [t for t in pending if t not in snaps and t > sim.time_s - 1e-12]
        next_rec, next_ckpt = resume["next_record_s"], resume["next_checkpoint_s"]

    def record():
        dz = sim.z_offset_m
        shifted = sim.centers - [0, 0, dz]
        hist["times_s"].append(sim.time_s)
        hist["porosity_spheres"].append(porosity_in_spheres(shifted, radii, mc, mr))
        hist["porosity_interior"].append(porosity_in_region(shifted, radii, region0))
        hist["porosity_global"].append(1.0 - vp / (container.area_m2 * surface_height(shifted, radii, container)))
        hist["floor_z_m"].append(dz)
        hist["bed_z_m"].append(float(np.mean(sim.centers[:, 2])))

    if resume is None:
        record()
    dt = sim.dt
    n_steps = int(np.ceil(duration_s / dt))
    for k in range(sim.steps, n_steps):
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
            if steady_window_s and _steady(hist, steady_window_s, steady_tol):
                stop = "steady"
                break
        while pending and sim.time_s >= pending[0] - 1e-12:
            snaps[pending.pop(0)] = (sim.centers - [0, 0, sim.z_offset_m]).copy()
        if checkpoint is not None and next_ckpt and sim.time_s >= next_ckpt - 1e-12:
            next_ckpt += checkpoint_every_s
            checkpoint({"state": sim.get_state(), "history": {k: list(v) for k, v in hist.items()},
                        "snapshots": dict(snaps), "next_record_s": next_rec, "next_checkpoint_s": next_ckpt})
    # stop at a zero of the floor's motion (a whole number of half periods, within half a step):
    # a duration or a steady stop off it moved the floor by up to A at once, into the bed or away
    t_end = np.ceil((sim.time_s - dt) * 2 * freq_hz) / (2 * freq_hz)
    while sim.time_s < t_end - 0.5 * dt:
        sim.z_offset_m = amplitude_m * np.sin(omega * sim.time_s)
        sim.wall_vz_m_s = amplitude_m * omega * np.cos(omega * sim.time_s)
        sim.step()
    vib_wall = time.perf_counter() - t0
    vib_steps, vib_time = sim.steps, sim.time_s
    sim.z_offset_m = 0.0
    sim.wall_vz_m_s = 0.0
    settle = sim.run(max_steps=max_settle_steps, tol=tol, check_every=check_every,
                     callback=None if progress is None else (lambda s, f: progress("settle", s, f)))
    record()
    summary = summarize(sim.centers, radii, container, material=material, measure_spheres=measure_spheres)
    ps_a = np.array(hist["porosity_spheres"])
    pi, pg = hist["porosity_interior"], hist["porosity_global"]
    summary.update({
        "freq_hz": freq_hz, "amplitude_m": amplitude_m, "intensity_g": intensity_g(freq_hz, amplitude_m),
        "duration_s": duration_s, "vibrated_s": vib_time, "stopped_by": stop, "mass_scale": mass_scale, "dt_s": dt,
        "vibration_steps": int(vib_steps), "vibration_wall_s": vib_wall, "settle": settle,
        "particle_steps_per_s": (vib_steps + settle["steps"]) * len(radii) / (time.perf_counter() - t0),
        "initial": {"porosity_interior": pi[0], "porosity_global": pg[0], "porosity_spheres_mean": float(ps_a[0].mean())},
        "final": {"porosity_interior": pi[-1], "porosity_global": pg[-1], "porosity_spheres_mean": float(ps_a[-1].mean())},
        "minimum_during": {"porosity_interior": float(np.min(pi)), "porosity_spheres_mean": float(ps_a.mean(axis=1).min()),
                           "porosity_spheres_min": float(ps_a.min())},
        "interior_region_fixed": region0.to_dict(),
        "steady_window_s": steady_window_s, "steady_tol": steady_tol,
        "threads": {str(k): v for k, v in sim.threads.steps_by_threads.items()},
    })
    return VibrationResult(np.array(hist["times_s"]), ps_a, np.array(pi), np.array(pg), sim.centers.copy(), radii,
                           snaps, summary, {"floor_z_m": np.array(hist["floor_z_m"]), "bed_z_m": np.array(hist["bed_z_m"])})


def _steady(hist, window_s, tol):
    """True when the global porosity has been steady over the last ``window_s``: the means of
    its two halves differ by less than ``tol`` with two standard errors added, so a bed whose
    per-period porosity still fluctuates (a bed in flight above 1 g) is never called steady."""
    t = np.asarray(hist["times_s"])
    if t[-1] - t[0] < window_s:
        return False
    p = np.asarray(hist["porosity_global"])
    a = p[(t >= t[-1] - window_s) & (t < t[-1] - window_s / 2)]
    b = p[t >= t[-1] - window_s / 2]
    if len(a) < 3 or len(b) < 3:
        return False
    err = np.sqrt(a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b))
    return abs(b.mean() - a.mean()) + 2 * err < tol
