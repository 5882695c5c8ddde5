r"""Reynolds-dependent drag laws of random sphere packings (lattice-Boltzmann fits).

Both laws give the dimensionless drag :math:`F(\phi, Re)` at solid fraction :math:`\phi` and
particle Reynolds number :math:`Re = \rho U d/\mu` from the **superficial** velocity U. The
network is compared through the ratio :math:`F(\phi,Re)/F(\phi,0)`, which for a fixed bed is
the ratio of the pressure gradient to its Darcy value, :math:`k/k_{app}` with
:math:`k_{app} = \mu U/(\Delta P/L)`: each paper normalises its inertial term like its Stokes
term, so the ratio needs no conversion of drag definitions (``docs/reference-permeabilities.md``).

* Beetstra, van der Hoef & Kuipers (2007) AIChE J. 53:489, Eq. (F0 + F1), as implemented in
  OpenFOAM's ``dragModels::Beetstra`` (``CdRe = 24 alpha2 (F0 + F1)`` with ``Res = alpha2 Re``,
  the superficial Reynolds number).
* Hill, Koch & Ladd (2001) J. Fluid Mech. 448:213 and 448:243: :math:`F = F_0 + F_1 Re_a^2`
  (weak inertia) below :math:`Re_a = F_3/F_1`, :math:`F = F_0 + F_3 Re_a` above, with
  :math:`Re_a = \rho U a/\mu = Re/2` (sphere radius); the coefficients for
  :math:`\phi \ge 0.4` as combined by Benyahia, Syamlal & O'Brien (2006, Powder Technol.
  162:166) and implemented in MFiX's ``KOCH_HILL`` drag (``RE_kh = 0.5 d VREL ROP_g / Mu``).

The two fits disagree with each other by several per cent at Re 5-50 (they were fitted to
different LB data sets, HKL's F1 Re² branch ending at a kink); the tables in
``docs/inertial-flow.md`` compare the network with both.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DRAG_LAWS", "beetstra_drag", "drag_ratio", "hill_koch_ladd_drag"]


def _args(solid_fraction, reynolds):
    phi = np.asarray(solid_fraction, dtype=float)
    re = np.asarray(reynolds, dtype=float)
    if np.any(~np.isfinite(phi)) or np.any((phi <= 0) | (phi >= 1)):
        raise ValueError(f"solid_fraction must lie in (0, 1), got {solid_fraction!r}")
    if np.any(~np.isfinite(re)) or np.any(re < 0):
        raise ValueError(f"reynolds must be finite and >= 0, got {reynolds!r}")
    return phi, re


def beetstra_drag(solid_fraction, reynolds):
    r"""Beetstra et al. (2007) drag :math:`F = F_0 + F_1`, normalised by :math:`3\pi\mu d U`.

    .. math:: F_0 = \frac{10\phi}{(1-\phi)^2} + (1-\phi)^2(1+1.5\sqrt\phi),\qquad
              F_1 = \frac{0.413\,Re}{24(1-\phi)^2}\,
                    \frac{(1-\phi)^{-1} + 3\phi(1-\phi) + 8.4\,Re^{-0.343}}
                         {1 + 10^{3\phi} Re^{-(1+4\phi)/2}}

    Re from the superficial velocity; :math:`F_1 \to 0` as Re → 0.

    >>> round(float(beetstra_drag(0.6, 0.0)), 4)
    37.8459
    """
    phi, re = _args(solid_fraction, reynolds)
    eps = 1.0 - phi
    f0 = 10.0 * phi / eps**2 + eps**2 * (1.0 + 1.5 * np.sqrt(phi))
    with np.errstate(divide="ignore", invalid="ignore"):
        f1 = (0.413 * re / (24.0 * eps**2)
              * (1.0 / eps + 3.0 * phi * eps + 8.4 * re**-0.343)
              / (1.0 + 10.0 ** (3.0 * phi) * re ** (-(1.0 + 4.0 * phi) / 2.0)))
    return f0 + np.where(re > 0, f1, 0.0)


def hill_koch_ladd_drag(solid_fraction, reynolds):
    r"""Hill, Koch & Ladd (2001) moderate-Re drag of random arrays, :math:`\phi \ge 0.4`.

    .. math:: F_0 = \frac{10\phi}{(1-\phi)^3},\quad F_1 = 0.11 + 5.1\times10^{-4}e^{11.6\phi},
              \quad F_3 = 0.0673 + 0.212\phi + \frac{0.0232}{(1-\phi)^5},

    :math:`F = F_0 + F_1 Re_a^2` for :math:`Re_a \le F_3/F_1`, else :math:`F_0 + F_3 Re_a`,
    :math:`Re_a = Re/2` (normalised by :math:`6\pi\mu a U`, U superficial).

    >>> round(float(hill_koch_ladd_drag(0.6, 0.0)), 4)
    93.75
    """
    phi, re = _args(solid_fraction, reynolds)
    if np.any(phi < 0.4):
        raise ValueError("the Hill-Koch-Ladd dense fit holds for solid_fraction >= 0.4, got "
                         f"{solid_fraction!r}")
    ra = 0.5 * re
    f0 = 10.0 * phi / (1.0 - phi) ** 3
    f1 = 0.11 + 5.1e-4 * np.exp(11.6 * phi)
    f3 = 0.0673 + 0.212 * phi + 0.0232 / (1.0 - phi) ** 5
    return np.where(ra <= f3 / f1, f0 + f1 * ra**2, f0 + f3 * ra)


#: name -> drag function(solid_fraction, reynolds)
DRAG_LAWS = {"beetstra": beetstra_drag, "hill_koch_ladd": hill_koch_ladd_drag}


def drag_ratio(law: str, solid_fraction, reynolds):
    r""":math:`F(\phi, Re)/F(\phi, 0)`: the law's :math:`k/k_{app}` (gradient over Darcy's).

    >>> float(drag_ratio("beetstra", 0.6, 0.0))
    1.0
    """
    if law not in DRAG_LAWS:
        raise ValueError(f"law must be one of {sorted(DRAG_LAWS)}, got {law!r}")
    f = DRAG_LAWS[law]
    return f(solid_fraction, reynolds) / f(solid_fraction, 0.0 * np.asarray(reynolds, float))
