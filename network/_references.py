r"""Reference permeabilities of sphere packings: periodic arrays and random beds (Stokes flow).

These are the numbers the network model is checked against. All functions are vectorised
over the solid fraction :math:`\phi` (volume of spheres per total volume, :math:`1-\varepsilon`)
and return permeability in the units of the radius or diameter passed in, squared.

From drag to permeability
-------------------------
In steady Stokes flow through a periodic array (or a statistically homogeneous bed) the mean
pressure gradient balances the *total* hydrodynamic force on the spheres, per unit volume:
:math:`-\nabla p = n F_{tot}`, with :math:`n = \phi / (\tfrac43 \pi a^3)` spheres per unit
volume. Darcy's law for the superficial (volume-averaged over fluid and solid) velocity
:math:`U` is :math:`U = -(k/\mu)\nabla p`, hence

.. math:: k = \frac{\mu U}{n F_{tot}}.

*Zick & Homsy (1982)* report :math:`K = F_{tot} / (6\pi\mu a U)` with :math:`U` the mean
velocity over the unit cell (superficial), so

.. math:: k = \frac{2 a^2}{9 \phi K}.   \qquad (1)

Check: an isolated sphere (:math:`K \to 1`) gives the Stokes value :math:`2a^2/(9\phi)`.

*van der Hoef, Beetstra & Kuipers (2005)* and *Beetstra et al. (2007)* report
:math:`F = F_d / (3\pi\mu d U)` with :math:`U` superficial and :math:`F_d` the drag force
*without* the part of the fluid force that the mean pressure gradient exerts on the sphere's
volume, :math:`F_{tot} = F_d - V_p \nabla p`. With :math:`-\nabla p = n F_{tot}` this gives
:math:`F_d = (1-\phi) F_{tot}`, hence

.. math:: k = \frac{(1-\phi)\, d^2}{18 \phi F}.   \qquad (2)

Check: their dense-limit term :math:`F = 10\phi/(1-\phi)^2` then gives exactly the
Kozeny-Carman law :math:`k = d^2 (1-\phi)^3 / (180 \phi^2)`, which is how those authors
describe it; and their normalisation of the Ergun law,
:math:`F = 150\phi / (18 (1-\phi)^2)`, gives Ergun's viscous term
:math:`k = d^2\varepsilon^3/(150(1-\varepsilon)^2)` (the same normalisation as in the
waLBerla drag-correlation module, ``DragForceCorrelations.h``). Without the :math:`(1-\phi)`
factor neither would hold.

Sources and what is tabulated here
----------------------------------
* **Simple cubic (SC) array, exact**: Zick, A. A. & Homsy, G. M. (1982) *Stokes flow through
  periodic arrays of spheres*, J. Fluid Mech. 115, 13-26, **Table 2**: drag coefficient
  :math:`K` (dimensionless, definition above) at :math:`\phi` = 0.027, 0.064, 0.125, 0.216,
  0.343, 0.45, 0.5236 (touching). The seven values were taken from the Basilisk test suite
  (``basilisk.fr/src/test/spheres.c``, "adapted from Table 2 of Zick and Homsy, 1982"); the
  same seven values are quoted, cross-checked against the paper, in the PoreWise
  verification notes, and the pystokes periodic example quotes the mobilities
  :math:`1/K` = 0.4980, 0.3559, 0.2330, 0.1344, 0.06494 for the first five. Between
  tabulated points :math:`\ln K` is interpolated monotonically (PCHIP) in :math:`\phi`;
  below 0.027 the dilute series below is used.
* **SC dilute series**: Sangani, A. S. & Acrivos, A. (1982) *Slow flow through a periodic
  array of spheres*, Int. J. Multiphase Flow 8, 343-360 (extending Hasimoto 1959):
  :math:`1/K = 1 - 1.7601\chi + \chi^3 - 1.5593\chi^6 + 3.9799\chi^8 - 3.0734\chi^{10}`,
  :math:`\chi = \phi^{1/3}`. It reproduces the Zick-Homsy table to 0.1 % for
  :math:`\phi \le 0.125` and 0.8 % at 0.216 (tested), which cross-validates both.
* **BCC and FCC arrays**: Zick & Homsy (1982) also tabulate BCC and FCC over the full range,
  but those tables **could not be found in the stored reference material** available to this
  project (only the abstract, and the SC table as quoted above). No BCC/FCC values are entered
  here rather than entering numbers from memory. :func:`lattice_permeability` raises
  ``NotImplementedError`` for them, naming this gap.
* **Random monodisperse packings (LBM)**: van der Hoef, M. A., Beetstra, R. & Kuipers, J. A. M.
  (2005) J. Fluid Mech. 528, 233-254, Stokes-limit fit to their lattice-Boltzmann data
  (also Beetstra, van der Hoef & Kuipers 2007, AIChE J. 53, 489-501, Re -> 0 limit):
  :math:`F = 10\phi/(1-\phi)^2 + (1-\phi)^2(1 + 1.5\sqrt{\phi})`, converted with (2). Their
  data cover :math:`0.1 \le \phi \le 0.6`; the stated fit accuracy is a few per cent. The
  paper's own tables of LB values were not available here, so the tests check the fit's
  published limits (Stokes drag at :math:`\phi\to 0`, Kozeny-Carman term) and the
  conversion, not a tabulated LB number.
* **BCC and FCC arrays, computed here** (not literature): Stokes flow in the 1/8 symmetry
  cell :math:`[0, a/2]^3` of the cubic cell (mirror planes of all three lattices), Taylor-Hood
  P2/P1 finite elements (gmsh + scikit-fem), no slip on the spheres, symmetry on the lateral
  planes, a unit pressure drop as traction on the planes normal to the flow;
  :math:`k = \int u_x\,dV / (a/2)^2`. Meshes of size 0.05a and 0.04a, Richardson-extrapolated
  (order 2). The same solver reproduces Zick & Homsy's simple-cubic table to +0.01 % (phi =
  0.45) and +0.2 % (0.3) after extrapolation (+1.0-1.1 % at 0.05a), and the extrapolation
  correction is 0.6-2.2 % for BCC/FCC; the solver is in ``tests/test_network_references_stokes.py``,
  which re-derives a coarse value. Tables :data:`STOKES_CELL_BCC`, :data:`STOKES_CELL_FCC`:
  (phi, k/a^2) with a the lattice constant; :func:`computed_lattice_permeability`.
* **Kozeny-Carman** (sanity reference): :math:`k = d^2\varepsilon^3/(180(1-\varepsilon)^2)`.
* **Ergun, viscous term**: :math:`k = d^2\varepsilon^3/(150(1-\varepsilon)^2)`.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.interpolate import PchipInterpolator

from ._lattices import TOUCHING_FRACTION

__all__ = [
    "ZICK_HOMSY_SC",
    "zick_homsy_sc_drag",
    "sangani_acrivos_sc_drag",
    "drag_to_permeability",
    "lattice_permeability",
    "beetstra_stokes_drag",
    "beetstra_permeability",
    "kozeny_carman_permeability",
    "ergun_viscous_permeability",
    "STOKES_CELL_BCC",
    "STOKES_CELL_FCC",
    "computed_lattice_permeability",
]

logger = logging.getLogger(__name__)

#: Zick & Homsy (1982) J. Fluid Mech. 115:13-26, Table 2, simple cubic array:
#: columns (solid fraction phi, drag coefficient K = F / (6 pi mu a U), U superficial).
ZICK_HOMSY_SC = np.array([
    [0.027, 2.008],
    [0.064, 2.810],
    [0.125, 4.292],
    [0.216, 7.442],
    [0.343, 15.4],
    [0.45, 28.1],
    [0.5236, 42.1],
])

#: Computed here (module notes): BCC array, columns (phi, k / a_lattice^2), Stokes flow,
#: Taylor-Hood FE in the 1/8 symmetry cell, Richardson-extrapolated from h = 0.05a, 0.04a.
STOKES_CELL_BCC = np.array([
    [0.30, 6.38581e-03],
    [0.40, 3.16442e-03],
    [0.50, 1.54446e-03],
    [0.60, 7.21956e-04],
    [0.66, 4.46669e-04],
])

#: As :data:`STOKES_CELL_BCC` for the FCC array.
STOKES_CELL_FCC = np.array([
    [0.30, 3.97404e-03],
    [0.45, 1.33121e-03],
    [0.55, 5.92101e-04],
    [0.65, 2.30504e-04],
    [0.72, 1.10398e-04],
])

_ZH_SC_LOGK = PchipInterpolator(ZICK_HOMSY_SC[:, 0], np.log(ZICK_HOMSY_SC[:, 1]), extrapolate=False)


def _phi(solid_fraction, upper=1.0, name="solid_fraction"):
    # a 1e-4 relative excess over the touching fraction is accepted (published 0.5236 vs pi/6)
    phi = np.asarray(solid_fraction, dtype=float)
    if not np.all(np.isfinite(phi)) or np.any(phi <= 0.0) or np.any(phi > upper * (1 + 1e-4)):
        raise ValueError(f"{name} must lie in (0, {upper:.6g}], got {solid_fraction!r}")
    return np.minimum(phi, upper)


def sangani_acrivos_sc_drag(solid_fraction):
    r"""Dilute series for the drag coefficient K of a simple cubic array.

    .. math:: K^{-1} = 1 - 1.7601\chi + \chi^3 - 1.5593\chi^6 + 3.9799\chi^8 - 3.0734\chi^{10},
              \quad \chi = \phi^{1/3}

    Sangani & Acrivos (1982), Int. J. Multiphase Flow 8:343. Accurate to < 1 % for
    :math:`\phi \lesssim 0.2` (checked against Zick & Homsy's table); not for dense arrays.

    Parameters
    ----------
    solid_fraction : array_like
        :math:`\phi` in (0, pi/6].

    Returns
    -------
    K : ndarray
        :math:`F / (6\pi\mu a U)`, dimensionless.

    Examples
    --------
    >>> round(float(sangani_acrivos_sc_drag(0.125)), 3)   # Zick & Homsy Table 2: 4.292
    4.289
    """
    chi = np.cbrt(_phi(solid_fraction, TOUCHING_FRACTION["sc"]))
    inv = 1 - 1.7601 * chi + chi**3 - 1.5593 * chi**6 + 3.9799 * chi**8 - 3.0734 * chi**10
    return 1.0 / inv


def zick_homsy_sc_drag(solid_fraction):
    r"""Exact Stokes drag coefficient K of a simple cubic array (Zick & Homsy 1982, Table 2).

    PCHIP interpolation of :math:`\ln K` between the tabulated fractions
    (:data:`ZICK_HOMSY_SC`), the Sangani-Acrivos series below :math:`\phi` = 0.027.
    The tabulated points are reproduced exactly.

    Parameters
    ----------
    solid_fraction : array_like
        :math:`\phi` in (0, pi/6].

    Returns
    -------
    K : ndarray
        :math:`F / (6\pi\mu a U)` with U the superficial velocity.

    Examples
    --------
    >>> round(float(zick_homsy_sc_drag(0.45)), 9)
    28.1
    """
    phi = _phi(solid_fraction, TOUCHING_FRACTION["sc"])
    lo = phi < ZICK_HOMSY_SC[0, 0]
    hi = phi >= TOUCHING_FRACTION["sc"] * (1.0 - 1e-9)   # the table's 0.5236 is touching
    mid = ~lo & ~hi
    out = np.empty_like(phi)
    out[mid] = np.exp(_ZH_SC_LOGK(phi[mid]))
    out[hi] = ZICK_HOMSY_SC[-1, 1]
    out[lo] = sangani_acrivos_sc_drag(phi[lo])
    return out[()] if out.ndim == 0 else out


def drag_to_permeability(drag_k, solid_fraction, radius):
    r"""Permeability from a Zick-Homsy drag coefficient: :math:`k = 2a^2/(9\phi K)`.

    Parameters
    ----------
    drag_k : array_like
        :math:`K = F_{tot}/(6\pi\mu a U)`, U superficial.
    solid_fraction : array_like
        :math:`\phi`.
    radius : array_like
        Sphere radius :math:`a` (any length unit; k comes out in that unit squared).

    Examples
    --------
    An isolated sphere (K = 1) at phi = 2/9 gives k = a**2:

    >>> float(drag_to_permeability(1.0, 2 / 9, 1.0))
    1.0
    """
    K = np.asarray(drag_k, dtype=float)
    phi = _phi(solid_fraction)
    a = np.asarray(radius, dtype=float)
    if np.any(K <= 0) or np.any(a <= 0):
        raise ValueError("drag coefficient and radius must be positive")
    return 2.0 * a**2 / (9.0 * phi * K)


def lattice_permeability(kind: str, solid_fraction, radius):
    r"""Exact Stokes permeability of a periodic sphere array, :math:`k = 2a^2/(9\phi K)`.

    Parameters
    ----------
    kind : {'sc', 'bcc', 'fcc'}
        Only 'sc' is available (Zick & Homsy 1982 Table 2); see the module notes.
    solid_fraction : array_like
        :math:`\phi` in (0, touching].
    radius : array_like
        Sphere radius (k is returned in its unit squared).

    Raises
    ------
    NotImplementedError
        For 'bcc' and 'fcc': their published tables were not available to this project.
    ValueError
        Unknown lattice or fraction out of range.

    Examples
    --------
    Touching SC spheres of radius 1 (lattice constant 2): K = 42.1,

    >>> round(float(lattice_permeability('sc', np.pi / 6, 1.0)), 6)
    0.010081
    """
    k = str(kind).lower()
    if k == "sc":
        phi = _phi(solid_fraction, TOUCHING_FRACTION["sc"])
        return drag_to_permeability(zick_homsy_sc_drag(phi), phi, radius)
    if k in ("bcc", "fcc"):
        raise NotImplementedError(
            f"no exact Stokes table for {k.upper()} arrays is entered: Zick & Homsy (1982) "
            "tabulate it, but the table was not found in the reference material available "
            "to this project (see network._references notes)")
    raise ValueError(f"unknown lattice {kind!r}; expected 'sc', 'bcc' or 'fcc'")


def beetstra_stokes_drag(solid_fraction):
    r"""Stokes-limit drag of random monodisperse sphere packings from LBM.

    .. math:: F = \frac{10\phi}{(1-\phi)^2} + (1-\phi)^2 (1 + 1.5\sqrt{\phi})

    van der Hoef, Beetstra & Kuipers (2005) J. Fluid Mech. 528:233; Beetstra et al. (2007)
    AIChE J. 53:489. :math:`F = F_d/(3\pi\mu d U)`, U superficial, :math:`F_d` the drag
    without the mean-pressure-gradient force (module notes). Fitted for 0.1 <= phi <= 0.6.

    Examples
    --------
    >>> round(float(beetstra_stokes_drag(0.4)), 4)
    11.8126
    """
    phi = _phi(solid_fraction, 0.999)
    return 10.0 * phi / (1.0 - phi) ** 2 + (1.0 - phi) ** 2 * (1.0 + 1.5 * np.sqrt(phi))


def beetstra_permeability(solid_fraction, diameter):
    r"""Permeability of a random monodisperse packing from the LBM drag law.

    .. math:: k = \frac{(1-\phi)\,d^2}{18\,\phi\,F(\phi)}

    Parameters
    ----------
    solid_fraction : array_like
        :math:`\phi = 1 - \varepsilon` (0.55-0.64 for the porosities 0.36-0.45 of grain beds).
    diameter : array_like
        Sphere diameter (for a polydisperse bed the Sauter mean is the usual choice).

    Examples
    --------
    Porosity 0.40, d = 1: k/d^2 = 0.6/(18*0.6*F(0.6)),

    >>> round(float(beetstra_permeability(0.6, 1.0)), 7)
    0.0009786
    """
    phi = _phi(solid_fraction, 0.999)
    d = np.asarray(diameter, dtype=float)
    if np.any(d <= 0):
        raise ValueError("diameter must be positive")
    return (1.0 - phi) * d**2 / (18.0 * phi * beetstra_stokes_drag(phi))


def kozeny_carman_permeability(porosity, diameter):
    r"""Kozeny-Carman permeability :math:`k = d^2\varepsilon^3 / (180(1-\varepsilon)^2)`.

    Examples
    --------
    >>> round(float(kozeny_carman_permeability(0.4, 1.0)), 7)
    0.0009877
    """
    eps = np.asarray(porosity, dtype=float)
    if np.any(~np.isfinite(eps)) or np.any(eps <= 0) or np.any(eps >= 1):
        raise ValueError(f"porosity must lie in (0, 1), got {porosity!r}")
    return np.asarray(diameter, dtype=float) ** 2 * eps**3 / (180.0 * (1.0 - eps) ** 2)


def ergun_viscous_permeability(porosity, diameter):
    r"""Permeability of Ergun's viscous term.

    .. math:: k = d^2\varepsilon^3 / (150(1-\varepsilon)^2)
    """
    eps = np.asarray(porosity, dtype=float)
    if np.any(~np.isfinite(eps)) or np.any(eps <= 0) or np.any(eps >= 1):
        raise ValueError(f"porosity must lie in (0, 1), got {porosity!r}")
    return np.asarray(diameter, dtype=float) ** 2 * eps**3 / (150.0 * (1.0 - eps) ** 2)


def computed_lattice_permeability(kind: str, solid_fraction, lattice_constant=1.0):
    r"""Stokes permeability of BCC/FCC arrays computed in this project (not literature).

    PCHIP interpolation of :math:`\ln k` in phi between the tabulated fractions of
    :data:`STOKES_CELL_BCC` / :data:`STOKES_CELL_FCC` (0.30-0.66 BCC, 0.30-0.72 FCC; outside
    that range ``ValueError``). See the module notes for the solver and its check against
    Zick & Homsy's simple-cubic table.

    Parameters
    ----------
    kind : {'bcc', 'fcc'}
    solid_fraction : array_like
    lattice_constant : float
        Cubic cell edge a (k is returned in its unit squared).

    Examples
    --------
    >>> round(float(computed_lattice_permeability('bcc', 0.5)), 8)
    0.00154446
    """
    k = str(kind).lower()
    table = {"bcc": STOKES_CELL_BCC, "fcc": STOKES_CELL_FCC}.get(k)
    if table is None:
        raise ValueError(f"computed tables exist for 'bcc' and 'fcc', got {kind!r}")
    phi = np.asarray(solid_fraction, dtype=float)
    if np.any(~np.isfinite(phi)) or np.any(phi < table[0, 0] - 1e-12) or \
            np.any(phi > table[-1, 0] + 1e-12):
        raise ValueError(f"solid_fraction must lie in [{table[0, 0]}, {table[-1, 0]}] for "
                         f"{k}, got {solid_fraction!r}")
    f = PchipInterpolator(table[:, 0], np.log(table[:, 1]))
    return np.exp(f(np.clip(phi, table[0, 0], table[-1, 0]))) * float(lattice_constant) ** 2
