r"""Inertial (kinetic-energy) loss of a conduit from its own geometry: contraction + expansion.

A conduit runs pore body P → window → pore body Q (:mod:`._conduit`). Its pressure drop is

.. math:: \Delta p = \frac{Q}{g} + K\,Q|Q|, \qquad
          K = \frac{\rho}{2A_w^2}\bigl[K_c(\sigma_\mathrm{up}) + K_e(\sigma_\mathrm{down})\bigr],

with :math:`A_w` the window's open area (:func:`throats.open_area` of the face) and
:math:`\sigma = A_w/A_b` the window-to-body area ratio on each side. :math:`A_b` is the conduit's
own section at the height of the pore body's centre (the face triangle less the sphere
sections of radius :math:`\sqrt{r_k^2-h_P^2}`, the last section of the conduit model). The
irreversible losses are those of El-Zehairy, Nezhad & Joekar-Niasar (2019, Adv. Water Resour.
131:103378; DuMux ``NonCreepingFlow``) with unit momentum and energy coefficients:
contraction to a vena contracta :math:`C_c = 1 - (1-\sigma)/(2.08(1-\sigma)+0.5371)`,
:math:`K_c = (1/C_c - 1)^2`, and Borda-Carnot expansion :math:`K_e = (1-\sigma)^2`. Their
reversible Bernoulli parts, :math:`\pm(1-\sigma^2)`, change the static pressure of a body by
its own kinetic energy and cancel along every path between inlet and outlet bodies; they are
left out so that every conduit's law is monotone (Newton's Jacobian stays a weighted graph
Laplacian). ``profile='laminar'`` takes the expansion's momentum and energy balances with the
Poiseuille-tube profile coefficients (alpha 2, beta 4/3) instead of flat ones; the weak-inertia
onset is the solver's (:func:`network.flow.conduit_flow`, ``crossover``). No coefficient is
fitted to bed-scale data. Derivation, measured onset and the validation against the LBM drag
laws: ``docs/inertial-flow.md``.
"""

from __future__ import annotations

import numpy as np

import throats

from .._air import RHO_AIR_KG_M3, check_density

__all__ = ["PROFILES", "contraction_coefficient", "expansion_coefficient",
           "inertial_coefficients"]


def contraction_coefficient(sigma):
    r"""Loss coefficient of a sudden contraction, :math:`K_c = (1/C_c-1)^2`, dimensionless.

    >>> float(contraction_coefficient(1.0)), round(float(contraction_coefficient(0.0)), 4)
    (0.0, 0.3824)
    """
    s = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
    cc = 1.0 - (1.0 - s) / (2.08 * (1.0 - s) + 0.5371)
    return (1.0 / cc - 1.0) ** 2


#: Kinetic-energy and momentum-flux coefficients (alpha, beta) of the velocity profile in the
#: window and downstream: a flat profile, or the laminar (Poiseuille) one of a circular tube.
PROFILES = {"uniform": (1.0, 1.0), "laminar": (2.0, 4.0 / 3.0)}


def expansion_coefficient(sigma, *, profile: str = "uniform"):
    r"""Loss coefficient of a sudden expansion from area ratio :math:`\sigma = A_1/A_2`.

    Momentum and energy balances between the expansion plane and the reattached flow, with
    profile coefficients :math:`(\alpha, \beta)` on both sides (:data:`PROFILES`):
    :math:`K_e = \alpha - 2\beta\sigma + (2\beta - \alpha)\sigma^2` (per
    :math:`\rho V_1^2/2`); Borda-Carnot :math:`(1-\sigma)^2` for a flat profile.

    >>> float(expansion_coefficient(0.25)), float(expansion_coefficient(0.0, profile="laminar"))
    (0.5625, 2.0)
    """
    if profile not in PROFILES:
        raise ValueError(f"profile must be one of {sorted(PROFILES)}, got {profile!r}")
    a, b = PROFILES[profile]
    s = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
    return a - 2.0 * b * s + (2.0 * b - a) * s**2


def inertial_coefficients(tessellation, throats_idx, h_m, *, internal=None,
                          density_kg_m3: float = RHO_AIR_KG_M3, profile: str = "uniform"):
    r"""Inertial coefficients K of M conduits for both flow directions, Pa s² m⁻⁶.

    Parameters
    ----------
    tessellation : Tessellation
    throats_idx : (M,) array_like of int
        Tessellation throats.
    h_m : (M, 2) array_like, m
        Conduit heights on each side of the window (``ConductanceResult.h_m``).
    internal : (M,) bool array_like, optional
        Throats inside one merged pore body: K = 0 (one pressure node).
    density_kg_m3 : float, keyword-only
        ρ (default 1.20 kg/m³).
    profile : {'uniform', 'laminar'}, keyword-only
        Velocity profile of the expansion loss (:func:`expansion_coefficient`).

    Returns
    -------
    K : (M, 2) ndarray
        Column 0 for flow from side 0 (``throat_pores[:, 0]``) to side 1, column 1 the
        reverse; 0 for closed windows and internal throats.
    """
    rho = check_density(density_kg_m3)
    idx = np.asarray(throats_idx, dtype=np.int64)
    h = np.asarray(h_m, dtype=float)
    if h.shape != (idx.size, 2):
        raise ValueError(f"h_m must have shape ({idx.size}, 2), got {h.shape}")
    radii = np.asarray(tessellation.throat_radii, dtype=float)[idx]
    sides = np.asarray(tessellation.throat_sides, dtype=float)[idx]
    a_w = np.asarray(throats.open_area(radii, sides), dtype=float)
    point = 1e-12 * sides.min(axis=1, keepdims=True)
    sigma = np.empty((idx.size, 2))
    for side in (0, 1):
        rk = np.sqrt(np.maximum(radii**2 - h[:, side, None] ** 2, 0.0))
        a_b = np.asarray(throats.open_area(np.maximum(rk, point), sides), dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma[:, side] = np.where(a_b > 0, a_w / a_b, 1.0)
    kc, ke = contraction_coefficient(sigma), expansion_coefficient(sigma, profile=profile)
    with np.errstate(divide="ignore"):
        scale = np.where(a_w > 0, rho / (2.0 * a_w**2), 0.0)
    K = np.column_stack([kc[:, 0] + ke[:, 1], kc[:, 1] + ke[:, 0]]) * scale[:, None]
    if internal is not None:
        K[np.asarray(internal, dtype=bool)] = 0.0
    return K
