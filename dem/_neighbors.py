r"""Verlet neighbour list with a skin, built from a sorted cell list (numba).

Candidate pairs are all (i, j), i < j, with centre distance below r_i + r_j + skin. The
list stays valid until some particle has moved more than skin/2 since the last build (then
no pair outside the list can touch). The build bins the centres into cubic cells of side
≥ 2 r_max + skin (a counting sort by cell), then every particle looks at the 27 cells
around its own, in parallel: linear in N. Pairs come out sorted by the key ``i * N + j``;
tangential contact history is carried across rebuilds by matching keys with
:func:`numpy.searchsorted`. For each particle the list also gives the pairs in which it is
the first member (a contiguous range) and those in which it is the second (``by_second``),
both in pair order: the force kernels sum each particle's contacts in that fixed order, so
results do not depend on the number of threads.
"""

from __future__ import annotations

import logging

import numba
import numpy as np

__all__ = ["VerletList", "build_pairs", "remap_history", "max_displacement"]

log = logging.getLogger(__name__)


@numba.njit(cache=True, error_model="numpy")
def _cell_sort(x, cell, lo, dims):
    """Counting sort of the particles by cell: (cell of each particle, order, cell starts)."""
    n = x.shape[0]
    ncell = dims[0] * dims[1] * dims[2]
    cid = np.empty(n, dtype=np.int64)
    start = np.zeros(ncell + 1, dtype=np.int64)
    for p in range(n):
        cx = min(max(int((x[p, 0] - lo[0]) / cell), 0), dims[0] - 1)
        cy = min(max(int((x[p, 1] - lo[1]) / cell), 0), dims[1] - 1)
        cz = min(max(int((x[p, 2] - lo[2]) / cell), 0), dims[2] - 1)
        cid[p] = (cx * dims[1] + cy) * dims[2] + cz
        start[cid[p] + 1] += 1
    for c in range(ncell):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for p in range(n):
        order[fill[cid[p]]] = p
        fill[cid[p]] += 1
    return cid, order, start


@numba.njit(inline="always", cache=True, error_model="numpy")
def _insertion_sort(a, lo, hi):
    """Sort ``a[lo:hi]`` in place (a particle's dozen neighbours: faster than a general sort)."""
    for s in range(lo + 1, hi):
        v = a[s]
        t = s - 1
        while t >= lo and a[t] > v:
            a[t + 1] = a[t]
            t -= 1
        a[t + 1] = v


