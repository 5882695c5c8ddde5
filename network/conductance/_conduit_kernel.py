r"""The conduit model's two halves of each throat in one compiled loop (numba), table Q* inline.

:func:`conduit_rows` computes, throat by throat, what :func:`._sections.side_resistance`
computes for blocks of throats with the Q* table answering the window and every section
(the ``'table-only'`` policy of :func:`._conduit.conduit_conductance`): the section nodes
:math:`h_j = r_{max}\sin(\theta_j)`, the disks :math:`\rho_k = \sqrt{r_k^2 - h_j^2}`, their
:math:`y = 1/Q` from the table (:func:`cache.point_kernel`), the slowly-varying-tube factor
:math:`1 + s/(1+s)` and the trapezoid integral up to each side's height, in the same
operations and order as the numpy code (agreement to the last bits or nearly,
``tests/network/test_network_conduit_kernel.py``). No (N, m+1, 3) section arrays and no per-call
lookup bookkeeping are made: 0.2 s instead of about 1 s of one core for the 1.4e6 sections
of the 20 000-sphere bench packing.

A throat whose window or any section the table does not serve (outside the grid, a cell
with a missing corner, a section that is not a valid triangle) is returned flagged; the
caller computes it by the numpy path, where the policy's fallbacks (stored FE values, the
shape-factor estimate, the closed-form continuation of sections) apply.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from cache import point_kernel

__all__ = ["compiled_conduit_rows"]

#: the table's one-point evaluation, set to :func:`cache.point_kernel` when compiling
interp_point = None
#: SHA-256 (first 16 hex digits) of cache/_kernel.py, whose functions numba compiles into
#: :func:`conduit_rows`: numba's disk cache of this module checks this file's own time stamp
#: only, so an edit of cache/_kernel.py must change this line too, or a stale machine code
#: keeps interpolating the previous source (a test compares the digest)
INTERP_SOURCE_SHA256 = "f22ee7f97ac0421b"
_COMPILED: list = []
# one compiler at a time: the conductance blocks' threads may ask together first
_LOCK = threading.Lock()


def compiled_conduit_rows():
    """:func:`conduit_rows` compiled by numba (imported on the first call, so that importing
    ``network`` stays cheap; the machine code is cached on disk by numba after the first run)."""
    if not _COMPILED:
        with _LOCK:
            if not _COMPILED:
                import numba

                g = globals()
                g["interp_point"] = point_kernel()
                g["_valid"] = numba.njit(inline="always", error_model="numpy")(_valid)
                _COMPILED.append(numba.njit(cache=True, nogil=True,
                                            error_model="numpy")(conduit_rows))
    return _COMPILED[0]


def _valid(a0, a1, a2, s0, s1, s2):
    """``cache``'s quick row check: finite positive radii and sides, strict triangle."""
    ok = (s0 < s1 + s2) and (s1 < s0 + s2) and (s2 < s0 + s1)
    for x in (a0, a1, a2, s0, s1, s2):
        ok = ok and (x > 0.0) and (x < math.inf)
    return ok


