r"""Fits of a resistance curve (U, ΔP/L): Darcy-Forchheimer, ASABE D272 and Ergun refitted.

.. math:: \frac{\Delta P}{L} = \frac{\mu U}{k} + \beta\rho U^2, \qquad
          \frac{\Delta P}{L} = \frac{a U^2}{\ln(1+bU)}, \qquad
          \frac{\Delta P}{L} = A\frac{\mu(1-\varepsilon)^2U}{\varepsilon^3d^2}
                             + B\frac{\rho(1-\varepsilon)U^2}{\varepsilon^3 d}

Forchheimer and Ergun are linear least squares in (1/k, β) and (A, B) on the relative
gradient; D272 is fitted on log ΔP/L (b by bounded scalar search, a in closed form). Every fit
reports its residual: the RMS relative error of the gradient over the points.
"""

from __future__ import annotations

import numpy as np
from .._grains import grains_with_d272

__all__ = ["fit_curve", "GRAINS"]

#: The grains whose D272 constants have a source (the grain library, network._grains).
GRAINS = tuple(grains_with_d272())


#: The keys of :func:`fit_curve` (all None when fewer than two distinct velocities).
FIT_KEYS = ("permeability_m2", "forchheimer_beta_per_m", "forchheimer_residual",
            "permeability_residual", "d272_a", "d272_b", "d272_residual", "ergun_A", "ergun_B",
            "ergun_residual")


def _rms_rel(pred, grad):
    return float(np.sqrt(np.mean((pred / grad - 1.0) ** 2)))


def fit_curve(velocity_m_s, gradient_pa_per_m, *, viscosity_pa_s, density_kg_m3, porosity,
              diameter_m) -> dict:
    """Darcy/Forchheimer, D272 and Ergun fits of a curve (JSON keys :data:`FIT_KEYS`).

    >>> u = np.array([0.01, 0.1, 1.0]); gr = 2.0 * u + 3.0 * 1.2 * u**2
    >>> f = fit_curve(u, gr, viscosity_pa_s=1.0, density_kg_m3=1.2, porosity=0.4, diameter_m=0.01)
    >>> round(f["permeability_m2"], 9), round(f["forchheimer_beta_per_m"], 9)
    (0.5, 3.0)
    """
    u = np.asarray(velocity_m_s, dtype=float)
    gr = np.asarray(gradient_pa_per_m, dtype=float)
    mu, rho, e, d = map(float, (viscosity_pa_s, density_kg_m3, porosity, diameter_m))
    if np.unique(u).size < 2:
        # every fit has two constants: one velocity determines none of them
        return dict.fromkeys(FIT_KEYS)
    out: dict = {}
    # Forchheimer: gr = mu U / k + beta rho U^2, weighted by 1/gr (relative residuals)
    M = np.column_stack([mu * u, rho * u**2]) / gr[:, None]
    (ik, beta), *_ = np.linalg.lstsq(M, np.ones_like(u), rcond=None)
    out["permeability_m2"] = float(1.0 / ik)
    out["forchheimer_beta_per_m"] = float(beta)
    out["forchheimer_residual"] = _rms_rel(mu * u * ik + beta * rho * u**2, gr)
    out["permeability_residual"] = out["forchheimer_residual"]
    # D272 (Shedd / Hukill-Ives): for a given b, log a is the mean log misfit
    def a_of(b):
        return float(np.exp(np.mean(np.log(gr * np.log1p(b * u) / u**2))))

    def cost(logb):
        b = 10.0**logb
        return float(np.sum((np.log(a_of(b) * u**2 / np.log1p(b * u)) - np.log(gr)) ** 2))

    from scipy.optimize import minimize_scalar   # 50 ms to import: only the fits need it

    lb = minimize_scalar(cost, bounds=(-3.0, 6.0), method="bounded").x
    b = 10.0**lb
    out["d272_a"], out["d272_b"] = a_of(b), float(b)
    out["d272_residual"] = _rms_rel(out["d272_a"] * u**2 / np.log1p(b * u), gr)
    if 0 < e < 1 and d > 0:
        c1 = mu * (1 - e) ** 2 * u / (e**3 * d**2)
        c2 = rho * (1 - e) * u**2 / (e**3 * d)
        (A, B), *_ = np.linalg.lstsq(np.column_stack([c1, c2]) / gr[:, None],
                                     np.ones_like(u), rcond=None)
        out["ergun_A"], out["ergun_B"] = float(A), float(B)
        out["ergun_residual"] = _rms_rel(A * c1 + B * c2, gr)
    else:
        out["ergun_A"] = out["ergun_B"] = out["ergun_residual"] = None
    return out
