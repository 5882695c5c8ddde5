r"""The thesis's throat conductance (Eq. 3.41): the window's Q* over the pore length 2r̄.

.. math:: g = \frac{Q}{\Delta P} = \frac{Q^* \bar r^4}{\mu L}, \qquad L = 2 \bar r,
          \qquad \bar r = (r_1 + r_2 + r_3)/3 .

The window's narrowest cross-section is taken to run the whole pore length, which over-resists
(k 0.24-0.63 of exact on sphere arrays, ``docs/conduit-model.md``); kept to reproduce the thesis.
"""

from __future__ import annotations

import numpy as np

from .._air import MU_AIR_PA_S, check_viscosity

__all__ = ["thesis_conductance"]


def thesis_conductance(qstar, radii_m, *, viscosity_pa_s: float = MU_AIR_PA_S):
    r"""Throat conductance of thesis Eq. 3.41, m³ Pa⁻¹ s⁻¹, shape (N,).

    .. math:: g = \frac{Q^* \bar r^4}{\mu L}, \quad L = 2\bar r
              \;\Longrightarrow\; g = \frac{Q^* \bar r^3}{2 \mu}

    Parameters
    ----------
    qstar : (N,) array_like
        Dimensionless flow rate in mean-radius units (0 for a closed throat).
    radii_m : (N, 3) array_like, m
        Radii of the three spheres of each throat.
    viscosity_pa_s : float, optional
        Dynamic viscosity μ (default 1.932e-5 Pa·s, air, as in the thesis).

    Returns
    -------
    (N,) ndarray, m³ Pa⁻¹ s⁻¹

    Examples
    --------
    A circular tube of radius r̄ = 1 mm (Q* = π/8) over L = 2 mm is Hagen–Poiseuille,
    g = π r⁴/(8 μ L):

    >>> import numpy as np
    >>> g = thesis_conductance([np.pi / 8], [[1e-3, 1e-3, 1e-3]], viscosity_pa_s=1e-3)
    >>> bool(np.isclose(g[0], np.pi * 1e-12 / (8 * 1e-3 * 2e-3)))
    True
    """
    q = np.asarray(qstar, dtype=float)
    r = np.asarray(radii_m, dtype=float)
    if r.ndim != 2 or r.shape[1] != 3 or q.shape != (r.shape[0],):
        raise ValueError(f"qstar (N,) and radii (N, 3) expected, got {q.shape} and {r.shape}")
    mu = check_viscosity(viscosity_pa_s)
    if np.any(q < 0):
        raise ValueError("qstar must be >= 0 (NaN marks a failed throat: resolve it first)")
    rbar = r.mean(axis=1)
    return q * rbar**4 / (mu * 2.0 * rbar)
