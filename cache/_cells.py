"""Whole-grid array operations of the interpolation table (:mod:`cache._interp`).

A grid's values are a 5-D array, one axis per coordinate; a *cell* is stored at its lower node.
These run once per table load, over every node, so they are written as whole-array passes.
"""

from __future__ import annotations

import numpy as np

__all__ = ["second_difference", "cell_reduce", "cell_mean", "cell_max", "cell_all", "fill_nan"]


def second_difference(v, a, axis):
    """Second derivative of v along ``axis`` on the non-uniform nodes ``a`` (edges copied)."""
    def cut(sl):
        return tuple(sl if k == axis else slice(None) for k in range(v.ndim))

    shape = [-1 if k == axis else 1 for k in range(v.ndim)]
    hm = (a[1:-1] - a[:-2]).reshape(shape)
    hp = (a[2:] - a[1:-1]).reshape(shape)
    out = np.empty_like(v)
    mid = v[cut(slice(1, -1))]
    out[cut(slice(1, -1))] = 2 * ((v[cut(slice(2, None))] - mid) / hp
                                  - (mid - v[cut(slice(None, -2))]) / hm) / (hp + hm)
    out[cut(0)] = out[cut(1)]
    out[cut(-1)] = out[cut(-2)]
    return out


def cell_reduce(a, pair, last=None):
    """Reduce each cell's 2^5 corners with ``pair(lower, upper)`` one axis at a time, stored at
    the cell's lower node (same shape as ``a``); ``last`` overwrites the last layer of each axis."""
    out = a.copy()
    for d in range(a.ndim):
        if a.shape[d] == 1:
            continue
        lo = [slice(None)] * a.ndim
        hi = [slice(None)] * a.ndim
        lo[d] = slice(0, -1)
        hi[d] = slice(1, None)
        out[tuple(lo)] = pair(out[tuple(lo)], out[tuple(hi)])
        if last is not None:
            edge = [slice(None)] * a.ndim
            edge[d] = -1
            out[tuple(edge)] = last
    return out


def cell_mean(a):
    """Mean over the 2^5 corners of each cell, stored at the cell's lower node."""
    return cell_reduce(a, lambda lo, hi: 0.5 * (lo + hi))


def cell_max(a):
    """Max over the 2^5 corners of each cell, stored at the cell's lower node (same shape as a)."""
    return cell_reduce(a, np.maximum)


def cell_all(mask):
    """True where all corners of the cell at that lower node are True (last layers: False)."""
    return cell_reduce(mask, np.logical_and, last=False)


def fill_nan(v, max_sweeps=50):
    """Replace NaN nodes by the mean of finite axis neighbours, sweep by sweep (keeps lookups finite).

    Each sweep reads the values left by the previous one (Jacobi order) and touches only the
    NaN nodes (3 % of g1's): 0.35 s -> 0.01 s on g1, same bits as whole-array sweeps.
    """
    v = v.copy()
    flat = v.reshape(-1)
    strides = [int(np.prod(v.shape[d + 1:])) for d in range(v.ndim)]
    for _ in range(max_sweeps):
        bad = np.flatnonzero(~np.isfinite(flat))
        if not bad.size:
            break
        coord = np.unravel_index(bad, v.shape)
        acc = np.zeros(bad.size)
        cnt = np.zeros(bad.size)
        for d in range(v.ndim):
            if v.shape[d] == 1:
                continue
            for shift in (1, -1):
                inside = (coord[d] - shift >= 0) & (coord[d] - shift < v.shape[d])
                nb = np.where(inside, flat[np.where(inside, bad - shift * strides[d], 0)], np.nan)
                ok = np.isfinite(nb)
                acc[ok] += nb[ok]
                cnt[ok] += 1
        fill = cnt > 0
        if not fill.any():
            break
        flat[bad[fill]] = acc[fill] / cnt[fill]
    v[~np.isfinite(v)] = 0.0
    return v
