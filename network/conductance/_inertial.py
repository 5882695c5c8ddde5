r"""The conduit window law: each conduit's inertial (kinetic-energy) loss from its own geometry.

A conduit runs pore body P → window → pore body Q (:mod:`._conduit`). Its pressure drop is

.. math:: \Delta p = \frac{q}{g} + K_\pm\,q|q|\,\frac{t}{\sqrt{1+t^2}}, \qquad
          K = \frac{\rho}{2A_w^2}\,K_e(\sigma, \cos\theta), \qquad t = \frac{Re_w}{Re_c},

with :math:`A_w` the window's open area (:func:`throats.open_area` of the face) and
:math:`\sigma = A_w/A_b` the window-to-body area ratio of the body the flow expands into.
:math:`A_b` is the conduit's own section at the height of the pore body's centre (the face
triangle less the sphere sections of radius :math:`\sqrt{r_k^2-h_P^2}`, the last section of the
conduit model). A sphere-rounded window has no vena contracta (no contraction loss); the jet
expands against the outflow direction of the body it enters, :math:`K_e = 1 - 2\sigma\cos\theta
+ \sigma^2` (flat-profile momentum balance, :func:`expansion_coefficient`), with the share f of
its cross momentum that the body recovers, :math:`\cos\theta \to \cos\theta + f(1-\cos\theta)`
(:func:`turning_cosines`). The loss sets in with the window Reynolds number,
:math:`Re_c = k_\infty/(c_1 h/a)` (:func:`onset_scales`). The two constants :math:`c_1` and f of
each conduit come from its window ratio through :data:`CHAIN_WINDOW_TABLE`: steady 3-D
Navier-Stokes through a regular tetrahedral pore body in a chain at nine window ratios
(:func:`window_constants`). The reversible Bernoulli parts, :math:`\pm(1-\sigma^2)`, change the
static pressure of a body by its own kinetic energy and cancel along every path between inlet
and outlet bodies; they are left out so that every conduit's law is monotone (Newton's Jacobian
stays a weighted graph Laplacian). :func:`conduit_law` assembles the law. No coefficient is
fitted to bed-scale data. Derivation, the Navier-Stokes tables and the validation against
resolved flow and the drag laws: ``docs/inertial-flow.md``.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

import throats

from .._air import MU_AIR_PA_S, RHO_AIR_KG_M3, check_density, check_viscosity

__all__ = ["CHAIN_WINDOW_TABLE", "conduit_law", "expansion_coefficient", "inertial_coefficients",
           "onset_scales", "turning_cosines", "window_constants"]

#: The chained pore body's two constants as functions of the window ratio sigma: onset slope
#: :math:`c_1` (low-Re slope of the body's excess loss coefficient, :math:`dk/dRe_w = c_1 h/a`)
#: and recovered share f of the jet's cross momentum. Steady 3-D Navier-Stokes through a regular
#: tetrahedron of spheres (edge 2) with radii 0.97 / 0.95 / 0.90 / 0.85 / 0.80 / 0.75 / 0.70 /
#: 0.60 / 0.50 (``docs/scripts/inertial_pore_ns.py``): the loss a body causes in a chain is its
#: own excess dissipation k_body plus the kinetic energy its jets carry out through the three
#: outlet windows beyond what they carry at Re_w 5; its k(Re_w) = k_peak t/sqrt(1+t^2),
#: t = Re_w/Re_c, gives c_1 = k_peak/(Re_c h/a) (Re_c from Re_w 5 and 10), and f is the share
#: whose turning balance gives k_peak. One run per radius at h 0.10 with 8 / 6 / 4 elements
#: across the gaps between spheres (r 0.90 / 0.80-0.85 / the others):
#: ``docs/data/pore_ns_series.json``. Not fitted to bed data.
CHAIN_WINDOW_TABLE = {"sigma": (0.4925, 0.5457, 0.6371, 0.6952, 0.7352, 0.7642, 0.7861, 0.8167,
                                0.8365),
                      "onset_slope": (0.0857, 0.0949, 0.1089, 0.1149, 0.1158, 0.1111, 0.1060,
                                      0.0872, 0.0656),
                      "recovery": (-0.367, -0.052, 0.097, 0.143, 0.174, 0.211, 0.246, 0.332,
                                   0.429)}


def expansion_coefficient(sigma, *, cos_theta=1.0):
    r"""Loss coefficient of a sudden expansion from area ratio :math:`\sigma = A_1/A_2`.

    Momentum and energy balances between the expansion plane and the reattached flow with a
    flat profile on both sides give Borda-Carnot, :math:`K_e = (1-\sigma)^2` (per
    :math:`\rho V_1^2/2`). A jet at angle :math:`\theta` to the downstream flow recovers only
    its momentum component along it: :math:`K_e = 1 - 2\sigma\cos\theta + \sigma^2`.

    >>> float(expansion_coefficient(0.25)), float(expansion_coefficient(0.5, cos_theta=0.0))
    (0.5625, 1.25)
    """
    s = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
    c = np.clip(np.asarray(cos_theta, dtype=float), -1.0, 1.0)
    return 1.0 - 2.0 * s * c + s**2


def inertial_coefficients(tessellation, throats_idx, h_m, *, internal=None,
                          density_kg_m3: float = RHO_AIR_KG_M3, cos_theta=None):
    r"""Inertial coefficients K of M conduits for both flow directions, Pa s² m⁻⁶.

    :math:`K = \rho K_e / (2A_w^2)`, :math:`K_e` of the expansion into the body the flow enters
    (:func:`expansion_coefficient`); a sphere-rounded window adds no contraction loss.

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
    cos_theta : (M, 2) array_like, optional
        Turning cosine of each flow direction in the body it expands into
        (:func:`turning_cosines`, same column order); None: 1 (straight expansion).

    Returns
    -------
    K : (M, 2) ndarray
        Column 0 for flow from side 0 (``throat_pores[:, 0]``) to side 1, column 1 the
        reverse; 0 for closed windows and internal throats.
    """
    return _coefficients(_window_and_ratios(tessellation, throats_idx, h_m), internal=internal,
                         density_kg_m3=density_kg_m3, cos_theta=cos_theta)


def _coefficients(window, *, internal, density_kg_m3, cos_theta):
    """:func:`inertial_coefficients` from ``_window_and_ratios``'s (A_w, sigma, a)."""
    rho = check_density(density_kg_m3)
    a_w, sigma, _ = window
    ct = np.ones((sigma.shape[0], 2)) if cos_theta is None else np.asarray(cos_theta, float)
    ke = expansion_coefficient(sigma[:, ::-1], cos_theta=ct)[:, ::-1]
    with np.errstate(divide="ignore"):
        scale = np.where(a_w > 0, rho / (2.0 * a_w**2), 0.0)
    K = np.column_stack([ke[:, 1], ke[:, 0]]) * scale[:, None]
    if internal is not None:
        K[np.asarray(internal, dtype=bool)] = 0.0
    return K


