r"""One point of :class:`cache.GridTable`'s interpolation as a numba function, for compiled callers.

:func:`interp_point` evaluates :math:`\ln Q^*` at one throat exactly as
``GridTable.at_throats(..., errors=False)`` does for a chunk of throats (the same lookup order,
:mod:`cache._order`, and coordinates,
same cell, the 32 corners blended in float32 in the same order, the same curvature
terms): the values agree bit for bit (``tests/cache/test_cache_kernel.py``). A compiled loop
(the network's conduit sections, :mod:`network.conductance._conduit_kernel`) calls it per
section instead of gathering (N, 5) coordinate columns through numpy. The arrays come from
:meth:`GridTable.kernel_arrays`; :func:`point_kernel` compiles it (numba is imported then).
"""

from __future__ import annotations

import threading

import numpy as np

__all__ = ["point_kernel"]

_COMPILED: list = []
# one compiler at a time: threads (the network's conductance blocks) may ask together first
_LOCK = threading.Lock()


def point_kernel():
    """:func:`interp_point` compiled by numba (imported here, on the first call: ``import
    cache`` stays cheap), to be called from other numba code or a test's compiled loop."""
    if not _COMPILED:
        with _LOCK:
            if not _COMPILED:
                import numba

                inline = numba.njit(inline="always", error_model="numpy")
                g = globals()
                for name in ("_lookup_order", "_side", "_gap_cell", "_rho_cell", "_lerp",
                             "_square", "_cube"):
                    g[name] = inline(g[name])
                _COMPILED.append(numba.njit(cache=True, nogil=True,
                                            error_model="numpy")(interp_point))
    return _COMPILED[0]


def interp_point(r0, r1, r2, s0, s1, s2, gap, rho_lo, rho_hi, rho_inv, n_rho, strides,
                 values, curv, snap):
    r"""(ln Q*, served) of the throat with radii (r0, r1, r2) and sides (s0, s1, s2).

    Coordinates :math:`\delta_{ij} = (l_{ij} - r_i - r_j)/\bar r`, :math:`\rho_i = r_i/\bar r - 1`
    (:func:`cache.grid_coordinates`); the gap axes by bisection (a point within ``snap``
    below a node uses the cell above it), the radius axes uniform; ``served`` is False
    outside the box or in a cell the table does not serve. Arguments:
    :meth:`GridTable.kernel_arrays`.
    """
    r0, r1, r2, s0, s1, s2 = _lookup_order(r0, r1, r2, s0, s1, s2)
    inv = 1.0 / ((r0 + r1 + r2) * (1.0 / 3.0))
    i0, t0, o0 = _gap_cell((s0 - r0 - r1) * inv, gap, snap)
    i1, t1, o1 = _gap_cell((s1 - r0 - r2) * inv, gap, snap)
    i2, t2, o2 = _gap_cell((s2 - r1 - r2) * inv, gap, snap)
    i3, t3, o3 = _rho_cell(r0 * inv - 1.0, rho_lo, rho_hi, rho_inv, n_rho)
    i4, t4, o4 = _rho_cell(r1 * inv - 1.0, rho_lo, rho_hi, rho_inv, n_rho)
    outside = o0 or o1 or o2 or o3 or o4
    base = (i0 * strides[0] + i1 * strides[1] + i2 * strides[2] + i3 * strides[3]
            + i4 * strides[4])
    # the 32 corners blended by b <- a + t (b - a) in float32 along d = 4, 3, ..., 0, the
    # tree GridTable's chunked evaluation reduces (same pairs, so the same bits)
    s0_, s1_, s2_, s3_, s4_ = strides[0], strides[1], strides[2], strides[3], strides[4]
    v = np.float64(_lerp(_cube(values, base, s1_, s2_, s3_, s4_, t1, t2, t3, t4),
                         _cube(values, base + s0_, s1_, s2_, s3_, s4_, t1, t2, t3, t4), t0))
    kk = curv[base]
    one = np.float32(1.0)
    v -= np.float64(t0 * (one - t0) * kk[0])
    v -= np.float64(t1 * (one - t1) * kk[1])
    v -= np.float64(t2 * (one - t2) * kk[2])
    v -= np.float64(t3 * (one - t3) * kk[3])
    v -= np.float64(t4 * (one - t4) * kk[4])
    return v, kk[5] > 0 and not outside


def _lookup_order(r0, r1, r2, s0, s1, s2):
    """One throat in :func:`cache._order.lookup_order`'s order: a stable sort of the vertices
    by (radius, opposite side), then the vertex of largest |rho| third."""
    a, b, c = 0, 1, 2
    r = (r0, r1, r2)
    opp = (s2, s1, s0)
    if r[b] < r[a] or (r[b] == r[a] and opp[b] < opp[a]):
        a, b = b, a
    if r[c] < r[b] or (r[c] == r[b] and opp[c] < opp[b]):
        b, c = c, b
        if r[b] < r[a] or (r[b] == r[a] and opp[b] < opp[a]):
            a, b = b, a
    if 2.0 * r[b] > r[a] + r[c]:
        a, b, c = b, c, a
    return (r[a], r[b], r[c], _side(a, b, s0, s1, s2), _side(a, c, s0, s1, s2),
            _side(b, c, s0, s1, s2))


def _side(i, j, s0, s1, s2):
    """l_ij of vertices i != j (0-based) from ``[l12, l13, l23]``."""
    k = i + j                 # 1: pair (0, 1), 2: (0, 2), 3: (1, 2)
    return s0 if k == 1 else (s1 if k == 2 else s2)


def _gap_cell(x, gap, snap):
    """(cell index, float32 position in it, outside the axis) on a gap axis:
    ``searchsorted(gap, x + snap, 'right') - 1`` by bisection, clipped to the cells."""
    ng = gap.shape[0]
    key = x + snap
    lo, hi = 0, ng
    while lo < hi:
        mid = (lo + hi) >> 1
        if gap[mid] <= key:
            lo = mid + 1
        else:
            hi = mid
    i = min(max(lo - 1, 0), ng - 2)
    a = gap[i]
    return i, np.float32((x - a) / (gap[i + 1] - a)), x < gap[0] - 1e-9 or x > gap[ng - 1] + 1e-9


def _rho_cell(x, lo, hi, inv_step, n):
    """(cell index, float32 position in it, outside the axis) on the uniform radius axis."""
    f = (x - lo) * inv_step
    fi = min(max(np.floor(f), 0.0), n - 2.0)
    return int(fi), np.float32(f - fi), x < lo - 1e-9 or x > hi + 1e-9


def _lerp(a, b, t):
    return a + t * (b - a)


def _square(values, o, s3, s4, t3, t4):
    """Bilinear blend over the last two axes of the cell at flat index ``o``."""
    return _lerp(_lerp(values[o], values[o + s4], t4),
                 _lerp(values[o + s3], values[o + s3 + s4], t4), t3)


def _cube(values, o, s1, s2, s3, s4, t1, t2, t3, t4):
    """Blend over the last four axes of the cell at flat index ``o``."""
    return _lerp(_lerp(_square(values, o, s3, s4, t3, t4),
                       _square(values, o + s2, s3, s4, t3, t4), t2),
                 _lerp(_square(values, o + s1, s3, s4, t3, t4),
                       _square(values, o + s1 + s2, s3, s4, t3, t4), t2), t1)
