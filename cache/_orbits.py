r"""Vertex-permutation orbits of a grid's nodes: compact storage and the extension grid's lookup.

A permutation of a throat's three vertices permutes its gaps and radius deviations; on a grid
whose three gap axes share one node set and whose radius lattice is symmetric it maps a node
:math:`(\delta_{12}, \delta_{13}, \delta_{23}, \rho_1, \rho_2)` to another node of the same
lattice, which lies in the grid box when its two first deviations do (:math:`\rho_3 =
-\rho_1 - \rho_2`). Precomputation solves each distinct shape once, so the node values repeat
over each orbit: :func:`compact` keeps the value of each orbit's first node in C order (about a
sixth of the nodes), :func:`expand` rebuilds the whole grid from them, bit for bit.

The extension grids serve, in turn, rows the shipped g1 does not: ``x1`` (g1's nodes, radius
deviations to ±0.375, gaps to 4.6), then ``d1`` (gaps from -2.2, the deep overlaps of two
spheres of one grain, deviations to ±0.5, step 0.2), then ``p1`` (the deep pairs that d1's
cells cannot hold, in coordinates of their own: :mod:`cache._pair`; no orbits); every grid reads a throat with its vertex of
largest |ρ| third, where a box reaches twice as far (:mod:`cache._order`, ``docs/cache-table.md``).
"""

from __future__ import annotations

import numpy as np

from ._grids import GRIDS

__all__ = ["DEFAULT_GRID", "EXTENSION_GRIDS", "compact", "expand", "orbit_representatives",
           "table_coverage"]

#: grid served when a table has none of its own (shipped in ``cache/data``)
DEFAULT_GRID = "g1"

#: grids shipped to serve, in this order, the rows the default grid cannot (``cache/data``)
EXTENSION_GRIDS = ("x1", "d1", "p1")


def table_coverage() -> str:
    """The shapes the shipped tables serve, in words: for :data:`DEFAULT_GRID`, then each of
    :data:`EXTENSION_GRIDS` in the order the lookup asks them, its gap range and the largest
    deviation of the two first radii, in mean radii r̄ (the third radius, the largest |ρ| for
    lookup order, reaches twice as far: :mod:`cache._order`)."""
    parts = []
    for name in (DEFAULT_GRID,) + EXTENSION_GRIDS:
        g = GRIDS[name]
        if hasattr(g, "describe"):
            parts.append(g.describe())
            continue
        parts.append(f"{name}: gaps {g.gap_nodes[0]:g} to {g.gap_nodes[-1]:g}, radius "
                     f"deviations to {g.rho_nodes[-1]:g}")
    return "; ".join(parts) + " (mean radii)"

_PERMS = ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0))


def orbit_representatives(spec):
    """Flat index (n_nodes,) int64 of each node's orbit representative: the smallest flat index
    among the node's vertex permutations that lie in the box of ``spec`` (a GridSpec)."""
    shape = spec.shape
    ng, nr = shape[0], shape[3]
    c = (nr - 1) // 2
    idx = np.indices(shape, dtype=np.int64).reshape(5, -1)
    gap = {(0, 1): idx[0], (0, 2): idx[1], (1, 2): idx[2]}
    rho = (idx[3], idx[4], 3 * c - idx[3] - idx[4])     # rho_3 = -rho_1 - rho_2 on the lattice
    rep = np.arange(idx.shape[1], dtype=np.int64)
    for a, b, d in _PERMS:
        pa, pb = rho[a], rho[b]
        inbox = (pa >= 0) & (pa < nr) & (pb >= 0) & (pb < nr)
        flat = (((gap[tuple(sorted((a, b)))] * ng + gap[tuple(sorted((a, d)))]) * ng
                 + gap[tuple(sorted((b, d)))]) * nr + pa) * nr + pb
        np.minimum(rep, np.where(inbox, flat, rep), out=rep)
    return rep


def compact(spec, *arrays):
    """The values of each orbit's representative node, one (n_orbits,) array per (``spec.shape``)
    array; ValueError when an orbit holds unequal values (NaN equals NaN)."""
    rep = orbit_representatives(spec)
    own = rep == np.arange(rep.size)
    out = []
    for a in arrays:
        flat = np.asarray(a, dtype=float).ravel()
        back = flat[own][np.cumsum(own)[rep] - 1]
        if not np.array_equal(back, flat, equal_nan=True):
            raise ValueError(f"grid {spec.name!r}: {int(np.sum(~((back == flat) | np.isnan(flat))))} "
                             "nodes differ from their orbit's value: not a permutation-symmetric grid")
        out.append(flat[own])
    return out


def expand(spec, *values):
    """The grids (``spec.shape``), one per array of orbit representatives' values
    (:func:`compact`), sharing one pass over the orbits."""
    rep = orbit_representatives(spec)
    own = rep == np.arange(rep.size)
    pick = np.cumsum(own)[rep] - 1
    out = []
    for v in values:
        v = np.asarray(v, dtype=float)
        if v.shape != (int(own.sum()),):
            raise ValueError(f"grid {spec.name!r} has {int(own.sum())} orbits, got {v.shape}")
        out.append(v[pick].reshape(spec.shape))
    return out