def _window_and_ratios(tessellation, throats_idx, h_m, pool=None):
    """Open window area (M,), area ratios sigma (M, 2) per side, mean sphere radius (M,);
    the two body sections' areas on ``pool``'s threads when given (the same bits)."""
    idx = np.asarray(throats_idx, dtype=np.int64)
    h = np.asarray(h_m, dtype=float)
    if h.shape != (idx.size, 2):
        raise ValueError(f"h_m must have shape ({idx.size}, 2), got {h.shape}")
    radii = np.asarray(tessellation.throat_radii, dtype=float)[idx]
    sides = np.asarray(tessellation.throat_sides, dtype=float)[idx]
    point = 1e-12 * sides.min(axis=1, keepdims=True)

    def body_area(side):
        rk = np.sqrt(np.maximum(radii**2 - h[:, side, None] ** 2, 0.0))
        return np.asarray(throats.open_area(np.maximum(rk, point), sides), dtype=float)

    bodies = [pool.submit(body_area, side) for side in (0, 1)] if pool else None
    a_w = np.asarray(throats.open_area(radii, sides), dtype=float)
    sigma = np.empty((idx.size, 2))
    for side in (0, 1):
        a_b = bodies[side].result() if bodies else body_area(side)
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma[:, side] = np.where(a_b > 0, a_w / a_b, 1.0)
    return a_w, sigma, radii.mean(axis=1)


