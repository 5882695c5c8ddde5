r"""Grain-mate disks: the spheres of a throat's grains that cut its conduit's sections.

On a bed of multi-sphere grains a conduit's section at height h above the face (the face
triangle moved along its normal n, :mod:`._conduit`) is cut by its three vertex spheres and
also by the other spheres of their grains (*grain mates*: a grain's spheres overlap, and one
that lies off the face can still reach into the section). A mate of centre :math:`c_j`,
radius :math:`r_j`, at signed distance :math:`d_j = (c_j - x_1)\cdot n` from the face plane,
cuts the plane at signed height t in a disk of radius

.. math:: \rho_j(t) = \sqrt{r_j^2 - (t - d_j)^2}\quad(|t - d_j| < r_j),

centred at the projection of :math:`c_j` on the face (coordinates in the frame of
:func:`throats.triangle_vertices`: vertex 1 at the origin, vertex 2 on +x, vertex 3 above).
The section is then the triangle minus the union of all the disks (:mod:`throats._multidisk`).
Sphere packings (no ``grain_id``) have no mates. The windows' flow-rate factors:
:func:`window_factors_compiled` (the compiled loop of :mod:`._mates_kernel`, what the conduit
model runs) and :func:`window_factors` (numpy, the reference it is tested against); every
section's: :func:`section_factors`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from throats import (NARROW_FRACTION, section_ratio, shape_factor_ratio, sub_triangle_centroids,
                     triangle_vertices)

from ._mates_kernel import compiled_window_rows

__all__ = ["MateDisks", "candidates", "grain_mates", "mate_radii", "section_factors",
           "window_factors", "window_factors_compiled"]


@dataclass(frozen=True)
class MateDisks:
    """The grain mates that reach some section of a set of conduits.

    ``rows`` (M,) positions (in the caller's throat list) of the conduits with at least one
    mate; ``center`` (M, E, 2) the mates' centres projected on the face, triangle frame, m;
    ``offset`` (M, E) signed distance d of each centre from the face plane along the face
    normal n = (x2 - x1) x (x3 - x1) / |...|, m; ``radius`` (M, E) sphere radius, m (0 pads
    a row with fewer than E mates); ``sphere`` (M, E) the mates' sphere indices (-1 pads).
    """

    rows: np.ndarray
    center: np.ndarray
    offset: np.ndarray
    radius: np.ndarray
    sphere: np.ndarray | None = None


def _grain_table(grain_id):
    """(G, S) sphere indices of each grain (-1 padded) and each sphere's grain row."""
    g = np.asarray(grain_id)
    uniq, row = np.unique(g, return_inverse=True)
    order = np.argsort(row, kind="stable")
    counts = np.bincount(row, minlength=uniq.size)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    pos = np.arange(g.size) - start[row[order]]
    table = np.full((uniq.size, max(int(counts.max()), 1)), -1, dtype=np.int64)
    table[row[order], pos] = order
    return table, row


def candidates(grain_id, vertices):
    """(N, C) sphere indices of the other spheres of each face's grains (-1 pads; a grain
    shared by two vertices listed once; the face's own spheres left out)."""
    table, grow = _grain_table(grain_id)
    tv = np.asarray(vertices, dtype=np.int64)
    g = grow[tv]                                                   # (N, 3)
    cand = table[g]                                                # (N, 3, S)
    cand[:, 1][g[:, 1] == g[:, 0]] = -1
    cand[:, 2][(g[:, 2] == g[:, 0]) | (g[:, 2] == g[:, 1])] = -1
    cand = cand.reshape(tv.shape[0], -1)
    own = (cand == tv[:, :1]) | (cand == tv[:, 1:2]) | (cand == tv[:, 2:3])
    return np.where(own, -1, cand)


def grain_mates(packing, vertices, heights, signs):
    r"""The grain mates of N conduits that cut any of their sections inside the triangle.

    Parameters
    ----------
    packing : Packing
        Centres, radii and ``grain_id`` (None: no mates, an empty result).
    vertices : (N, 3) int array
        The face's sphere indices (``throat_vertices``).
    heights : (N, 2) array
        Section heights of the two conduit halves (the conduit model's
        :math:`H = \min(h, \max_k r_k)`), m, >= 0.
    signs : (N, 2) array
        +1 / -1: the side of the face plane (along n) each half lies on.

    Returns
    -------
    MateDisks
        A mate is kept when the sphere reaches the slab of signed heights the two halves
        span and its largest disk, :math:`r_j`, comes within :math:`r_j` of the triangle.
    """
    n = len(vertices)
    empty = MateDisks(np.zeros(0, np.int64), np.zeros((0, 0, 2)), np.zeros((0, 0)),
                      np.zeros((0, 0)))
    if packing.grain_id is None or n == 0:
        return empty
    tv = np.asarray(vertices, dtype=np.int64)
    cand = candidates(packing.grain_id, tv)
    ok = cand >= 0
    cen = packing.centers
    x0, x1, x2 = cen[tv[:, 0]], cen[tv[:, 1]], cen[tv[:, 2]]
    e1 = x1 - x0
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    nrm = np.cross(x1 - x0, x2 - x0)
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    e2 = np.cross(nrm, e1)
    p = cen[np.maximum(cand, 0)] - x0[:, None, :]                  # (N, C, 3)
    uvd = np.matmul(p, np.stack([e1, e2, nrm], axis=2))            # (N, C, 3): frame coords
    u, v, d = uvd[..., 0], uvd[..., 1], uvd[..., 2]
    r = packing.radii[np.maximum(cand, 0)]
    # the slab of signed heights the two halves span, [lo, hi] (both contain the face)
    t = np.asarray(heights, dtype=float) * np.asarray(signs, dtype=float)
    lo = np.minimum(np.minimum(t[:, 0], t[:, 1]), 0.0)[:, None]
    hi = np.maximum(np.maximum(t[:, 0], t[:, 1]), 0.0)[:, None]
    ok &= (d + r > lo) & (d - r < hi)
    # within r of the triangle (vertices (0, 0), (a, 0), (bx, by))
    a = np.linalg.norm(x1 - x0, axis=1)[:, None]
    q2 = x2 - x0
    bx = np.einsum("nk,nk->n", q2, e1)[:, None]
    by = np.einsum("nk,nk->n", q2, e2)[:, None]
    ok &= _triangle_distance(u, v, a, bx, by) < r
    keep = ok.any(axis=1)
    rows = np.flatnonzero(keep)
    if rows.size == 0:
        return empty
    ok = ok[rows]
    e_max = int(ok.sum(axis=1).max())
    order = np.argsort(~ok, axis=1, kind="stable")[:, :e_max]     # kept mates first
    take = np.take_along_axis
    okm = take(ok, order, axis=1)
    center = np.stack([take(u[rows], order, axis=1), take(v[rows], order, axis=1)], axis=-1)
    return MateDisks(rows, np.where(okm[..., None], center, 0.0),
                     np.where(okm, take(d[rows], order, axis=1), 0.0),
                     np.where(okm, take(r[rows], order, axis=1), 0.0),
                     np.where(okm, take(cand[rows], order, axis=1), -1))


def _triangle_distance(u, v, a, bx, by):
    """Distance of points (u, v) from the triangle (0, 0), (a, 0), (bx, by) (by > 0): 0 inside."""
    ax_ = [0.0, a, bx]
    ay_ = [0.0, 0.0, by]
    inside = np.ones(np.broadcast(u, a).shape, dtype=bool)
    best = np.full(inside.shape, np.inf)
    for k in range(3):
        px, py = ax_[k], ay_[k]
        qx, qy = ax_[(k + 1) % 3], ay_[(k + 1) % 3]
        ex, ey = qx - px, qy - py                       # counter-clockwise edge
        wx, wy = u - px, v - py
        inside &= ex * wy - ey * wx >= 0
        ll = ex * ex + ey * ey
        s = np.clip((wx * ex + wy * ey) / ll, 0.0, 1.0)
        best = np.minimum(best, np.hypot(wx - s * ex, wy - s * ey))
    return np.where(inside, 0.0, best)


def mate_radii(mates, t):
    r"""Disk radii :math:`\rho_j(t)` (M, E, ...) of the mates in the planes of signed heights
    ``t`` (M, ...), m: 0 where a sphere does not reach the plane."""
    t = np.asarray(t, dtype=float)
    extra = (None,) * (t.ndim - 1)
    dd = t[:, None] - mates.offset[(slice(None), slice(None)) + extra]
    r = mates.radius[(slice(None), slice(None)) + extra]
    return np.sqrt(np.maximum(r * r - dd * dd, 0.0))


def _live(mates, rho, V, rv, n_angles=16):
    """(R, E) bool: the mate disks (radii ``rho`` (R, E)) that take area from the three-disk
    section (vertex disks ``rv`` (R, 3), triangle ``V`` (R, 3, 2)): some point of the mate's
    circle (``n_angles`` of them) lies inside the triangle and outside the vertex disks."""
    a, bx, by = V[:, 1, 0][:, None], V[:, 2, 0][:, None], V[:, 2, 1][:, None]
    cx, cy = mates.center[..., 0], mates.center[..., 1]
    live = (rho > 0) & (_triangle_distance(cx, cy, a, bx, by) < rho)
    for k in range(3):          # a disk inside a vertex disk takes nothing
        live &= np.hypot(cx - V[:, k, None, 0], cy - V[:, k, None, 1]) + rho > rv[:, k, None]
    r_, e_ = np.nonzero(live)
    if r_.size == 0:
        return live
    th = np.linspace(0.0, 2.0 * np.pi, n_angles, endpoint=False)
    px = cx[r_, e_, None] + rho[r_, e_, None] * np.cos(th)                  # (P, A)
    py = cy[r_, e_, None] + rho[r_, e_, None] * np.sin(th)
    a, bx, by = a[r_], bx[r_], by[r_]
    # inside the triangle: left of its three counter-clockwise edges
    out = (py >= 0) & ((bx - a) * py - by * (px - a) >= 0) & (by * (px - bx) - bx * (py - by) >= 0)
    for k in range(3):
        out &= np.hypot(px - V[r_, k, None, 0], py - V[r_, k, None, 1]) >= rv[r_, k, None]
    live[r_, e_] = out.any(axis=1)
    return live


def _ratio(mates, rho, live, s3, rv, n):
    """:func:`throats.section_ratio` of the rows with a live mate (others 1)."""

    f = np.ones(rho.shape[0])
    sec = np.flatnonzero(live.any(axis=1))
    if sec.size == 0:
        return f
    lv = live[sec]
    e_max = int(lv.sum(axis=1).max())
    order = np.argsort(~lv, axis=1, kind="stable")[:, :e_max]            # live mates first
    kept = np.take_along_axis(lv, order, axis=1)
    cen = np.take_along_axis(mates.center[sec], order[..., None], axis=1)
    rad = np.where(kept, np.take_along_axis(rho[sec], order, axis=1), 0.0)
    f[sec] = section_ratio(s3[sec], rv[sec], cen, rad, n=n)
    return f


def window_factors(mates, radii, sides, *, n=16):
    r"""Flow rate of the conduits' windows with their grain mates relative to the three-disk
    windows (:func:`throats.section_ratio`), (M,) for the M rows of ``mates``; 1 where no
    mate takes area from the window. ``radii``, ``sides`` (M, 3): the faces'."""

    V = triangle_vertices(sides)
    rho = mate_radii(mates, np.zeros(mates.rows.size))                      # (M, E)
    return _ratio(mates, rho, _live(mates, rho, V, radii), sides, radii, n)


def window_factors_compiled(packing, vertices, *, n=16, n_angles=16, max_live=32):
    r""":func:`window_factors` of N faces (``vertices`` (N, 3)) from the packing directly, by
    the compiled loop of :mod:`._mates_kernel` (the mates, the circle test and the
    distance-squared rule per window), the narrow windows by
    :func:`throats.shape_factor_ratio`: (N,) factors, 1 where no mate takes area."""


    tv = np.ascontiguousarray(vertices, dtype=np.int64)
    n_w = tv.shape[0]
    cand = np.ascontiguousarray(candidates(packing.grain_id, tv))
    b1, b2 = sub_triangle_centroids(int(n))
    factor = np.ones(n_w)
    flagged = np.zeros(n_w, dtype=bool)
    live_c = np.zeros((n_w, max_live, 2))
    live_r = np.zeros((n_w, max_live))
    n_live = np.zeros(n_w, dtype=np.int64)
    th = np.linspace(0.0, 2.0 * np.pi, int(n_angles), endpoint=False)   # as :func:`_live`
    compiled_window_rows()(np.ascontiguousarray(packing.centers, dtype=float),
                           np.ascontiguousarray(packing.radii, dtype=float), tv, cand, b1, b2,
                           np.cos(th), np.sin(th), float(NARROW_FRACTION), factor, flagged,
                           live_c, live_r, n_live)
    k = np.flatnonzero(flagged)
    if k.size:
        e = max(int(n_live[k].max()), 1)
        r3 = packing.radii[tv[k]]
        c = packing.centers[tv[k]]
        sides = np.stack([np.linalg.norm(c[:, 1] - c[:, 0], axis=1),
                          np.linalg.norm(c[:, 2] - c[:, 0], axis=1),
                          np.linalg.norm(c[:, 2] - c[:, 1], axis=1)], axis=1)
        factor[k] = np.clip(shape_factor_ratio(sides, r3, live_c[k, :e], live_r[k, :e]),
                            0.0, 1.0)
    return factor


def section_factors(mates, rows, h_nodes, signs, radii, sides, *, n=16):
    r"""Flow rate of the conduits' sections with their grain mates relative to the three-disk
    sections (:func:`throats.section_ratio`), (M, 2, m+1), at the nodes ``h_nodes`` (M, m+1)
    of both halves; 1 where no mate takes area from the section.

    ``mates`` holds the mates of the conduits ``rows`` (positions in ``h_nodes``' rows);
    ``signs`` (M, 2) the halves' sides of the face; ``radii``, ``sides`` (M, 3) the faces'.
    The vertex disks are floored at 2e-2 of the shortest side, as the conduit model's
    sections are.
    """

    m1 = h_nodes.shape[1]
    out = np.ones((h_nodes.shape[0], 2, m1))
    if rows.size == 0:
        return out
    hn = h_nodes[rows]                                              # (R, m+1)
    r3 = radii[rows]
    s3 = sides[rows]
    smin = np.min(s3, axis=1)
    rv = np.sqrt(np.maximum(np.square(r3)[:, :, None] - np.square(hn)[:, None, :], 0.0))
    rv = np.maximum(rv, 2e-2 * smin[:, None, None])                 # (R, 3, m+1)
    V = triangle_vertices(s3)
    for c in (0, 1):
        rho = mate_radii(mates, hn * signs[rows, c][:, None])       # (R, E, m+1)
        for j in range(0 if c == 0 else 1, m1):                     # the window once
            live = _live(mates, rho[:, :, j], V, rv[:, :, j])
            out[rows, c, j] = _ratio(mates, rho[:, :, j], live, s3, rv[:, :, j], n)
    out[rows, 1, 0] = out[rows, 0, 0]
    return out
