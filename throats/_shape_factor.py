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

from ._geometry import as_throats, _closed_forms, _exact_area_perimeter, open_area_perimeter

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
    r, s = as_throats(radii, sides)
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
