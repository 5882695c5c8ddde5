"""The interpolation grids' node sets: the radius lattice, :class:`GridSpec` and the named grids.

A :class:`GridSpec` is the full box over the five coordinates of :mod:`cache._interp` (three
gaps, two radius deviations): one node set on the three gap axes, with a node at 0 where Q* has
its kink, and a uniform lattice centred on 0 on the two radius axes, so that a permutation of
the vertices maps nodes to nodes.  These are the grids' definitions, apart from how a table
interpolates on them (:mod:`cache._interp`): precomputation, the commands' ``--grid`` choices,
the orbits (:mod:`cache._orbits`) and the deep-pair grids (:mod:`cache._pair`, which adds
``p1`` to :data:`GRIDS`) read them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["GRIDS", "GridSpec", "RadiusLattice"]


class RadiusLattice:
    """The two radius-deviation axes every grid ends with: ``rho_count`` nodes spaced
    ``rho_step`` and centred on 0; a subclass names its :attr:`axes`."""

    @property
    def rho_nodes(self):
        return self.rho_step * (np.arange(self.rho_count) - (self.rho_count - 1) / 2)

    @property
    def shape(self):
        return tuple(len(a) for a in self.axes)


class GridSpec(RadiusLattice):
    """Definition of a grid: gap nodes (shared by the 3 gap axes) and the radius lattice.

    Parameters
    ----------
    name : str
    gap_nodes : sequence of float
        Increasing, odd count, must contain 0 (units of r̄).
    rho_step : float
        Spacing h of the radius-deviation lattice.
    rho_count : int
        Odd number of nodes per radius axis, centred on 0: ``h * (arange(n) - (n - 1) / 2)``.
    """

    def __init__(self, name, gap_nodes, rho_step, rho_count, *, _sub=False):
        g = np.asarray(gap_nodes, dtype=float)
        if g.ndim != 1 or len(g) < 2 or np.any(np.diff(g) <= 0):
            raise ValueError(f"gap_nodes must be increasing, got {g}")
        if not _sub and (len(g) < 3 or len(g) % 2 == 0 or not np.any(g == 0.0)):
            raise ValueError(f"gap_nodes need an odd count >= 3 and a node at 0, got {g}")
        if rho_count < 1 or not rho_step > 0 or (not _sub and rho_count % 2 == 0):
            raise ValueError(f"rho_count must be odd >= 1 and rho_step > 0, got {rho_count}, {rho_step}")
        self.name = str(name)
        self.gap_nodes = g
        self.rho_step = float(rho_step)
        self.rho_count = int(rho_count)

    @property
    def axes(self):
        g, p = self.gap_nodes, self.rho_nodes
        return [g, g, g, p, p]

    def to_dict(self):
        return {"name": self.name, "gap_nodes": self.gap_nodes.tolist(),
                "rho_step": self.rho_step, "rho_count": self.rho_count}

    @classmethod
    def from_dict(cls, d):
        return cls(d["name"], d["gap_nodes"], d["rho_step"], d["rho_count"])

    def node_shapes(self):
        """All nodes as throats: ``(radii (M, 3), sides (M, 3))`` with r̄ = 1, C order."""
        mesh = np.meshgrid(*self.axes, indexing="ij")
        x = np.stack([m.ravel() for m in mesh], axis=1)
        r = np.stack([1 + x[:, 3], 1 + x[:, 4], 1 - x[:, 3] - x[:, 4]], axis=1)
        s = np.stack([r[:, 0] + r[:, 1] + x[:, 0], r[:, 0] + r[:, 2] + x[:, 1],
                      r[:, 1] + r[:, 2] + x[:, 2]], axis=1)
        return r, s

    def __repr__(self):
        return (f"GridSpec({self.name!r}, {len(self.gap_nodes)} gap nodes "
                f"[{self.gap_nodes[0]}, {self.gap_nodes[-1]}], rho {self.rho_count} x {self.rho_step})")


def _arange(lo, hi, step):
    return [round(lo + k * step, 10) for k in range(int(round((hi - lo) / step)) + 1)]


#: grids for ``python -m cache.precompute --grid NAME``; g2 is g1's coarse sub-grid (built first)
GRIDS = {
    "tiny": GridSpec("tiny", [-0.05, 0.0, 0.1, 0.3, 0.6], 0.15, 3),    # tests and smoke runs
    # gaps -0.2 .. 2.2 step 0.2 (g2) / 0.1 (g1), radius deviations +-0.25 step 0.25 / 0.125
    "g2": GridSpec("g2", _arange(-0.2, 2.2, 0.2), 0.25, 3),
    "g1": GridSpec("g1", _arange(-0.2, 2.2, 0.1), 0.125, 5),
    # beyond g1 for clumps (docs/cache-table.md): radius deviations +-0.375 and gaps to 4.6 (x1),
    "x1": GridSpec("x1", _arange(-0.2, 2.2, 0.1) + [2.4, 2.6, 2.8, 3, 3.4, 3.8, 4.2, 4.6], 0.125, 7),
    "d1": GridSpec("d1", _arange(-2.2, 2.2, 0.2), 0.125, 9),    # deep overlaps, deviations 0.5
}
