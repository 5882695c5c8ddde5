r"""The porosity band of ``network.report``: d ln(ΔP/L)/dε computed with the project's packer.

The bed's pressure gradient g(U) is predicted for its own porosity ε. How it moves with ε is
measured, not assumed: :func:`pack_band` packs the same grain size (same count, same diameter
range, same box shape) with :func:`network.packing.random_packing` (a geometric grow-and-push
packer, no gravity, no friction) at five solid fractions around the bed's, in ``seeds``
independent families, solves each with inertia at a few velocities, and :func:`fit_log_slope`
fits, per velocity,

.. math:: \ln g_{s,i} = c_s + S\,\varepsilon_{s,i}

(one intercept per seed family, one common slope S: a family's own offset, from its random
arrangement, does not leak into S). :func:`band_gradients` then gives
g(ε + Δε) = g(ε) exp(S Δε) at Δε = -0.02, -0.01, +0.01, +0.02. Near ε = 0.40 the soybean
size gives S ≈ -11 to -13.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

import numpy as np

from ..flow import ConductanceOptions, FlowOptions, solve_network
from ..packing import Packing, random_packing

__all__ = ["BAND_OFFSETS", "fit_log_slope", "band_gradients", "slope_at", "pack_band",
           "measured_band", "GRAIN_BANDS"]

log = logging.getLogger(__name__)

#: grains whose band was measured on their own DEM grain beds: network/data/band_<grain>.json
#: (beds, gradients at three velocities, how they were made)
GRAIN_BANDS = {"wheat": Path(__file__).resolve().parents[1] / "data" / "band_wheat.json"}
#: porosity offsets of the reported band
BAND_OFFSETS = (-0.02, -0.01, 0.01, 0.02)
#: interior porosity of random_packing beds ≈ WALL_OFFSET - solid fraction (the walls loosen
#: the outer layer): 0.57 gives 0.399 (the bundled scene) and 0.404 (seed 2), measured here
WALL_OFFSET = 0.969
#: solid-fraction steps of the band packings (interior porosity moves about as much)
SF_STEPS = (-0.02, -0.01, 0.0, 0.01, 0.02)


def fit_log_slope(porosity, gradient, family=None) -> dict:
    """Least-squares common slope S of ln(gradient) against porosity, one intercept per family.

    Parameters
    ----------
    porosity, gradient : (N,) array_like
        Porosities and pressure gradients (> 0, Pa/m) of N packings.
    family : (N,) array_like, optional
        Family label of each packing (e.g. its seed); default: one family.

    Returns
    -------
    dict with ``slope`` (S), ``slope_stderr`` (NaN with fewer than families + 2 points),
    ``rms_residual`` (of ln g) and ``intercepts`` (one per family, sorted labels).

    >>> e = np.array([0.38, 0.39, 0.40, 0.41]); f = fit_log_slope(e, 5.0 * np.exp(-11.0 * e))
    >>> round(f["slope"], 9), round(float(np.exp(f["intercepts"][0])), 9)
    (-11.0, 5.0)
    """
    e = np.asarray(porosity, dtype=float)
    g = np.asarray(gradient, dtype=float)
    if e.shape != g.shape or e.ndim != 1:
        raise ValueError(f"porosity and gradient must be (N,) arrays, got {e.shape}, {g.shape}")
    if not np.all(np.isfinite(g) & (g > 0)):
        raise ValueError("every gradient must be finite and > 0 to take its logarithm")
    fam = np.zeros(e.size, int) if family is None else np.asarray(family)
    labels, idx = np.unique(fam, return_inverse=True)
    if e.size < labels.size + 1 or np.ptp(e) == 0:
        raise ValueError(f"need at least two porosities per fit, got {e.tolist()}")
    X = np.column_stack([e, np.eye(labels.size)[idx]])
    coef, *_ = np.linalg.lstsq(X, np.log(g), rcond=None)
    res = np.log(g) - X @ coef
    dof = e.size - X.shape[1]
    stderr = float("nan")
    if dof > 0:
        cov = (res @ res / dof) * np.linalg.pinv(X.T @ X)
        stderr = float(np.sqrt(cov[0, 0]))
    return {"slope": float(coef[0]), "slope_stderr": stderr,
            "rms_residual": float(np.sqrt(np.mean(res**2))),
            "intercepts": [float(c) for c in coef[1:]]}


def band_gradients(gradient, slope, offsets=BAND_OFFSETS) -> list[float]:
    """g exp(S Δε) for each offset Δε: the gradient at porosity ε + Δε.

    >>> [round(v, 6) for v in band_gradients(100.0, -10.0, (-0.01, 0.01))]
    [110.517092, 90.483742]
    """
    return [float(gradient * np.exp(slope * d)) for d in offsets]


def slope_at(velocity_m_s, velocities_m_s, slopes) -> float:
    """The band slope at one velocity: linear in ln U between the fitted velocities, held
    constant beyond them.

    >>> slope_at(0.1, [0.01, 1.0], [-12.0, -10.0])
    -11.0
    """
    lu = np.log(np.asarray(velocities_m_s, dtype=float))
    return float(np.interp(np.log(velocity_m_s), lu, np.asarray(slopes, dtype=float)))


def pack_band(packing: Packing, porosity: float, *, velocities_m_s, axis: str = "z",
              seeds=(1, 2), viscosity_pa_s: float, density_kg_m3: float,
              db=None) -> dict:
    """Pack and solve the band's beds; the fitted slope at each velocity (see the module).

    The packings have ``packing``'s grain count, its (volume-equivalent) diameter range and its
    bounding-box shape; solid fractions ``WALL_OFFSET - porosity + SF_STEPS``. Returns a dict:
    ``velocities_m_s``, ``slopes``, ``slope_stderrs``, ``rms_residuals`` (one per velocity),
    ``beds`` (seed, solid fraction, porosity, gradients, one per packing), ``n_spheres``,
    ``diameter_range_m``, ``packer`` and ``seconds``.
    """
    t0 = time.perf_counter()
    d = packing.grain_diameters
    drange = (float(d.min()), float(d.max()))
    lo = packing.centers.min(axis=0) - packing.radii.max()
    hi = packing.centers.max(axis=0) + packing.radii.max()
    aspect = tuple(float(v) for v in (hi - lo) / (hi - lo).min())
    us = sorted(float(u) for u in velocities_m_s)
    beds = []
    for seed in seeds:
        for step in SF_STEPS:
            sf = float(np.clip(WALL_OFFSET - porosity + step, 0.30, 0.63))
            p = random_packing(packing.n_grains, diameter_range_m=drange, solid_fraction=sf,
                               aspect=aspect, rng=int(seed))
            r = solve_network(p, axis=axis, conductance=ConductanceOptions(db=db),
                              flow=FlowOptions(viscosity_pa_s=viscosity_pa_s, velocity_m_s=us[0],
                                               inertia=True, density_kg_m3=density_kg_m3,
                                               curve_velocities_m_s=us[1:]))
            pts = r.curve_points()
            if not all(q["converged"] for q in pts):
                raise RuntimeError(f"band packing seed {seed}, solid fraction {sf:.3f}: the "
                                   "inertial solve did not converge")
            beds.append({"seed": int(seed), "solid_fraction": sf, "porosity": r.porosity,
                         "pressure_gradient_pa_per_m":
                             [q["pressure_gradient_pa_per_m"] for q in pts]})
            log.info("band bed seed %d phi %.3f: porosity %.4f", seed, sf, r.porosity)
    e = np.array([b["porosity"] for b in beds])
    fam = np.array([b["seed"] for b in beds])
    g = np.array([b["pressure_gradient_pa_per_m"] for b in beds])
    fits = [fit_log_slope(e, g[:, j], fam) for j in range(len(us))]
    return {"velocities_m_s": us, "slopes": [f["slope"] for f in fits],
            "slope_stderrs": [f["slope_stderr"] for f in fits],
            "rms_residuals": [f["rms_residual"] for f in fits], "beds": beds,
            "n_spheres": packing.n_grains, "diameter_range_m": list(drange),
            "packer": "network.packing.random_packing (geometric grow-and-push, no gravity or "
                      "friction; closed box of the packing's shape)",
            "seconds": time.perf_counter() - t0}


def measured_band(grain: str) -> dict | None:
    """The band of ``grain`` from its own multi-sphere DEM beds (:data:`GRAIN_BANDS`), or None.

    The bundled beds' porosities and gradients are fitted here as :func:`pack_band` fits its
    sphere beds (:func:`fit_log_slope`, one family), and the same keys are returned. Sphere beds
    of the grain's volume-equivalent size give a steeper slope: for wheat -11.2 / -10.9 / -10.6
    against its grain beds' -9.7 / -9.2 / -7.6 at 0.005 / 0.039 / 0.3 m/s
    (``docs/report.md``), so a grain with measured beds uses them.
    """
    path = GRAIN_BANDS.get(grain)
    if path is None:
        return None
    data = json.loads(path.read_text())
    e = np.array([b["porosity"] for b in data["beds"]])
    g = np.array([b["pressure_gradient_pa_per_m"] for b in data["beds"]])
    fits = [fit_log_slope(e, g[:, j]) for j in range(g.shape[1])]
    return {"velocities_m_s": list(data["velocities_m_s"]), "slopes": [f["slope"] for f in fits],
            "slope_stderrs": [f["slope_stderr"] for f in fits],
            "rms_residuals": [f["rms_residual"] for f in fits],
            "beds": [{"name": b["name"], "seed": b["seed"], "porosity": b["porosity"],
                      "pressure_gradient_pa_per_m": b["pressure_gradient_pa_per_m"]}
                     for b in data["beds"]],
            "packer": f"dem.pack (the grain's own multi-sphere beds, network/data/{path.name})",
            "source": data["source"], "seconds": 0.0}
