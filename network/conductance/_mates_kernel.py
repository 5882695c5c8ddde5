r"""The grain mates of windows and their flow-rate ratios in one compiled loop (numba).

:func:`window_rows` computes, window by window, what :func:`._mates.grain_mates` (at the face
plane), :func:`._mates._live` and :func:`throats.section_ratio`'s distance-squared rule compute
for blocks of windows in numpy: the candidate mates' frame coordinates, the disk each cuts
from the face plane, the ones that take area from the three-disk section (a point of their
circle inside the triangle and outside the vertex disks, at the angles given), and the two
integrals of the squared distance to the nearest disk over the sub-triangles' centroids. The
windows the rule leaves to the shape-factor form (three-disk open share below
``narrow``, or none of it sampled) are returned flagged with their live disks, for numpy
(``throats.section_area_perimeter``). The same operations as the numpy path, in the same
order per window (agreement to rounding, ``tests/network/test_network_grain_mates.py``),
without the (windows, candidates, points) arrays.
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["compiled_window_rows"]

_COMPILED: list = []
_LOCK = threading.Lock()


def compiled_window_rows():
    """:func:`window_rows` compiled by numba (imported on the first call; cached on disk)."""
    if not _COMPILED:
        with _LOCK:
            if not _COMPILED:
                import numba

                globals()["_tri_distance"] = numba.njit(inline="always",
                                                        error_model="numpy")(_tri_distance)
                _COMPILED.append(numba.njit(cache=True, nogil=True,
                                            error_model="numpy")(window_rows))
    return _COMPILED[0]


def window_rows(centers, radii, tv, cand, b1, b2, cos_t, sin_t, narrow, factor, flagged,
                live_c, live_r, n_live):
    """Per window p (rows of ``tv`` (N, 3), candidate mates ``cand`` (N, C), -1 padded):
    ``cos_t``, ``sin_t`` the circle test's angles; ``b1``, ``b2`` the sub-triangles'
    centroids; ``factor[p]`` the flow-rate ratio (1: no mate takes area), ``flagged[p]`` True where the
    shape-factor form must answer, ``live_c`` (N, E, 2), ``live_r`` (N, E), ``n_live`` (N,)
    the live mates (at most E; more are dropped, smallest last)."""
    n = tv.shape[0]
    n_c = cand.shape[1]
    e_max = live_r.shape[1]
    n_pts = b1.shape[0]
    for p in range(n):
        i0, i1, i2 = tv[p, 0], tv[p, 1], tv[p, 2]
        x0 = centers[i0]
        ax_, ay_, az_ = centers[i1, 0] - x0[0], centers[i1, 1] - x0[1], centers[i1, 2] - x0[2]
        bx_, by_, bz_ = centers[i2, 0] - x0[0], centers[i2, 1] - x0[1], centers[i2, 2] - x0[2]
        la = math.sqrt(ax_ * ax_ + ay_ * ay_ + az_ * az_)
        e1 = (ax_ / la, ay_ / la, az_ / la)
        nx, ny, nz = ay_ * bz_ - az_ * by_, az_ * bx_ - ax_ * bz_, ax_ * by_ - ay_ * bx_
        ln = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / ln, ny / ln, nz / ln
        e2 = (ny * e1[2] - nz * e1[1], nz * e1[0] - nx * e1[2], nx * e1[1] - ny * e1[0])
        a = la
        bx = bx_ * e1[0] + by_ * e1[1] + bz_ * e1[2]
        by = bx_ * e2[0] + by_ * e2[1] + bz_ * e2[2]
        r0, r1, r2 = radii[i0], radii[i1], radii[i2]
        nl = 0
        for k in range(n_c):
            j = cand[p, k]
            if j < 0:
                continue
            px_, py_, pz_ = centers[j, 0] - x0[0], centers[j, 1] - x0[1], centers[j, 2] - x0[2]
            d = px_ * nx + py_ * ny + pz_ * nz
            rj = radii[j]
            if not (d + rj > 0.0 and d - rj < 0.0):
                continue
            rho = math.sqrt(max(rj * rj - d * d, 0.0))
            if not rho > 0.0:
                continue
            u = px_ * e1[0] + py_ * e1[1] + pz_ * e1[2]
            v = px_ * e2[0] + py_ * e2[1] + pz_ * e2[2]
            if not _tri_distance(u, v, a, bx, by) < rho:
                continue
            if (math.hypot(u, v) + rho <= r0 or math.hypot(u - a, v) + rho <= r1
                    or math.hypot(u - bx, v - by) + rho <= r2):
                continue
            hit = False
            for q in range(cos_t.shape[0]):
                qx, qy = u + rho * cos_t[q], v + rho * sin_t[q]
                if (qy >= 0 and (bx - a) * qy - by * (qx - a) >= 0
                        and by * (qx - bx) - bx * (qy - by) >= 0
                        and math.hypot(qx, qy) >= r0 and math.hypot(qx - a, qy) >= r1
                        and math.hypot(qx - bx, qy - by) >= r2):
                    hit = True
                    break
            if hit and nl < e_max:
                live_c[p, nl, 0] = u
                live_c[p, nl, 1] = v
                live_r[p, nl] = rho
                nl += 1
        n_live[p] = nl
        flagged[p] = False
        factor[p] = 1.0
        if nl == 0:
            continue
        i3 = 0.0
        ia = 0.0
        open3 = 0
        for q in range(n_pts):
            px = a * b1[q] + bx * b2[q]
            py = by * b2[q]
            d3 = math.sqrt(px * px + py * py) - r0
            dx, dy = px - a, py
            d3 = min(d3, math.sqrt(dx * dx + dy * dy) - r1)
            dx, dy = px - bx, py - by
            d3 = min(d3, math.sqrt(dx * dx + dy * dy) - r2)
            dall = d3
            for k in range(nl):
                dx, dy = px - live_c[p, k, 0], py - live_c[p, k, 1]
                dall = min(dall, math.sqrt(dx * dx + dy * dy) - live_r[p, k])
            if d3 > 0.0:
                i3 += d3 * d3
                open3 += 1
            if dall > 0.0:
                ia += dall * dall
        if not (open3 >= narrow * n_pts) or not i3 > 0.0:
            flagged[p] = True
            continue
        factor[p] = min(max(ia / i3, 0.0), 1.0)


def _tri_distance(u, v, a, bx, by):
    """Distance of (u, v) from the triangle (0, 0), (a, 0), (bx, by), by > 0: 0 inside."""
    inside = True
    best = math.inf
    xs = (0.0, a, bx)
    ys = (0.0, 0.0, by)
    for k in range(3):
        px, py = xs[k], ys[k]
        qx, qy = xs[(k + 1) % 3], ys[(k + 1) % 3]
        ex, ey = qx - px, qy - py
        wx, wy = u - px, v - py
        if ex * wy - ey * wx < 0:
            inside = False
        s = min(max((wx * ex + wy * ey) / (ex * ex + ey * ey), 0.0), 1.0)
        best = min(best, math.hypot(wx - s * ex, wy - s * ey))
    return 0.0 if inside else best