def conduit_rows(radii, sides, heights, tnodes, gap, rho_lo, rho_hi, rho_inv, n_rho, strides,
                 values, curv, snap, q_win, resist, looked, flagged):
    r"""Window Q* (r̄ units) and viscosity-free resistances :math:`R_P/\mu` (unit⁻³) of both
    halves of N throats, in place: ``q_win`` (N,), ``resist`` (N, 2), ``looked`` (N,) the
    sections looked up, ``flagged`` (N,) True where the table cannot answer the throat (its
    other outputs are then not set).

    ``radii``, ``sides`` (N, 3); ``heights`` (N, 2) the pore-centre heights above the face;
    ``tnodes`` = ``np.linspace(0, 1, n_sections + 1)``; the table's arrays as
    :meth:`cache.GridTable.kernel_arrays` gives them.
    """
    n = radii.shape[0]
    m = tnodes.shape[0] - 1
    h = np.empty(m + 1)
    dhdth = np.empty(m + 1)
    y = np.empty(m + 1)
    F = np.empty(m + 1)
    C = np.empty(m + 1)
    for p in range(n):
        r0, r1, r2 = radii[p, 0], radii[p, 1], radii[p, 2]
        s0, s1, s2 = sides[p, 0], sides[p, 1], sides[p, 2]
        flagged[p] = True
        if not _valid(r0, r1, r2, s0, s1, s2):
            continue
        v, served = interp_point(r0, r1, r2, s0, s1, s2, gap, rho_lo, rho_hi, rho_inv, n_rho,
                                 strides, values, curv, snap)
        if not served:
            continue
        qw = math.exp(v)
        rbar = (r0 + r1 + r2) / 3.0
        y0 = 1.0 / (qw * rbar ** 4.0) if qw > 0 else math.inf
        rmax = max(max(r0, r1), r2)
        H0 = min(max(heights[p, 0], 0.0), rmax)
        H1 = min(max(heights[p, 1], 0.0), rmax)
        Hmax = max(H0, H1)
        th_end = math.asin(min(max(Hmax / rmax if rmax > 0 else 0.0, 0.0), 1.0))
        smin = min(min(s0, s1), s2)
        small = 2e-2 * smin
        ok = True
        nlook = 0
        for j in range(m + 1):
            th = th_end * tnodes[j]
            h[j] = rmax * math.sin(th)
            dhdth[j] = rmax * math.cos(th)
            if j == 0:
                y[0] = y0
                continue
            hh = h[j] * h[j]
            a0 = math.sqrt(max(r0 * r0 - hh, 0.0))
            a1 = math.sqrt(max(r1 * r1 - hh, 0.0))
            a2 = math.sqrt(max(r2 * r2 - hh, 0.0))
            if max(max(a0, a1), a2) <= 0.0 or not Hmax > 0.0:
                y[j] = 0.0                      # no disk left: no wall, no resistance
                continue
            a0, a1, a2 = max(a0, small), max(a1, small), max(a2, small)
            if not _valid(a0, a1, a2, s0, s1, s2):
                ok = False
                break
            v, served = interp_point(a0, a1, a2, s0, s1, s2, gap, rho_lo, rho_hi, rho_inv,
                                     n_rho, strides, values, curv, snap)
            if not served:
                ok = False
                break
            nlook += 1
            rb = (a0 + a1 + a2) / 3.0
            q = math.exp(v) * rb ** 4.0
            y[j] = 1.0 / q if q < math.inf else 0.0
        if not ok:
            continue
        closed = not (y0 < math.inf)
        for j in range(m + 1):
            if not (abs(y[j]) < math.inf):
                closed = True
                y[j] = 0.0
        dth = max(th_end / m, 1e-300)
        for j in range(m + 1):
            if j == 0:
                dy = 0.0                            # symmetry at the window
            elif j == m:
                dy = (y[m] - y[m - 1]) / 1.0 / dth / dhdth[j]
            else:
                dy = (y[j + 1] - y[j - 1]) / 2.0 / dth / dhdth[j]
            yj = y[j]
            if yj > 0.0:
                g = dy / yj
                s = math.sqrt(8.0 / (math.pi * yj)) * (g * g) / 12.0
                f = 1.0 + s / (1.0 + s)
                if math.isnan(f):
                    f = 2.0                         # s = inf/inf: steep wall
            else:
                f = 1.0
            F[j] = yj * f
        C[0] = 0.0
        for j in range(m):
            C[j + 1] = C[j] + 0.5 * (F[j + 1] + F[j]) * (h[j + 1] - h[j])
        for c in range(2):
            Hc = H0 if c == 0 else H1
            if closed:
                resist[p, c] = math.inf
                continue
            if not Hc > 0.0:
                resist[p, c] = 0.0
                continue
            below = Hc * (1 - 1e-12)
            j = 0
            for c2 in range(m + 1):
                if h[c2] < below:
                    j += 1
            j = min(max(j, 1), m)
            h0, h1, F0, F1 = h[j - 1], h[j], F[j - 1], F[j]
            w = (Hc - h0) / (h1 - h0) if h1 > h0 else 0.0
            w = min(max(w, 0.0), 1.0)
            resist[p, c] = C[j - 1] + (Hc - h0) * (F0 + 0.5 * w * (F1 - F0))
        q_win[p] = qw
        looked[p] = nlook
        flagged[p] = False
