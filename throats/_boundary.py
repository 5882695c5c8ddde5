r"""Boundary engine: the boundary of a throat's open region, piece by piece, and its area.

The open region of a throat (lengths in units of r̄) is

.. math:: \Omega = T \cap \bigcap_i \overline{D_i}^c \cap \bigcap_m R_m^c,

the triangle T minus the disks D_i (the three vertex disks; more where other spheres cut the
section's plane) and, for the mesher, minus the rectangles R_m of its closing rules.  Its
boundary is assembled from primitive curves: the triangle edges, the circles and optional
extra segments.  Each primitive is split at its intersections with
all the others; a sub-piece belongs to the boundary when its midpoint lies in the closure of
every other set that makes up the region.  The area follows from Green's theorem,
:math:`A = \tfrac12 \oint_{\partial\Omega} (x\,dy - y\,dx)`, in closed form over segments
and arcs.  This is exact for disks that overlap each other, cover the triangle or reach
across the opposite edge; :mod:`throats._area` takes its exact areas from here and
:mod:`throats._mesh` its tagged boundary curves.  Vectorised over N throats.
"""

from __future__ import annotations

import numpy as np

__all__ = ["region_boundary"]

#: geometric tolerance in mean-radius units
TOL = 1e-11


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _angle_param(points, centers):
    """Clockwise angle parameter u in [0, 1) of points on circles: theta = -2 pi u."""
    th = np.arctan2(points[..., 1] - centers[..., 1], points[..., 0] - centers[..., 0])
    return np.mod(-th, 2 * np.pi) / (2 * np.pi)


def region_boundary(verts, centers, radii, lines_a=None, lines_b=None, lines_owner=None,
                     lines_present=None, rects=None, extra_lt=None, extra_cu=None, tol=TOL):
    r"""Boundary of :math:`\Omega = T \cap \bigcap_i \overline{D_i}^c \cap \bigcap_m R_m^c`.

    Vectorised over N throats (lengths in units of r̄).  Primitive curves: the 3 triangle
    edges (counter-clockwise, owner set 0), the K circles (clockwise so that the fluid is on
    the left, owner sets 1..K) and optional extra segments (owner set 4 + m, oriented with the
    fluid on the left) that bound removed rectangles ``rects`` (closing rules of the mesher;
    with the three vertex disks only, K = 3).

    Parameters
    ----------
    verts : (N, 3, 2) triangle vertices, counter-clockwise
    centers : (N, K, 2) disk centres (the throat's K = 3 vertex disks, or more disks: a section
        that other spheres cut too)
    radii : (N, K)
    lines_a, lines_b : (N, K, 2) extra segments (start, end)
    lines_owner : (K,) int, set index 4 + m of the rectangle each segment bounds
    lines_present : (N, K) bool
    rects : dict of (N, M, ...) arrays ``origin``, ``e``, ``n`` (unit axes), ``x0``, ``x1``,
        ``s1``, ``present``: removed open set {x0 < x < x1, s < s1} in the frame.
    extra_lt : (N, L', E), optional
        Extra split parameters on the first L' segments (mesh feature points).
    extra_cu : (N, K, E), optional
        Extra split parameters (clockwise, in [0, 1)) on the circles.

    Returns
    -------
    dict with, for the L = 3 + K segments: ``la, lb`` (N, L, 2), ``lt`` (N, L, Kb) sorted
    breakpoints, ``lon`` (N, L, Kb-1) piece-on-boundary mask, ``lowner`` (L,); for the 3
    circles: ``cu`` (N, K, Kc) sorted clockwise parameters, ``con`` (N, K, Kc-1); and
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
    K = C.shape[1]
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
    u_cl = np.moveaxis(u_cl, 2, 1).reshape(N, K, -1)                          # (N,3,2L)
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
    u_cc = np.where(meet[..., None], u_cc, np.nan).reshape(N, K, -1)
    cu = np.concatenate([u_cl, u_cc] + ([] if extra_cu is None else [extra_cu]), axis=2)
    cu = np.where((cu > 1e-13) & (cu < 1 - 1e-13), cu, np.nan)
    cu = np.concatenate([np.zeros((N, K, 1)), np.ones((N, K, 1)), cu], axis=2)
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
        for i in range(K):
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
    con = cvalid & inside_all(pc, np.arange(1, K + 1))

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
