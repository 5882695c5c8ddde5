r"""Overburden: the vertical stress of the grain above a bed, and a lid that applies it.

A bed at depth z of a bin of diameter D carries the weight of the grain above it less what the
walls hold by friction (Janssen 1895):

.. math:: \sigma_v(z) = \frac{\rho_b g D}{4 \mu_w K}\left(1 - e^{-4 \mu_w K z / D}\right)

with bulk density :math:`\rho_b`, wall friction :math:`\mu_w` and lateral pressure ratio
:math:`K = \sigma_h/\sigma_v` (:func:`janssen_stress`). Near the surface it is the weight of the
column, :math:`\rho_b g z`; deep down it tends to :math:`\rho_b g D/(4\mu_w K)`.

:func:`load_bed` puts a rigid lid on a settled bed and moves it under servo control until the
mean lid stress holds the target and the bed is at rest. The servo is PFC's wall servo: each
step the lid moves by

.. math:: \Delta z = \alpha\, \frac{A (\sigma - \sigma^*)}{n_c k_n},

capped at :math:`v_{max}\Delta t` (A the lid's area, σ its stress from its contact forces, σ*
the target, :math:`n_c` its contacts of normal stiffness :math:`k_n`, α = 0.3 < 1 for stability:
the lid closes a fraction α of the gap in force that its contacts' stiffness predicts). The
measured lid stress is the mean over the last ``average_steps`` steps.
"""

from __future__ import annotations

import math

import numpy as np

from ._walls import PlaneWall

__all__ = ["janssen_stress", "load_bed", "SERVO_GAIN", "LID_SPEED_M_S", "MAX_STRESS_PA"]

#: fraction α of the force gap the lid closes per step
SERVO_GAIN = 0.3
#: largest lid speed, m/s
LID_SPEED_M_S = 0.05
#: largest lid stress the command lines take, Pa: twice the deep-bin limit of Janssen's stress,
#: rho_b g D / (4 mu_w K), of every library grain with Janssen inputs in a bin 40 m across
#: (0.35-0.47 MPa at rho_b 850 kg/m^3); a larger stress is a slip (1e9 for 1e4), which the lid
#: would drive to a DEM blow-up only after the whole pour
MAX_STRESS_PA = 1.0e6


def janssen_stress(depth_m, *, bulk_density_kg_m3, diameter_m, wall_friction, lateral_ratio, g=9.81):
    r"""Janssen's vertical stress at depth ``depth_m`` in a bin of diameter ``diameter_m``, Pa (module notes).

    Parameters
    ----------
    depth_m : float or array, m (>= 0)
    bulk_density_kg_m3 : float
    diameter_m : float
    wall_friction : float
        :math:`\mu_w` > 0.
    lateral_ratio : float
        K > 0.

    >>> round(janssen_stress(10.0, bulk_density_kg_m3=750.0, diameter_m=6.0, wall_friction=0.5,
    ...                      lateral_ratio=0.54))
    34118
    """
    z = np.asarray(depth_m, dtype=float)
    for name, v in (("bulk density", bulk_density_kg_m3), ("diameter", diameter_m), ("wall friction", wall_friction),
                    ("lateral pressure ratio", lateral_ratio)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be finite and > 0, got {v!r}")
    if np.any(~np.isfinite(z) | (z < 0)):
        raise ValueError(f"depth must be finite and >= 0, got {depth_m!r}")
    a = 4 * wall_friction * lateral_ratio / diameter_m
    out = bulk_density_kg_m3 * g / a * -np.expm1(-a * z)
    return float(out) if out.ndim == 0 else out


def load_bed(sim, container, stress_pa, *, tol=2e-3, stress_tol=0.02, max_steps=60_000, check_every=200,
             average_steps=2000, callback=None):
    """Load a settled bed through a rigid lid servo-controlled to ``stress_pa`` (module notes).

    The lid starts at the highest sphere top and closes on the bed; the run ends when the mean
    unbalanced-force ratio is below ``tol`` and the lid stress, averaged over the last
    ``average_steps`` steps, is within ``stress_tol`` (relative) of the target, or after
    ``max_steps`` steps. ``sim`` keeps its lid (the last wall). Grains frozen in a pour
    (:mod:`dem._freeze`) are released first: the lid loads the whole bed.

    Returns dict: ``target_pa``, ``lid_stress_pa`` (the average), ``lid_stress_rel_error``,
    ``lid_height_m``, ``steps``, ``ratio``, ``converged``.
    """
    if not (math.isfinite(stress_pa) and stress_pa > 0):
        raise ValueError(f"lid stress must be > 0, got {stress_pa!r}")
    if getattr(sim, "active", None) is not None:   # the load acts on the whole bed: no grain stays frozen
        sim.detach_active()
    xs = sim.sphere_centers()
    z_lid = float(np.max(xs[:, 2] + sim.radii))
    old_shear, old_touch = sim.wall_shear.copy(), sim._wall_touch.copy()
    walls = list(sim.walls) + [PlaneWall((0.0, 0.0, z_lid), (0.0, 0.0, -1.0), "lid", moves=False)]
    sim.set_walls(walls)
    sim.wall_shear[:-1], sim._wall_touch[:-1] = old_shear, old_touch
    k_lid = len(walls) - 1
    area = container.area_m2
    kn = sim.material.kn_pw
    dz_max = LID_SPEED_M_S * sim.dt
    hist = []
    ratio, k = float("inf"), 0
    converged = False
    for k in range(1, max_steps + 1):
        force = sim.step()
        fn = sim._wall_fn[k_lid]
        touching = sim._wall_touch[k_lid].view(bool)
        sigma = float(fn[touching].sum()) / area
        hist.append(sigma)
        n_c = int(touching.sum())
        gap = SERVO_GAIN * area * (sigma - stress_pa) / (max(n_c, 1) * kn)
        dz = float(np.clip(gap, -dz_max, dz_max))
        z_lid += dz
        sim.walls[k_lid] = PlaneWall((0.0, 0.0, z_lid), (0.0, 0.0, -1.0), "lid", moves=False)
        sim._wall_offset_at = None
        if k % check_every == 0:
            sim.check_stability()
            ratio = sim.unbalanced_force_ratio(force)
            if callback is not None:
                callback(sim, force)
            if k >= average_steps:
                mean = float(np.mean(hist[-average_steps:]))
                if ratio < tol and abs(mean - stress_pa) <= stress_tol * stress_pa:
                    converged = True
                    break
    mean = float(np.mean(hist[-min(average_steps, len(hist)):]))
    return {"target_pa": float(stress_pa), "lid_stress_pa": mean, "lid_stress_rel_error": mean / stress_pa - 1,
            "lid_height_m": z_lid, "steps": k, "ratio": ratio, "converged": converged,
            "servo": {"gain": SERVO_GAIN, "max_speed_m_s": LID_SPEED_M_S, "average_steps": average_steps,
                      "stress_tol": stress_tol}}