@numba.njit(parallel=True, cache=True, error_model="numpy")
def _scan(xs, rs, order, skin, cid, start, dims, counts, offsets, out):
    """Neighbours j > i of every particle i within r_i + r_j + skin: counts only when
    ``out`` is empty, else written (ascending j) at ``offsets[i]``. ``xs``, ``rs`` are the
    centres and radii in cell order (``order``), so each cell's candidates are contiguous."""
    n = xs.shape[0]
    write = out.shape[0] > 0
    for a in numba.prange(n):
        i = order[a]
        c = cid[i]
        cz = c % dims[2]
        cy = (c // dims[2]) % dims[1]
        cx = c // (dims[1] * dims[2])
        xa, ya, za, ra = xs[a, 0], xs[a, 1], xs[a, 2], rs[a] + skin
        k = 0
        base = offsets[i]
        for ax in range(max(cx - 1, 0), min(cx + 2, dims[0])):
            for ay in range(max(cy - 1, 0), min(cy + 2, dims[1])):
                c0 = (ax * dims[1] + ay) * dims[2]
                # the z-neighbour cells of one (x, y) column are consecutive: one contiguous run
                for b in range(start[c0 + max(cz - 1, 0)], start[c0 + min(cz + 2, dims[2])]):
                    j = order[b]
                    if j <= i:
                        continue
                    dx = xs[b, 0] - xa
                    dy = xs[b, 1] - ya
                    dz = xs[b, 2] - za
                    reach = ra + rs[b]
                    if dx * dx + dy * dy + dz * dz < reach * reach:
                        if write:
                            out[base + k] = j
                        k += 1
        if write:
            _insertion_sort(out, base, base + k)
        else:
            counts[i] = k


def build_pairs(centers, radii, skin):
    """Candidate contact pairs, (Np, 2) int64 array sorted by key i*N+j, i < j.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    skin : float, m
        Extra distance beyond touching.
    """
    x = np.ascontiguousarray(centers, dtype=float)
    r = np.ascontiguousarray(radii, dtype=float)
    n = len(r)
    if n < 2:
        return np.empty((0, 2), dtype=np.int64)
    cell = 2.0 * float(r.max()) + float(skin)
    lo = x.min(axis=0)
    span = x.max(axis=0) - lo
    # a grid of at most ~8 cells a particle: a particle far away (escaping) coarsens it
    cell = max(cell, float((np.prod(span + cell) / (8.0 * n + 64)) ** (1 / 3)))
    dims = np.maximum((span // cell).astype(np.int64) + 1, 1)
    cid, order, start = _cell_sort(x, cell, lo, dims)
    xs, rs = x[order], r[order]
    counts = np.zeros(n, dtype=np.int64)
    offsets = np.zeros(n + 1, dtype=np.int64)
    _scan(xs, rs, order, float(skin), cid, start, dims, counts, offsets, np.empty(0, dtype=np.int64))
    np.cumsum(counts, out=offsets[1:])
    js = np.empty(offsets[-1], dtype=np.int64)
    _scan(xs, rs, order, float(skin), cid, start, dims, counts, offsets, js)
    return np.column_stack([np.repeat(np.arange(n, dtype=np.int64), counts), js])


def remap_history(old_keys, old_values, new_keys):
    """Carry per-pair values (e.g. shear springs) from an old sorted key list to a new one.

    Pairs absent from the old list get zeros.

    Parameters
    ----------
    old_keys : (M,) int64, sorted
    old_values : (M, k) array
    new_keys : (P,) int64

    Returns
    -------
    (P, k) array
    """
    out = np.zeros((len(new_keys),) + old_values.shape[1:], dtype=old_values.dtype)
    if len(old_keys) == 0 or len(new_keys) == 0:
        return out
    pos = np.searchsorted(old_keys, new_keys)
    pos_c = np.minimum(pos, len(old_keys) - 1)
    found = old_keys[pos_c] == new_keys
    out[found] = old_values[pos_c[found]]
    return out


@numba.njit(cache=True, error_model="numpy")
def max_displacement(x, ref):
    """Largest distance, m, between rows of two (N, 3) arrays (0 for N = 0)."""
    m = 0.0
    for p in range(x.shape[0]):
        dx = x[p, 0] - ref[p, 0]
        dy = x[p, 1] - ref[p, 1]
        dz = x[p, 2] - ref[p, 2]
        m = max(m, dx * dx + dy * dy + dz * dz)
    return np.sqrt(m)


@numba.njit(cache=True, error_model="numpy")
def _reach_used(x, ref, r, ref_r):
    """2 (largest displacement) + 2 (largest growth) since the reference, m."""
    g = -np.inf
    for p in range(r.shape[0]):
        g = max(g, r[p] - ref_r[p])
    return 2.0 * max_displacement(x, ref) + 2.0 * g


class VerletList:
    """Pair list plus the state needed to know when it must be rebuilt.

    Attributes
    ----------
    pairs : (Np, 2) int64
    keys : (Np,) int64, sorted
    first_start : (N + 1,) int64
        Pairs ``first_start[p]:first_start[p + 1]`` have p as first member.
    second_start, by_second : (N + 1,) and (Np,) int64
        ``by_second[second_start[p]:second_start[p + 1]]`` are the pairs with p as second
        member, ascending.
    n_builds : int
    groups : (N,) int64 or None
        Pairs whose two members have the same group (the spheres of one rigid grain) are left
        out of the list: they are never contacts.
    """

    def __init__(self, skin, *, groups=None):
        if not skin > 0:
            raise ValueError(f"skin must be positive, got {skin}")
        self.skin = float(skin)
        self.groups = None if groups is None else np.asarray(groups, dtype=np.int64)
        self.pairs = np.empty((0, 2), dtype=np.int64)
        self.keys = np.empty(0, dtype=np.int64)
        self.first_start = self.second_start = self.by_second = np.zeros(1, dtype=np.int64)
        self._ref = None
        self._ref_radii = None
        self.n_builds = 0

    def needs_rebuild(self, centers, radii):
        """True when a particle moved more than skin/2 (or grew) since the last build."""
        if self._ref is None or len(self._ref) != len(centers):
            return True
        return _reach_used(centers, self._ref, radii, self._ref_radii) > self.skin

    def build(self, centers, radii):
        """Rebuild; returns the old keys so callers can remap pair history."""
        old = self.keys
        self.pairs = build_pairs(centers, radii, self.skin)
        if self.groups is not None:
            self.pairs = self.pairs[self.groups[self.pairs[:, 0]] != self.groups[self.pairs[:, 1]]]
        n = len(radii)
        i, j = self.pairs[:, 0], self.pairs[:, 1]
        self.keys = i * n + j
        self.first_start = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(i, minlength=n), out=self.first_start[1:])
        self.second_start = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(j, minlength=n), out=self.second_start[1:])
        self.by_second = np.argsort(j, kind="stable").astype(np.int64)
        self._ref = np.array(centers, dtype=float)
        self._ref_radii = radii.copy()
        self.n_builds += 1
        return old
