r"""Shape-factor estimate of Q* (Patzek & Silin 2001 form), vectorised, microseconds or less.

For a duct of area A and wetted perimeter P, Patzek & Silin (2001) write the conductance as
:math:`g = c\,A^2 G/\mu` with the shape factor :math:`G = A/P^2` (c = 3/5 for triangles,
1/2 for circles).  In units of r̄:

.. math:: Q^* \approx c_t\, A^{*2}\, G, \qquad G = A^*/P^{*2},

with :math:`A^*` the exact open area and :math:`P^*` the no-slip (arc) perimeter of the open
region (:mod:`throats._area`), and one constant :math:`c_t` per contact type t = a, b, c, d
fitted to finite-element Q* (``python -m throats.bench --fit``); types b and c with a deep
overlap (a pair closer than :math:`r_i + r_j - 0.2\bar r`, two spheres of one multi-sphere
grain) have their own (``FIT["deep"]``).  :data:`FIT` records the fit:
the constants come from a fit at commit 1404360 on sampled packing throats, and their error
is measured on ``network.sample_throats`` throats.  Both records, and how to refit, are in
``docs/throats-shape-factor.md``.  A screening estimate (median error about 0.2, 95th
percentile about 0.5), not a substitute for the FE solve.

References
----------
Patzek, T. W., Silin, D. B. (2001). Shape factor and hydraulic conductance in noncircular
capillaries I. One-phase creeping flow. J. Colloid Interface Sci. 236, 295–304.
"""

from __future__ import annotations

import numpy as np

from ._area import area_perimeter_columns
from ._geometry import as_throats, contact_count

__all__ = ["FIT", "deep_overlap", "shape_factor_qstar"]

#: fitted constants c_t per contact type and the record of the fit (``throats.bench --fit``)
FIT = {
    "c": {"a": 0.6868, "b": 0.7511, "c": 0.8293, "d": 0.9215},
    # c_t = exp(median(log(Q*_FE / (A*^3 / P*^2)))) over the throats of type t
    "data": ("fitted at commit 1404360 on 1600 interior Delaunay faces of random 5.5-7.5 mm "
             "packings of that commit's throats._sampling.sample_throats(1600, rng=2026) "
             "(400 spheres, solid fraction 0.57, overlap relaxation; 572 a, 690 b, 289 c, 49 d), "
             "Q*_FE from solve_fem(rtol=1e-4), SOLVER_VERSION 1.0; versions up to 1.3 move "
             "those Q* by < 1e-4, far below the fit error"),
    "median_rel_error": 0.206,
    "p95_rel_error": 0.537,
    "per_type": {"a": (0.242, 0.758), "b": (0.239, 0.522), "c": (0.138, 0.276),
                 "d": (0.035, 0.116)},   # (median, p95) of |Q_sf / Q_FE - 1|
    "holdout": "fit on even rows, tested on odd rows: median 0.204, p95 0.521",
    # the same constants measured on the project's one sampler (docs/throats-shape-factor.md)
    "remeasured": {
        "data": ("network.sample_throats(1600, rng=2026) (1500 spheres, solid fraction 0.57, "
                 "closed box; 368 a, 761 b, 435 c, 36 d), Q*_FE from solve_fem(rtol=1e-4), "
                 "SOLVER_VERSION 1.3"),
        "median_rel_error": 0.221,
        "p95_rel_error": 0.504,
        "per_type": {"a": (0.258, 1.083), "b": (0.232, 0.405), "c": (0.195, 0.288),
                     "d": (0.194, 0.209)},
    },
    # deep overlaps (a pair closer than r_i + r_j - 0.2 r̄: two spheres of one multi-sphere
    # grain, never two grains in contact) are another shape: with the constants above their Q*
    # came out 2.2 times the FE value. Their own c_t for types b and c, fitted as above on the
    # windows of the bundled soybean clump bed that the shipped table does not serve, checked
    # on the bundled wheat bed's (docs/throats-shape-factor.md, "Deep overlaps";
    # docs/scripts/fit_deep_overlap.py)
    "deep": {
        "gap": -0.2,
        "c": {"b": 0.3366, "c": 0.9535},
        "data": ("network/data/soybean_grains.csv (495 six-sphere grains): the 21 142 "
                 "windows outside the shipped table's gap range, 14 691 b and 2 156 c with a "
                 "deep overlap, Q*_FE from solve_fem(rtol=1e-3), SOLVER_VERSION 1.3"),
        "checked": ("network/data/wheat_grains.csv (678 eight-sphere grains), its 14 115 "
                    "sample windows outside the table: median Q_sf / Q_FE - 1 from +1.165 to "
                    "-0.027 (p5 / p95 -0.415 / +0.005); permeability of that bed, table-only "
                    "against FE windows, +13.5 % -> -0.24 %"),
    },
}


def shape_factor_qstar(radii, sides):
    r"""Fast Q* estimate (units of r̄⁴): :math:`Q^* \approx c_t A^{*2} G`, :math:`G = A^*/P^{*2}`.

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        A throat a row, as everywhere in :mod:`throats`; only the shape matters.

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
    with np.errstate(invalid="ignore"):
        srt = np.sort(s, axis=1)
        ok = (np.isfinite(r).all(1) & np.isfinite(s).all(1) & (r > 0).all(1)
              & (srt[:, 0] > 0) & (srt[:, 2] < srt[:, 0] + srt[:, 1]))
    if not ok.all():
        r, s = r[ok], s[ok]
    rbar = (r[:, 0] + r[:, 1] + r[:, 2]) / 3.0
    r = r / rbar[:, None]
    s = s / rbar[:, None]
    area, per = area_perimeter_columns(np.ascontiguousarray(r.T), np.ascontiguousarray(s.T))
    kind = contact_count(r, s, 1.0)
    plain = np.array([FIT["c"][t] for t in "abcd"])
    deep = np.array([FIT["deep"]["c"].get(t, FIT["c"][t]) for t in "abcd"])
    c = np.where(_deep(r, s), deep[kind], plain[kind])
    with np.errstate(invalid="ignore", divide="ignore"):
        q = np.where(area > 0, c * area**3 / per**2, 0.0)
    out = np.full(ok.shape[0], np.nan)
    out[ok] = q
    return out


def deep_overlap(radii, sides):
    r"""True where a pair of the throat's disks overlaps deeper than ``FIT["deep"]["gap"]``
    (:math:`l_{ij} - r_i - r_j < -0.2\,\bar r`: two spheres of one multi-sphere grain), the
    rows whose estimate uses the deep-overlap constants. (N,) bool; False for invalid rows.

    >>> deep_overlap([[1, 1, 1], [1, 1, 1]], [[1.5, 2.3, 2.3], [1.99, 2.3, 2.3]]).tolist()
    [True, False]
    """
    r, s = as_throats(radii, sides)
    with np.errstate(invalid="ignore", divide="ignore"):
        rbar = (r[:, 0] + r[:, 1] + r[:, 2]) / 3.0
        out = _deep(r / rbar[:, None], s / rbar[:, None])
    return out & np.isfinite(rbar) & (rbar > 0)


def _deep(r, s):
    """Deep-overlap rows of radii and sides in units of r̄ (float (N, 3) arrays)."""
    gap = np.minimum(np.minimum(s[:, 0] - r[:, 0] - r[:, 1], s[:, 1] - r[:, 0] - r[:, 2]),
                     s[:, 2] - r[:, 1] - r[:, 2])
    return gap < FIT["deep"]["gap"]
