r"""Open area and no-slip perimeter of throats: closed forms, with the exact engine behind them.

The open (fluid) area of a throat is the triangle minus the union of its three disks,
:math:`A = |T \setminus (D_1 \cup D_2 \cup D_3)|`, and its no-slip perimeter P is the length
of the disk arcs on the boundary (the triangle-edge pieces are symmetry lines and carry no
shear).  In the usual case (no disk reaches the opposite edge, no point shared by all three
disks) both have closed forms, with a lens term for each overlapping pair; the derivation is
in ``docs/throats-open-area.md``.  The other rows go through the boundary engine
(:mod:`throats._boundary`, Green's theorem), which is exact for every valid triangle of disks.
"""

from __future__ import annotations

import numpy as np

from ._area_kernel import area_perimeter_rows
from ._boundary import TOL, region_boundary
from ._geometry import as_throats, check_rows, mean_radius, triangle_vertices

__all__ = ["area_perimeter_columns", "boundary_area_perimeter", "closed_forms", "exact_area_perimeter",
           "open_area", "open_area_perimeter"]


def exact_area_perimeter(r, s):
    """Exact A and arc perimeter of (N, 3) rows ``r``, ``s`` (units of r̄ in, out): the boundary
    engine's construction as one compiled loop (:mod:`throats._area_kernel`, equal to
    :func:`boundary_area_perimeter` to 1e-14)."""
    return area_perimeter_rows(triangle_vertices(s), r, TOL)


def boundary_area_perimeter(r, s):
    """Exact A and arc perimeter from the vectorised boundary engine (units of r̄ in, out):
    the reference that :func:`exact_area_perimeter`'s loop is tested against."""
    v = triangle_vertices(s)
    res = region_boundary(v, v, r)
    cu, con = res["cu"], res["con"]
    dth = 2 * np.pi * (np.nan_to_num(cu[..., 1:]) - np.nan_to_num(cu[..., :-1]))
    per = np.sum(np.where(con, dth * r[:, :, None], 0.0), axis=(1, 2))
    return res["area"], per


def open_area_perimeter(radii_star, sides_star):
    """Open area A* and no-slip (arc) perimeter P* of throats in units of r̄, (N,) each.

    Inputs must be valid throats, (N, 3) each; see :func:`area_perimeter_columns`.
    """
    r = np.ascontiguousarray(np.asarray(radii_star, dtype=float).T)   # (3, N) rows
    s = np.ascontiguousarray(np.asarray(sides_star, dtype=float).T)
    return area_perimeter_columns(r, s)


def area_perimeter_columns(r, s):
    """A* and P* of valid throats given as (3, N) rows ``r``, ``s`` in units of r̄ (fast layout).

    Closed forms for the usual case (derivation: ``docs/throats-open-area.md``), the exact
    boundary engine for rows where a disk reaches the opposite edge or three disks overlap.
    """
    area, per, hard = closed_forms(r, s)
    if hard.any():
        area[hard], per[hard] = exact_area_perimeter(r[:, hard].T, s[:, hard].T)
    return np.maximum(area, 0.0), per


def closed_forms(r, s):
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


def open_area(radii, sides):
    r"""Exact open (fluid) area of N throats: triangle minus the union of the three disks.

    .. math:: A = |T \setminus (D_1 \cup D_2 \cup D_3)|
              = \tfrac12 \oint_{\partial\Omega} (x\,dy - y\,dx)

    evaluated in closed form over the boundary pieces (segments of the triangle edges, arcs of
    the circles).  Exact when disks overlap each other (no lens subtracted twice), when a disk
    reaches across the opposite edge (the open region may split into pieces), and 0 when the
    disks cover the triangle.  Without overlaps it reduces to
    :math:`A_\triangle - \tfrac12\sum_i \theta_i r_i^2` (:math:`\theta_i` the angle at vertex i).

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``.  Rows with non-finite or non-positive
        values, or sides that do not form a triangle, give NaN.

    Returns
    -------
    (N,) ndarray, in input units squared.

    Examples
    --------
    Three touching unit disks leave the cusped region √3 − π/2; in a 3-4-5 triangle three
    r = 0.5 sectors add up to half a disk of radius 0.5:

    >>> open_area([[1, 1, 1], [0.5, 0.5, 0.5]], [[2, 2, 2], [3, 4, 5]]).round(12).tolist()
    [0.161254480774, 5.607300918301]
    """
    r, s = as_throats(radii, sides)
    ok, _ = check_rows(r, s, deep_overlap=False)
    out = np.full(r.shape[0], np.nan)
    if not ok.any():
        return out
    rbar = mean_radius(r[ok])
    rs = r[ok] / rbar[:, None]
    ss = s[ok] / rbar[:, None]
    area, _ = open_area_perimeter(rs, ss)
    out[ok] = area * rbar**2
    return out
