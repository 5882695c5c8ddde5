r"""Reference permeabilities of sphere packings: periodic arrays and random beds (Stokes flow).

The numbers the network model is checked against; derivations of the drag-to-permeability
conversions and the full account of the sources: ``docs/reference-permeabilities.md``.
All functions are vectorised over the solid fraction :math:`\phi = 1 - \varepsilon` and return
permeability in the units of the radius or diameter passed in, squared:

* simple cubic, exact: Zick & Homsy (1982) J. Fluid Mech. 115:13, Table 2,
  :math:`k = 2a^2/(9\phi K)`; dilute series of Sangani & Acrivos (1982);
* BCC and FCC: our own Stokes FE of the symmetry cell (Taylor-Hood P2/P1, Richardson-
  extrapolated; tables :data:`STOKES_CELL_BCC`, :data:`STOKES_CELL_FCC`);
* random monodisperse packings: the LBM drag law of van der Hoef, Beetstra & Kuipers (2005)
  J. Fluid Mech. 528:233, :math:`k = (1-\phi) d^2/(18\phi F)`;
* Kozeny-Carman and the viscous Ergun term (sanity references).
"""

from __future__ import annotations

import functools
import logging

import numpy as np

from ..packing import TOUCHING_FRACTION

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


@functools.lru_cache(maxsize=None)
def _log_interpolant(name):
    """Monotone (PCHIP) interpolant of ln K or ln k of a table, built on first use (scipy's
    interpolate module costs 0.2-0.4 s to import, which network.solve does not need)."""
    from scipy.interpolate import PchipInterpolator

    table = {"ZICK_HOMSY_SC": ZICK_HOMSY_SC, "STOKES_CELL_BCC": STOKES_CELL_BCC,
             "STOKES_CELL_FCC": STOKES_CELL_FCC}[name]
    return PchipInterpolator(table[:, 0], np.log(table[:, 1]),
                             extrapolate=False if name == "ZICK_HOMSY_SC" else True)


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
    out[mid] = np.exp(_log_interpolant("ZICK_HOMSY_SC")(phi[mid]))
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
    f = _log_interpolant(f"STOKES_CELL_{k.upper()}")
    return np.exp(f(np.clip(phi, table[0, 0], table[-1, 0]))) * float(lattice_constant) ** 2
