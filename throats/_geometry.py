r"""Geometry of triangular throat cross-sections, vectorised over N throats.

A throat is the face shared by two Delaunay tetrahedra: three sphere centres with radii
``radii = [r1, r2, r3]`` and side lengths ``sides = [l12, l13, l23]`` (any consistent length
unit).  The face plane cuts each sphere in a great circle, so the open (fluid) cross-section is

.. math:: \Omega = T \setminus (D_1 \cup D_2 \cup D_3),

the triangle :math:`T` minus three disks centred on its vertices.

Everything here is exact closed-form geometry (no meshing): the open area is obtained by
Green's theorem, :math:`A = \tfrac12 \oint_{\partial\Omega} (x\,dy - y\,dx)`, over the boundary
of :math:`\Omega`, which is assembled from pieces of the three triangle edges and the three
circles.  Each primitive curve is split at its intersections with all the others; a sub-piece
belongs to :math:`\partial\Omega` when its midpoint lies in the closure of every other set that
makes up :math:`\Omega`.  This is exact for disks that overlap each other, cover the triangle
or reach across the opposite edge, and the same engine (:func:`_region_boundary`) gives the
mesher its boundary curves, tagged by the set they come from.
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = ["as_throats", "canonical_form", "contact_type", "open_area", "validate_throats",
           "triangle_vertices"]

logger = logging.getLogger(__name__)

#: column of ``sides`` holding the side between vertices (i, j)
_PAIR_COL = {(0, 1): 0, (1, 0): 0, (0, 2): 1, (2, 0): 1, (1, 2): 2, (2, 1): 2}
#: vertex pairs in the column order of ``sides``
_PAIRS = ((0, 1), (0, 2), (1, 2))
_PERMS = ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0))

#: geometric tolerance in mean-radius units used by the boundary engine
_TOL = 1e-11


def as_throats(radii, sides):
    """Convert to two float (N, 3) arrays (a single (3,) row is accepted as N = 1).

    Raises ``TypeError`` for non-numeric input and ``ValueError`` for other shapes.
    """
    try:
        r = np.atleast_2d(np.asarray(radii, dtype=float))
        s = np.atleast_2d(np.asarray(sides, dtype=float))
    except (TypeError, ValueError) as exc:
        raise TypeError(f"radii and sides must be numeric arrays: {exc}") from exc
    if r.ndim != 2 or r.shape[1] != 3 or s.shape != r.shape:
        raise ValueError(f"expected radii and sides of shape (N, 3), got {r.shape} and {s.shape}")
    return r, s


def mean_radius(radii):
    """Mean radius r̄ = (r1 + r2 + r3)/3 of each row, (N,), permutation-exact (sorted sum)."""
    r = np.sort(np.atleast_2d(np.asarray(radii, dtype=float)), axis=1)
    return (r[:, 0] + r[:, 1] + r[:, 2]) / 3.0


def triangle_vertices(sides):
    r"""Planar vertex coordinates of N triangles, (N, 3, 2), counter-clockwise.

    Vertex 1 at the origin, vertex 2 on the +x axis, vertex 3 above it:

    .. math:: x_3 = \frac{l_{12}^2 + l_{13}^2 - l_{23}^2}{2 l_{12}},\quad
              y_3 = \sqrt{l_{13}^2 - x_3^2}.

    Parameters
    ----------
    sides : (N, 3) array_like
        ``[l12, l13, l23]`` in any length unit.

    Returns
    -------
    (N, 3, 2) ndarray, same unit as ``sides``.
    """
    s = np.atleast_2d(np.asarray(sides, dtype=float))
    l12, l13, l23 = s[:, 0], s[:, 1], s[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        x3 = (l12**2 + l13**2 - l23**2) / (2.0 * l12)
        y3 = np.sqrt(np.maximum(l13**2 - x3**2, 0.0))
    v = np.zeros((s.shape[0], 3, 2))
    v[:, 1, 0] = l12
    v[:, 2, 0] = x3
    v[:, 2, 1] = y3
    return v


def triangle_area(sides):
    """Area of N triangles from their sides, Heron's formula in Kahan's stable form.

    Parameters
    ----------
    sides : (N, 3) array_like
        Side lengths, any unit (rows that are no triangle give 0).

    Returns
    -------
    (N,) ndarray, the unit squared.

    Examples
    --------
    >>> triangle_area([[3.0, 4.0, 5.0]]).tolist()
    [6.0]
    """
    a = np.sort(np.asarray(sides, dtype=float), axis=1)[:, ::-1]  # a >= b >= c
    a, b, c = a[:, 0], a[:, 1], a[:, 2]
    prod = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c))
    return 0.25 * np.sqrt(np.maximum(prod, 0.0))


def canonical_form(radii, sides):
    r"""Scale-, permutation- and mirror-invariant form of N throats.

    Lengths are divided by the mean radius :math:`\bar r = (r_1+r_2+r_3)/3`, then the vertex
    order is chosen among the six permutations as the one whose row
    ``[r1, r2, r3, l12, l13, l23]`` is lexicographically smallest.  A throat is fixed by its
    radii and side lengths alone, so rotations, translations and mirror images of the face
    are already the same input; permutations of the vertices and uniform scaling give the
    same canonical row.

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``.

    Returns
    -------
    radii_star, sides_star : (N, 3) ndarray, dimensionless (units of r̄)

    Examples
    --------
    >>> r, s = canonical_form([[2.0, 1.0, 3.0]], [[3.5, 5.0, 4.5]])
    >>> r.round(3).tolist(), s.round(3).tolist()
    ([[0.5, 1.0, 1.5]], [[1.75, 2.25, 2.5]])
    """
    r, s = as_throats(radii, sides)
    rbar = mean_radius(r)[:, None]
    r = r / rbar
    s = s / rbar
    cand = np.empty((r.shape[0], 6, 6))
    for k, (a, b, c) in enumerate(_PERMS):
        cand[:, k, 0:3] = r[:, [a, b, c]]
        cand[:, k, 3] = s[:, _PAIR_COL[a, b]]
        cand[:, k, 4] = s[:, _PAIR_COL[a, c]]
        cand[:, k, 5] = s[:, _PAIR_COL[b, c]]
    alive = np.ones((r.shape[0], 6), dtype=bool)
    for col in range(6):
        v = np.where(alive, cand[:, :, col], np.inf)
        alive &= v == v.min(axis=1, keepdims=True)
    best = np.argmax(alive, axis=1)
    out = cand[np.arange(r.shape[0]), best]
    return out[:, :3].copy(), out[:, 3:].copy()


def contact_type(radii, sides, *, gap_tol=1e-9):
    r"""Contact type of N throats (thesis Fig. 3.17): ``'a'``, ``'b'``, ``'c'`` or ``'d'``.

    Disks i and j are in contact when their gap
    :math:`g_{ij} = l_{ij} - r_i - r_j \le` ``gap_tol`` :math:`\cdot\bar r` (touching or
    overlapping).  Zero, one, two or three pairs in contact give type a, b, c, d.

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``, any consistent length unit.
    gap_tol : float, optional
        Gap (in units of r̄) still counted as touching, default 1e-9 (round-off of
        coordinates of touching spheres).

    Returns
    -------
    (N,) ndarray of str

    Examples
    --------
    >>> contact_type([[1, 1, 1], [1, 1, 1]], [[2, 2, 2], [2, 2.5, 2.5]]).tolist()
    ['d', 'b']
    """
    r, s = as_throats(radii, sides)
    rbar = mean_radius(r)
    gaps = np.stack([s[:, _PAIR_COL[i, j]] - r[:, i] - r[:, j] for i, j in _PAIRS], axis=1)
    n = np.sum(gaps <= gap_tol * rbar[:, None], axis=1)
    return np.array(["a", "b", "c", "d"])[n]


def validate_throats(radii, sides):
    """Row-wise checks of N throats; never raises for a bad row.

    A row is invalid when it holds NaN/inf, a radius or side <= 0, sides that violate the
    triangle inequality or form a (nearly) collinear triangle (area <= 1e-9 * longest side²),
    or a disk that contains another vertex (r_i >= l_ij: overlap too deep for a throat).

    Parameters
    ----------
    radii, sides : (N, 3) array_like

    Returns
    -------
    ok : (N,) bool ndarray
    messages : (N,) object ndarray of str, '' where ok

    Raises
    ------
    ValueError
        If the arrays are not both of shape (N, 3) (a programming error, not a bad row).
    """
    return _validate(*as_throats(radii, sides), deep_overlap=True)


def _validate(r, s, *, deep_overlap):
    n = r.shape[0]
    msg = np.full(n, "", dtype=object)

    def flag(mask, text):
        new = mask & (msg == "")
        for k in np.flatnonzero(new):  # only on bad rows, to build their messages
            msg[k] = text(k)

    flag(~(np.isfinite(r).all(1) & np.isfinite(s).all(1)),
         lambda k: f"non-finite value in radii {r[k].tolist()} or sides {s[k].tolist()}")
    flag((r <= 0).any(1), lambda k: f"radius <= 0 in radii {r[k].tolist()}")
    flag((s <= 0).any(1), lambda k: f"side length <= 0 in sides {s[k].tolist()}")
    with np.errstate(invalid="ignore"):
        srt = np.sort(s, axis=1)
        area = triangle_area(np.where(np.isfinite(s), s, 1.0))
        bad_tri = (srt[:, 2] >= srt[:, 0] + srt[:, 1]) | (area <= 1e-9 * srt[:, 2] ** 2)
    flag(bad_tri, lambda k: f"sides {s[k].tolist()} do not form a triangle "
                            "(triangle inequality violated or collinear vertices)")
    if not deep_overlap:
        return msg == "", msg
    with np.errstate(invalid="ignore"):
        deep = np.zeros(n, dtype=bool)
        for i, j in _PAIRS:
            l = s[:, _PAIR_COL[i, j]]
            deep |= (r[:, i] >= l) | (r[:, j] >= l)
    flag(deep, lambda k: f"a disk contains another vertex (r_i >= l_ij) in radii "
                         f"{r[k].tolist()}, sides {s[k].tolist()}: overlap too deep for a throat")
    return msg == "", msg


# ----------------------------------------------------------------------------------------
# Boundary engine
# ----------------------------------------------------------------------------------------

def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _angle_param(points, centers):
    """Clockwise angle parameter u in [0, 1) of points on circles: theta = -2 pi u."""
    th = np.arctan2(points[..., 1] - centers[..., 1], points[..., 0] - centers[..., 0])
    return np.mod(-th, 2 * np.pi) / (2 * np.pi)


def _region_boundary(verts, centers, radii, lines_a=None, lines_b=None, lines_owner=None,
                     lines_present=None, rects=None, extra_lt=None, extra_cu=None, tol=_TOL):
    r"""Boundary of :math:`\Omega = T \cap \bigcap_i \overline{D_i}^c \cap \bigcap_m R_m^c`.

    Vectorised over N throats (lengths in units of r̄).  Primitive curves: the 3 triangle
    edges (counter-clockwise, owner set 0), the 3 circles (clockwise so that the fluid is on
    the left, owner sets 1..3) and optional extra segments (owner set 4 + m, oriented with the
    fluid on the left) that bound removed rectangles ``rects`` (closing rules of the mesher).

    Parameters
    ----------
    verts : (N, 3, 2) triangle vertices, counter-clockwise
    centers : (N, 3, 2) disk centres (the vertices)
    radii : (N, 3)
    lines_a, lines_b : (N, K, 2) extra segments (start, end)
    lines_owner : (K,) int, set index 4 + m of the rectangle each segment bounds
    lines_present : (N, K) bool
    rects : dict of (N, M, ...) arrays ``origin``, ``e``, ``n`` (unit axes), ``x0``, ``x1``,
        ``s1``, ``present``: removed open set {x0 < x < x1, s < s1} in the frame.
    extra_lt : (N, L', E), optional
        Extra split parameters on the first L' segments (mesh feature points).
    extra_cu : (N, 3, E), optional
        Extra split parameters (clockwise, in [0, 1)) on the circles.

    Returns
    -------
    dict with, for the L = 3 + K segments: ``la, lb`` (N, L, 2), ``lt`` (N, L, Kb) sorted
    breakpoints, ``lon`` (N, L, Kb-1) piece-on-boundary mask, ``lowner`` (L,); for the 3
    circles: ``cu`` (N, 3, Kc) sorted clockwise parameters, ``con`` (N, 3, Kc-1); and
    ``area`` (N,) from Green's theorem.
    """
    N = verts.shape[0]
    # triangle edges counter-clockwise: 1->2, 2->3, 3->1
    la = [verts[:, [0, 1, 2]]]
    lb = [verts[:, [1, 2, 0]]]
    owner = [np.zeros(3, dtype=int)]
    present = [np.ones((N, 3), dtype=bool)]
    if lines_a is not None and lines_a.shape[1] > 0:
        la.append(lines_a)
        lb.append(lines_b)
        owner.append(np.asarray(lines_owner, dtype=int))
        present.append(lines_present)
    la = np.concatenate(la, axis=1)
    lb = np.concatenate(lb, axis=1)
    owner = np.concatenate(owner)
    present = np.concatenate(present, axis=1)
    L = la.shape[1]
    C = centers
    R = radii
    d = lb - la                                                   # (N, L, 2)

    # --- breakpoints on segments -----------------------------------------------------
    # segment p vs segment q
    dp = d[:, :, None, :]
    dq = d[:, None, :, :]
    w = la[:, None, :, :] - la[:, :, None, :]                     # q0 - p0, (N, L, L, 2)
    den = _cross(dp, dq)
    with np.errstate(invalid="ignore", divide="ignore"):
        t_ll = _cross(w, dq) / den
        s_ll = _cross(w, dp) / den
    ok = (np.abs(den) > 1e-14) & (s_ll >= -tol) & (s_ll <= 1 + tol) \
        & present[:, None, :] & present[:, :, None]
    ok &= ~np.eye(L, dtype=bool)[None]
    t_ll = np.where(ok, t_ll, np.nan)
    # segment p vs circle c
    f = la[:, :, None, :] - C[:, None, :, :]                      # (N, L, 3, 2)
    aa = np.sum(d * d, axis=-1)[:, :, None]
    bb = 2 * np.sum(f * d[:, :, None, :], axis=-1)
    cc = np.sum(f * f, axis=-1) - R[:, None, :] ** 2
    disc = bb * bb - 4 * aa * cc
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        t_lc = np.stack([(-bb - sq) / (2 * aa), (-bb + sq) / (2 * aa)], axis=-1)  # (N,L,3,2)
    t_lc = np.where((disc >= 0)[..., None] & present[:, :, None, None], t_lc, np.nan)
    lt = [t_ll.reshape(N, L, -1), t_lc.reshape(N, L, -1)]
    if extra_lt is not None:   # extra split points (mesh features), (N, L' <= L, E)
        pad = np.full((N, L, extra_lt.shape[2]), np.nan)
        pad[:, :extra_lt.shape[1]] = extra_lt
        lt.append(pad)
    lt = np.concatenate(lt, axis=2)
    lt = np.where((lt > tol) & (lt < 1 - tol), lt, np.nan)
    lt = np.concatenate([np.zeros((N, L, 1)), np.ones((N, L, 1)), lt], axis=2)
    lt = np.sort(lt, axis=2)

    # --- breakpoints on circles ------------------------------------------------------
    # circle c vs segment q: points from the same quadratic, kept where t in [0, 1]
    t_cl = np.where((t_lc >= -tol) & (t_lc <= 1 + tol), t_lc, np.nan)        # (N,L,3,2)
    pts = la[:, :, None, None, :] + t_cl[..., None] * d[:, :, None, None, :]  # (N,L,3,2,2)
    u_cl = _angle_param(pts, C[:, None, :, None, :])                         # (N,L,3,2)
    u_cl = np.where(np.isfinite(t_cl), u_cl, np.nan)
    u_cl = np.moveaxis(u_cl, 2, 1).reshape(N, 3, -1)                          # (N,3,2L)
    # circle c vs circle k
    dv = C[:, None, :, :] - C[:, :, None, :]                                  # (N,3,3,2)
    dist = np.linalg.norm(dv, axis=-1)
    r1 = R[:, :, None]
    r2 = R[:, None, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        aq = (dist**2 + r1**2 - r2**2) / (2 * dist)
        hq = np.sqrt(np.maximum(r1**2 - aq**2, 0.0))
        ev = dv / dist[..., None]
    meet = (dist > 0) & (dist <= r1 + r2 + tol) & (dist >= np.abs(r1 - r2) - tol)
    perp = np.stack([-ev[..., 1], ev[..., 0]], axis=-1)
    base = C[:, :, None, :] + aq[..., None] * ev
    pcc = np.stack([base + hq[..., None] * perp, base - hq[..., None] * perp], axis=3)
    u_cc = _angle_param(pcc, C[:, :, None, None, :])                          # (N,3,3,2)
    u_cc = np.where(meet[..., None], u_cc, np.nan).reshape(N, 3, -1)
    cu = np.concatenate([u_cl, u_cc] + ([] if extra_cu is None else [extra_cu]), axis=2)
    cu = np.where((cu > 1e-13) & (cu < 1 - 1e-13), cu, np.nan)
    cu = np.concatenate([np.zeros((N, 3, 1)), np.ones((N, 3, 1)), cu], axis=2)
    cu = np.sort(cu, axis=2)

    # --- midpoint membership ---------------------------------------------------------
    def inside_all(p, skip):
        """p (N, X, K, 2): closed-membership in every set except ``skip`` (X,) owner."""
        res = np.ones(p.shape[:-1], dtype=bool)
        skip = skip[None, :, None]
        # triangle (set 0), counter-clockwise
        va = verts[:, [0, 1, 2]][:, None, None]
        vb = verts[:, [1, 2, 0]][:, None, None]
        e = vb - va
        sd = _cross(e, p[..., None, :] - va) / np.linalg.norm(e, axis=-1)
        res &= (sd >= -tol).all(axis=-1) | (skip == 0)
        for i in range(3):
            dd = np.linalg.norm(p - C[:, None, None, i], axis=-1)
            res &= (dd >= R[:, None, None, i] - tol) | (skip == 1 + i)
        if rects is not None:
            M = rects["x0"].shape[1]
            for m in range(M):
                q = p - rects["origin"][:, None, None, m]
                x = np.sum(q * rects["e"][:, None, None, m], axis=-1)
                s = np.sum(q * rects["n"][:, None, None, m], axis=-1)
                inside = ((x > rects["x0"][:, None, None, m] + tol)
                          & (x < rects["x1"][:, None, None, m] - tol)
                          & (s < rects["s1"][:, None, None, m] - tol)
                          & rects["present"][:, None, None, m])
                res &= ~inside | (skip == 4 + m)
        return res

    lvalid = np.isfinite(lt[..., 1:]) & (lt[..., 1:] - lt[..., :-1] > 1e-14) \
        & present[..., None]
    tm = 0.5 * (lt[..., 1:] + lt[..., :-1])
    pm = la[:, :, None, :] + np.nan_to_num(tm)[..., None] * d[:, :, None, :]
    lon = lvalid & inside_all(pm, owner)

    cvalid = np.isfinite(cu[..., 1:]) & (cu[..., 1:] - cu[..., :-1] > 1e-14)
    um = 0.5 * (cu[..., 1:] + cu[..., :-1])
    thm = -2 * np.pi * np.nan_to_num(um)
    pc = C[:, :, None, :] + R[:, :, None, None] * np.stack([np.cos(thm), np.sin(thm)], -1)
    con = cvalid & inside_all(pc, np.array([1, 2, 3]))

    # --- Green's theorem -----------------------------------------------------------------
    t0 = np.nan_to_num(lt[..., :-1])
    t1 = np.nan_to_num(lt[..., 1:])
    p0 = la[:, :, None, :] + t0[..., None] * d[:, :, None, :]
    p1 = la[:, :, None, :] + t1[..., None] * d[:, :, None, :]
    area_l = 0.5 * _cross(p0, p1)
    th0 = -2 * np.pi * np.nan_to_num(cu[..., :-1])
    th1 = -2 * np.pi * np.nan_to_num(cu[..., 1:])
    rr = R[:, :, None]
    cx = C[:, :, None, 0]
    cy = C[:, :, None, 1]
    area_c = 0.5 * (rr**2 * (th1 - th0) + rr * cx * (np.sin(th1) - np.sin(th0))
                    - rr * cy * (np.cos(th1) - np.cos(th0)))
    area = np.sum(np.where(lon, area_l, 0.0), axis=(1, 2)) \
        + np.sum(np.where(con, area_c, 0.0), axis=(1, 2))
    return dict(la=la, lb=lb, lt=lt, lon=lon, lowner=owner, cu=cu, con=con,
                area=np.maximum(area, 0.0))


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
    edge or share a triple overlap (closed forms in the ``throats._shape_factor`` docstring).  Inputs must be valid throats.
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
    ok, _ = _validate(r, s, deep_overlap=False)
    out = np.full(r.shape[0], np.nan)
    if not ok.any():
        return out
    rbar = mean_radius(r[ok])
    rs = r[ok] / rbar[:, None]
    ss = s[ok] / rbar[:, None]
    area, _ = open_area_perimeter(rs, ss)
    out[ok] = area * rbar**2
    return out
