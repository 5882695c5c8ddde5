r"""Shape-factor estimate of Q* (Patzek & Silin 2001 form), vectorised, microseconds or less.

For a duct of area A and wetted perimeter P, Patzek & Silin (2001) write the conductance as
:math:`g = c\,A^2 G/\mu` with the shape factor :math:`G = A/P^2` (c = 3/5 for triangles,
1/2 for circles).  In units of r̄:

.. math:: Q^* \approx c_t\, A^{*2}\, G, \qquad G = A^*/P^{*2},

with :math:`A^*` the exact open area and :math:`P^*` the no-slip (arc) perimeter of the open
region (the symmetry segments carry no shear), and one constant :math:`c_t` per contact type
t = a, b, c, d fitted to finite-element Q* (``throats.bench --fit``; data and errors in
:data:`FIT`).  Against FE on throats of random 5.5–7.5 mm packings its relative error has
median 0.21 and 95th percentile 0.54 (type d: 0.035 / 0.12; type a: 0.24 / 0.76): a
screening estimate, not a substitute for the FE solve.

A and P come from closed forms when the disks neither reach the opposite edge nor have a
common (triple) overlap (the usual case):

.. math::
    A = A_\triangle - \tfrac12\sum_i \theta_i r_i^2
        + \tfrac12\sum_{i<j \text{ overlapping}} L_{ij},\qquad
    P = \sum_i \theta_i r_i - \sum_{i<j \text{ overlapping}} (\alpha_i r_i + \alpha_j r_j),

with :math:`\theta_i` the triangle angle at vertex i, :math:`\alpha_i` the half-angle at
centre i of the chord through the two circle intersection points
(:math:`\cos\alpha_i = (l_{ij}^2 + r_i^2 - r_j^2)/(2 l_{ij} r_i)`) and
:math:`L_{ij} = \sum_{k\in\{i,j\}} r_k^2(\alpha_k - \sin\alpha_k\cos\alpha_k)` the lens
area.  Other rows use the exact boundary engine of :mod:`throats._geometry`.

References
----------
Patzek, T. W., Silin, D. B. (2001). Shape factor and hydraulic conductance in noncircular
capillaries I. One-phase creeping flow. J. Colloid Interface Sci. 236, 295–304.
"""

from __future__ import annotations

import numpy as np

from ._geometry import _as_throats, _region_boundary, triangle_vertices

__all__ = ["FIT", "open_area_perimeter", "shape_factor_qstar"]

#: fitted constants c_t per contact type and the record of the fit (``throats.bench --fit``)
FIT = {
    "c": {"a": 0.6868, "b": 0.7511, "c": 0.8293, "d": 0.9215},
    # c_t = exp(median(log(Q*_FE / (A*^3 / P*^2)))) over the throats of type t
    "data": ("1600 interior Delaunay faces of random 5.5-7.5 mm packings "
             "(throats._sampling.sample_throats(1600, rng=2026); 572 a, 690 b, 289 c, 49 d), "
             "Q*_FE from solve_fem(rtol=1e-4), SOLVER_VERSION 1.0; versions up to 1.3 move "
             "those Q* by < 1e-4, far below the fit error"),
    "median_rel_error": 0.206,
    "p95_rel_error": 0.537,
    "per_type": {"a": (0.242, 0.758), "b": (0.239, 0.522), "c": (0.138, 0.276),
                 "d": (0.035, 0.116)},   # (median, p95) of |Q_sf / Q_FE - 1|
    "holdout": "fit on even rows, tested on odd rows: median 0.204, p95 0.521",
}


def _exact_area_perimeter(r, s):
    """Exact A and arc perimeter from the boundary engine (units of r̄ in, out)."""
    v = triangle_vertices(s)
    res = _region_boundary(v, v, r)
    cu, con = res["cu"], res["con"]
    dth = 2 * np.pi * (np.nan_to_num(cu[..., 1:]) - np.nan_to_num(cu[..., :-1]))
    per = np.sum(np.where(con, dth * r[:, :, None], 0.0), axis=(1, 2))
    return res["area"], per


def open_area_perimeter(radii_star, sides_star):
    """Open area A* and no-slip (arc) perimeter P* of throats in units of r̄, (N,) each.

    Closed forms for the usual case, the exact engine for disks that reach the opposite
    edge or share a triple overlap (module docstring).  Inputs must be valid throats.
    """
    r = np.ascontiguousarray(np.asarray(radii_star, dtype=float).T)   # (3, N) rows
    s = np.ascontiguousarray(np.asarray(sides_star, dtype=float).T)
    area, per, hard = _closed_forms(r, s)
    if hard.any():
        area[hard], per[hard] = _exact_area_perimeter(r[:, hard].T, s[:, hard].T)
    return np.maximum(area, 0.0), per


