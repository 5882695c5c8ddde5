r"""Exact open area and arc perimeter of throats, one compiled loop over the rows (numba).

The same construction as the boundary engine (:func:`throats._boundary.region_boundary`)
restricted to what the area needs (no mesher rectangles, no tagged curves): each triangle
edge is split where it crosses the three circles, each circle where it crosses the edges and
the other circles; a piece lies on the boundary of
:math:`\Omega = T \setminus (D_1 \cup D_2 \cup D_3)` when its midpoint is in the closure of
every other set; Green's theorem, :math:`A = \tfrac12 \oint_{\partial\Omega} (x\,dy - y\,dx)`,
sums a segment from :math:`p_0` to :math:`p_1` as :math:`\tfrac12\,p_0 \times p_1` and a clockwise
arc of the circle (c, r) from :math:`\theta_0` to :math:`\theta_1` as
:math:`\tfrac12\,[r^2(\theta_1-\theta_0) + r c_x(\sin\theta_1-\sin\theta_0) - r c_y(\cos\theta_1-\cos\theta_0)]`;
the no-slip perimeter is the length of the arcs on the boundary.

The numpy engine allocates (N, 3, 14, 2) temporaries and costs about 55 µs a row on the
deep-overlap sections of multi-sphere grains (a wheat bed: 0.55 M rows, 29 s of a 35 s
network solve); this loop does the same arithmetic in scalars. numba is imported on the first
call only (``import throats`` stays cheap; the compiled loop is cached on disk). Agreement
with the numpy engine: ``tests/throats/test_throats_area_kernel.py``.
"""

from __future__ import annotations

import threading

import numpy as np

__all__ = ["area_perimeter_rows"]

_COMPILED = []
# one compiler at a time: threads (network's conductance blocks) may call in together first
_COMPILE_LOCK = threading.Lock()


def area_perimeter_rows(verts, radii, tol=1e-11):
    """Exact A and arc perimeter P of N throats (units of r̄), (N,) each.

    ``verts`` (N, 3, 2) counter-clockwise vertices (= disk centres), ``radii`` (N, 3);
    ``tol`` the boundary engine's geometric tolerance (:data:`throats._boundary.TOL`).
    """
    if not _COMPILED:
        with _COMPILE_LOCK:
            if not _COMPILED:
                import numba  # a dependency, loaded only when some row needs the exact engine

                jit = numba.njit(cache=True, error_model="numpy")
                # the compiled loop calls the compiled helpers
                globals()["_sort"] = jit(_sort)
                globals()["_line_circle"] = jit(_line_circle)
                _COMPILED.append(jit(_rows))
    v = np.ascontiguousarray(verts, dtype=np.float64)
    r = np.ascontiguousarray(radii, dtype=np.float64)
    area = np.empty(v.shape[0])
    per = np.empty(v.shape[0])
    _COMPILED[0](v, r, float(tol), area, per)
    return area, per