def onset_scales(tessellation, throats_idx, h_m, K, *, slope,
                 density_kg_m3: float = RHO_AIR_KG_M3, viscosity_pa_s: float = MU_AIR_PA_S):
    r"""Onset scale c of M conduits for both flow directions, s/m³: :math:`c|q| = Re_w/Re_c`.

    A pore body loses :math:`k(Re_w)\,\rho u_w^2/2` over its Stokes drop with
    :math:`k = k_\infty\,t/\sqrt{1+t^2}`, :math:`t = Re_w/Re_c`,
    :math:`Re_c = k_\infty/(c_1 h/a)`: the low-Re slope :math:`dk/dRe_w = c_1 h/a`
    (``slope`` :math:`c_1`, one number or (M, 2) per conduit and flow direction; h the
    window-to-body height, a the sphere radius) and the asymptote :math:`k_\infty`. Here
    :math:`k_\infty = 2A_w^2 K/\rho` is the conduit's own loss coefficient (``K`` from
    :func:`inertial_coefficients`, same columns), :math:`Re_w = \rho (|q|/A_w) D_w/\mu`,
    :math:`D_w = 2\sqrt{A_w/\pi}`, h of the side the flow expands into, a the mean radius of
    the window's spheres. 0 where K = 0.

    Returns
    -------
    c : (M, 2) ndarray
    """
    return _onset(_window_and_ratios(tessellation, throats_idx, h_m), h_m, K,
                  density_kg_m3=density_kg_m3, viscosity_pa_s=viscosity_pa_s, slope=slope)


def _onset(window, h_m, K, *, density_kg_m3, viscosity_pa_s, slope):
    """:func:`onset_scales` from ``_window_and_ratios``'s (A_w, sigma, a)."""
    rho = check_density(density_kg_m3)
    mu = check_viscosity(viscosity_pa_s)
    c1 = np.asarray(slope, dtype=float)
    if np.any(~np.isfinite(c1)) or np.any(c1 <= 0):
        raise ValueError(f"slope must be finite and > 0, got {slope!r}")
    a_w, _, a = window
    K = np.asarray(K, dtype=float)
    if K.shape != (a_w.size, 2):
        raise ValueError(f"K must have shape ({a_w.size}, 2), got {K.shape}")
    h = np.abs(np.asarray(h_m, dtype=float))[:, ::-1]        # flow 0 -> 1 expands into side 1
    with np.errstate(divide="ignore", invalid="ignore"):
        re_per_q = 2.0 * rho / (mu * np.sqrt(np.pi * a_w))
        k_inf = 2.0 * a_w[:, None] ** 2 * K / rho
        c = re_per_q[:, None] * c1 * h / (a[:, None] * k_inf)
    return np.where(np.isfinite(c) & (K > 0), c, 0.0)


def window_constants(sigma, table=None):
    r"""Onset slope :math:`c_1` and recovered share f of the chained pore body at window
    ratios ``sigma`` (any shape): linear in sigma between the rows of ``table`` (default
    :data:`CHAIN_WINDOW_TABLE`), the end rows' values outside them. Returns ``(c_1, f)``.

    >>> c1, f = window_constants([0.30, 0.6371, 0.95])
    >>> c1.round(4).tolist(), f.round(3).tolist()
    ([0.0857, 0.1089, 0.0656], [-0.367, 0.097, 0.429])
    """
    t = CHAIN_WINDOW_TABLE if table is None else table
    x = np.asarray(t["sigma"], dtype=float)
    if x.ndim != 1 or x.size < 1 or np.any(np.diff(x) <= 0):
        raise ValueError("the table's sigma must increase")
    s = np.asarray(sigma, dtype=float)
    return (np.interp(s, x, np.asarray(t["onset_slope"], dtype=float)),
            np.interp(s, x, np.asarray(t["recovery"], dtype=float)))


def _recovery(recovery):
    """``recovery`` as an array, checked to lie in [-1, 1]."""
    f = np.asarray(recovery, dtype=float)
    if np.any(~np.isfinite(f)) or np.any(f > 1.0) or np.any(f < -1.0):
        raise ValueError(f"recovery must lie in [-1, 1], got {recovery!r}")
    return f


class _now:
    """A call made at once, with the ``result()`` of a future (the one-thread path)."""

    def __init__(self, fn, *args):
        self.value = fn(*args)

    def result(self):
        return self.value