def _closed_forms(r, s):
    """Closed-form A, P and the mask of rows that need the exact engine; r, s are (3, N)."""
    l12, l13, l23 = s
    q12, q13, q23 = l12 * l12, l13 * l13, l23 * l23
    th = np.arccos(np.clip(np.array([(q12 + q13 - q23) / (2 * l12 * l13),
                                     (q12 + q23 - q13) / (2 * l12 * l23),
                                     (q13 + q23 - q12) / (2 * l13 * l23)]), -1.0, 1.0))
    sp = 0.5 * (l12 + l13 + l23)
    a_tri = np.sqrt(np.maximum(sp * (sp - l12) * (sp - l13) * (sp - l23), 0.0))
    rth = th * r
    area = a_tri - 0.5 * (rth[0] * r[0] + rth[1] * r[1] + rth[2] * r[2])
    per = rth[0] + rth[1] + rth[2]
    # altitudes h_i = 2 A / (opposite side); a disk reaching its opposite edge -> exact path
    two_a = 2 * a_tri
    hard = (r[0] * l23 >= two_a) | (r[1] * l13 >= two_a) | (r[2] * l12 >= two_a)
    for i, j, k, l, lik in ((0, 1, 2, l12, l13), (0, 2, 1, l13, l12), (1, 2, 0, l23, l12)):
        ri, rj = r[i], r[j]
        ov = l < ri + rj
        if not ov.any():
            continue
        idx = np.flatnonzero(ov)
        ri, rj, l, lik = ri[idx], rj[idx], l[idx], lik[idx]
        ci = np.clip((l * l + ri * ri - rj * rj) / (2 * l * ri), -1.0, 1.0)
        cj = np.clip((l * l + rj * rj - ri * ri) / (2 * l * rj), -1.0, 1.0)
        ai, aj = np.arccos(ci), np.arccos(cj)
        lens = ri * ri * (ai - np.sqrt(1 - ci * ci) * ci) \
            + rj * rj * (aj - np.sqrt(1 - cj * cj) * cj)
        area[idx] += 0.5 * lens
        per[idx] -= ai * ri + aj * rj
        # lens outside the angular sectors, or its corner (on the triangle side of edge ij)
        # inside the third disk -> exact path; distance from vertex k by the law of cosines
        # with the angle theta_i - alpha_i between the directions i->k and i->corner
        d2 = ri * ri + lik * lik - 2 * ri * lik * np.cos(th[i, idx] - ai)
        hard[idx] |= (ai > th[i, idx]) | (aj > th[j, idx]) | (d2 <= r[k, idx] ** 2)
    return area, per, hard


def shape_factor_qstar(radii, sides):
    r"""Fast Q* estimate (units of r̄⁴): :math:`Q^* \approx c_t A^{*2} G`, :math:`G = A^*/P^{*2}`.

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``.

    Returns
    -------
    (N,) ndarray
        Q* estimate; 0 where the disks cover the triangle; NaN for invalid rows.

    Notes
    -----
    Constants per contact type and the error of the fit against finite elements are in
    :data:`throats._shape_factor.FIT`.  Vectorised: over 1e6 throats per second.

    Examples
    --------
    >>> q = shape_factor_qstar([[1, 1, 1]], [[2, 2, 2]])
    >>> bool(0 < q[0] < 1e-3)
    True
    """
    r, s = _as_throats(radii, sides)
    r = np.ascontiguousarray(r.T)
    s = np.ascontiguousarray(s.T)
    with np.errstate(invalid="ignore"):
        srt = np.sort(s, axis=0)
        ok = (np.isfinite(r).all(0) & np.isfinite(s).all(0) & (r > 0).all(0)
              & (srt[0] > 0) & (srt[2] < srt[0] + srt[1]))
    if not ok.all():
        r, s = r[:, ok], s[:, ok]
    rbar = (r[0] + r[1] + r[2]) / 3.0
    r = r / rbar
    s = s / rbar
    area, per, hard = _closed_forms(r, s)
    if hard.any():
        area[hard], per[hard] = _exact_area_perimeter(r[:, hard].T, s[:, hard].T)
    # contact type inline (same rule as throats.contact_type, gap_tol = 1e-9)
    n_contact = ((s[0] - r[0] - r[1] <= 1e-9).astype(np.int8)
                 + (s[1] - r[0] - r[2] <= 1e-9) + (s[2] - r[1] - r[2] <= 1e-9))
    c = np.array([FIT["c"][t] for t in "abcd"])[n_contact]
    with np.errstate(invalid="ignore", divide="ignore"):
        q = np.where(area > 0, c * area**3 / per**2, 0.0)
    out = np.full(ok.shape[0], np.nan)
    out[ok] = q
    return out