def _rows(V, R, tol, area, per):  # compiled by area_perimeter_rows
    two_pi = 2.0 * np.pi
    lt = np.empty(8)
    cu = np.empty(12)
    ax, ay, dx, dy, en = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for n in range(V.shape[0]):
        for k in range(3):
            ax[k], ay[k] = V[n, k, 0], V[n, k, 1]
            dx[k] = V[n, (k + 1) % 3, 0] - ax[k]
            dy[k] = V[n, (k + 1) % 3, 1] - ay[k]
            en[k] = np.sqrt(dx[k] * dx[k] + dy[k] * dy[k])
        a_sum = 0.0
        p_sum = 0.0
        # --- the three edges ---------------------------------------------------------
        for k in range(3):
            m = 2
            lt[0], lt[1] = 0.0, 1.0
            for c in range(3):
                meets, t_lo, t_hi = _line_circle(ax[k], ay[k], dx[k], dy[k], V[n, c, 0],
                                                 V[n, c, 1], R[n, c])
                if meets:
                    for t in (t_lo, t_hi):
                        if tol < t < 1.0 - tol:
                            lt[m] = t
                            m += 1
            _sort(lt, m)
            for j in range(m - 1):
                t0, t1 = lt[j], lt[j + 1]
                if not t1 - t0 > 1e-14:
                    continue
                tm = 0.5 * (t0 + t1)
                px, py = ax[k] + tm * dx[k], ay[k] + tm * dy[k]
                on = True
                for i in range(3):
                    ex, ey = px - V[n, i, 0], py - V[n, i, 1]
                    if not np.sqrt(ex * ex + ey * ey) >= R[n, i] - tol:
                        on = False
                if on:
                    x0, y0 = ax[k] + t0 * dx[k], ay[k] + t0 * dy[k]
                    x1, y1 = ax[k] + t1 * dx[k], ay[k] + t1 * dy[k]
                    a_sum += 0.5 * (x0 * y1 - y0 * x1)
        # --- the three circles (clockwise, u in [0, 1), theta = -2 pi u) -----------
        for c in range(3):
            cx, cy, rc = V[n, c, 0], V[n, c, 1], R[n, c]
            m = 2
            cu[0], cu[1] = 0.0, 1.0
            for q in range(3):
                meets, t_lo, t_hi = _line_circle(ax[q], ay[q], dx[q], dy[q], cx, cy, rc)
                if meets:
                    for t in (t_lo, t_hi):
                        if -tol <= t <= 1.0 + tol:
                            u = (-np.arctan2(ay[q] + t * dy[q] - cy, ax[q] + t * dx[q] - cx)) % two_pi / two_pi
                            if 1e-13 < u < 1.0 - 1e-13:
                                cu[m] = u
                                m += 1
            for o in range(3):
                if o == c:
                    continue
                vx, vy = V[n, o, 0] - cx, V[n, o, 1] - cy
                dist = np.sqrt(vx * vx + vy * vy)
                ro = R[n, o]
                if not (dist > 0.0 and dist <= rc + ro + tol and dist >= abs(rc - ro) - tol):
                    continue
                aq = (dist * dist + rc * rc - ro * ro) / (2.0 * dist)
                hq = np.sqrt(max(rc * rc - aq * aq, 0.0))
                ux, uy = vx / dist, vy / dist
                for sgn in (1.0, -1.0):
                    qx = cx + aq * ux - sgn * hq * uy
                    qy = cy + aq * uy + sgn * hq * ux
                    u = (-np.arctan2(qy - cy, qx - cx)) % two_pi / two_pi
                    if 1e-13 < u < 1.0 - 1e-13:
                        cu[m] = u
                        m += 1
            _sort(cu, m)
            for j in range(m - 1):
                u0, u1 = cu[j], cu[j + 1]
                if not u1 - u0 > 1e-14:
                    continue
                thm = -two_pi * 0.5 * (u0 + u1)
                px, py = cx + rc * np.cos(thm), cy + rc * np.sin(thm)
                on = True
                for k in range(3):       # closed triangle: signed distance to every edge >= -tol
                    if not (dx[k] * (py - ay[k]) - dy[k] * (px - ax[k])) / en[k] >= -tol:
                        on = False
                for i in range(3):
                    if i != c:
                        ex, ey = px - V[n, i, 0], py - V[n, i, 1]
                        if not np.sqrt(ex * ex + ey * ey) >= R[n, i] - tol:
                            on = False
                if on:
                    th0, th1 = -two_pi * u0, -two_pi * u1
                    a_sum += 0.5 * (rc * rc * (th1 - th0) + rc * cx * (np.sin(th1) - np.sin(th0))
                                    - rc * cy * (np.cos(th1) - np.cos(th0)))
                    p_sum += two_pi * (u1 - u0) * rc
        area[n] = max(a_sum, 0.0)
        per[n] = p_sum


def _line_circle(ax, ay, dx, dy, cx, cy, r):
    """Where the line (ax, ay) + t (dx, dy) meets the circle (cx, cy, r): ``(meets, t_lo, t_hi)``,
    the roots of |a + t d - c|^2 = r^2 (compiled with the loop; edges and circles both use it)."""
    aa = dx * dx + dy * dy
    fx, fy = ax - cx, ay - cy
    bb = 2.0 * (fx * dx + fy * dy)
    cc = fx * fx + fy * fy - r * r
    disc = bb * bb - 4.0 * aa * cc
    if disc < 0.0:
        return False, 0.0, 0.0
    sq = np.sqrt(disc)
    return True, (-bb - sq) / (2.0 * aa), (-bb + sq) / (2.0 * aa)


def _sort(a, m):
    """Insertion sort of ``a[:m]`` in place (at most 12 breakpoints; compiled with the loop)."""
    for i in range(1, m):
        x = a[i]
        j = i - 1
        while j >= 0 and a[j] > x:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = x