def turning_cosines(centers_m, throat_vertices, pore_xyz_m, conns, flow_m3_s, axis: int, *,
                    recovery: float = 0.0):
    r"""Cosine between each conduit's jet and the mean outflow of the body it enters, (M, 2).

    The jet leaves the window along the face normal :math:`d` (oriented from ``conns[:, 0]``
    to ``conns[:, 1]``); body Q sends its flow on along
    :math:`M_Q = \sum_{out} |q_g| o_g / \sum_{out} |q_g|` (outflow directions :math:`o_g`,
    weighted by ``flow_m3_s``, e.g. the Stokes flows); a body without outflow (outlet)
    takes the flow axis. Column 0: :math:`d\cdot M_{Q_1}` (flow 0 → 1), column 1:
    :math:`-d\cdot M_{Q_0}`. ``recovery`` f (-1 <= f <= 1) recovers that part of the cross
    momentum: :math:`\cos \to \cos + f(1-\cos)` (f = 0: none, the momentum balance above),
    a number or one per conduit and column ((M, 2)); f < 0 (a body losing more than the
    balance, :data:`CHAIN_WINDOW_TABLE`'s narrowest window) lowers the cosine, held at -1.
    """
    f = _recovery(recovery)
    x = np.asarray(centers_m, dtype=float)[np.asarray(throat_vertices, dtype=np.int64)]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    c = np.asarray(conns, dtype=np.int64)
    xyz = np.asarray(pore_xyz_m, dtype=float)
    n *= np.sign(np.einsum("ij,ij->i", n, xyz[c[:, 1]] - xyz[c[:, 0]]))[:, None]
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    q = np.asarray(flow_m3_s, dtype=float)
    up = np.where(q > 0, c[:, 0], c[:, 1])
    npores = xyz.shape[0]
    tot = np.bincount(up, np.abs(q), npores)
    M = np.stack([np.bincount(up, q * n[:, k], npores) for k in range(3)], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        M = np.where(tot[:, None] > 0, M / tot[:, None], np.eye(3)[int(axis)])
    cos = np.clip(np.column_stack([np.einsum("ij,ij->i", n, M[c[:, 1]]),
                                   -np.einsum("ij,ij->i", n, M[c[:, 0]])]), -1.0, 1.0)
    return np.clip(cos + f * (1.0 - cos), -1.0, 1.0)


def conduit_law(tessellation, throats_idx, h_m, *, pore_xyz_m, conns, stokes_flow_m3_s,
                axis: int, internal=None, density_kg_m3: float = RHO_AIR_KG_M3,
                viscosity_pa_s: float = MU_AIR_PA_S, table=None, threads: int = 1):
    r"""The window law of a sample's conduits: ``(K, onset_scale)``, both (M, 2).

    ``K`` (Pa s² m⁻⁶, :func:`inertial_coefficients`) with the expansion against each body's
    outflow direction of the Stokes flows ``stokes_flow_m3_s`` (:func:`turning_cosines`, which
    needs ``pore_xyz_m``, ``conns`` and the flow ``axis``); ``onset_scale`` (s/m³,
    :func:`onset_scales`). The onset slope :math:`c_1` and the recovered share f of each
    conduit and flow direction come from the window ratio sigma of the body the flow expands
    into (:func:`window_constants` on ``table``, default :data:`CHAIN_WINDOW_TABLE`). The law
    of a conduit is then :math:`\Delta p = q/g + K q|q|\,t/\sqrt{1+t^2}`, :math:`t = c|q|`
    (:func:`network.flow.conduit_flow`). ``threads`` > 1: the body sections' open areas and
    the turning cosines run on two more threads beside the window's (the same bits).
    """
    if stokes_flow_m3_s is None or pore_xyz_m is None or conns is None:
        raise ValueError("the window law needs the Stokes flows, pore positions and conns")
    pool = ThreadPoolExecutor(2) if int(threads) > 1 else None
    try:
        # the cosines without recovery (which comes from the window ratios below): the same
        # bits as with it, cos + f (1 - cos) being applied to them last either way
        bare = (pool.submit if pool else _now)(
            turning_cosines, tessellation.packing.centers,
            np.asarray(tessellation.throat_vertices)[throats_idx], pore_xyz_m, conns,
            stokes_flow_m3_s, axis)
        win = _window_and_ratios(tessellation, throats_idx, h_m, pool)  # for K and the onset
        cos = bare.result()
    finally:
        if pool:
            pool.shutdown()
    # column 0: flow 0 -> 1 expands into side 1
    onset_slope, recovery = window_constants(win[1][:, ::-1], table)
    cos = np.clip(cos + _recovery(recovery) * (1.0 - cos), -1.0, 1.0)
    K = _coefficients(win, internal=internal, density_kg_m3=density_kg_m3, cos_theta=cos)
    c = _onset(win, h_m, K, density_kg_m3=density_kg_m3, viscosity_pa_s=viscosity_pa_s,
               slope=onset_slope)
    return K, c
