r"""The deep-pair grid: windows bounded by two overlapping spheres of one grain and a third sphere.

A multi-sphere grain puts two of its spheres, overlapping by 1-2 r̄, at two corners of many of
a bed's windows (:func:`throats.deep_overlap`). In the gap coordinates of the other grids
(:mod:`cache._interp`) such a window lies in a band :math:`|\delta_{13} - \delta_{23} + \rho_1 -
\rho_2| < l_{12}` narrower than one cell when the pair's side :math:`l_{12}` is short (0.1-0.7 r̄
for soybean and wheat), so those grids cannot serve it (``docs/cache-table.md``). This grid reads
the window in coordinates that follow its shape:

.. math::
    x = \bigl(\ln(l_{12}/\bar r),\ \delta_{13},\ \tau,\ \rho_1,\ \rho_2\bigr), \qquad
    \tau = \frac{l_{13} - l_{23}}{l_{12}} \in (-1, 1),

with vertices 1 and 2 the deepest-overlapping pair, vertex 1 the one of the pair nearer the
third (:math:`\delta_{13} \le \delta_{23}`; a tie: the smaller radius first), :math:`\delta_{ij}
= (l_{ij} - r_i - r_j)/\bar r` and :math:`\rho_i = r_i/\bar r - 1`. Every node with
:math:`|\tau| < 1` is a triangle; :math:`\tau` is where along the pair the third centre faces,
:math:`\delta_{13}` its gap to the nearer sphere of the pair (a node at 0: the contact kink,
as on the gap axes of the other grids), and the open sliver's width grows with :math:`l_{12}`,
whose logarithm is the axis. The table holds FE's Q* over the shape factor's geometric part
(:class:`PairTable`); the interpolation, error estimate and derived arrays are
:class:`cache.GridTable`'s over these five axes.
"""

from __future__ import annotations

import numpy as np
from throats import validate_throats
from throats._area import open_area_perimeter

from ._cells import cell_all
from ._grids import GRIDS, RadiusLattice
from ._interp import GridTable

__all__ = ["PairSpec", "PairTable", "pair_coordinates", "geometric_factor", "DEEP_GAP"]

#: nodes whose ratio of FE to the geometric factor lies beyond this factor either way (an open
#: area that vanishes) are not served
RATIO_MAX = 50.0

#: a pair closer than this gap (units of r̄) is a deep overlap (``throats.deep_overlap``)
DEEP_GAP = -0.2


class PairSpec(RadiusLattice):
    r"""A deep-pair grid: node sets of its five axes (module docstring).

    Parameters
    ----------
    name : str
    log_side_nodes : sequence of float
        Nodes of :math:`\ln(l_{12}/\bar r)`, increasing.
    gap_nodes : sequence of float
        Nodes of :math:`\delta_{13}` (units of r̄), increasing, with a node at 0.
    tau_nodes : sequence of float
        Nodes of :math:`\tau`, increasing, inside (-1, 1).
    rho_step, rho_count : float, int
        The radius lattice of :math:`\rho_1, \rho_2`: ``rho_step * (arange(n) - (n - 1) / 2)``.
    """

    kind = "pair"

    def __init__(self, name, log_side_nodes, gap_nodes, tau_nodes, rho_step, rho_count, *,
                 _sub=False):
        axes = [np.asarray(a, dtype=float) for a in (log_side_nodes, gap_nodes, tau_nodes)]
        for a in axes:
            if a.ndim != 1 or len(a) < 2 or np.any(np.diff(a) <= 0):
                raise ValueError(f"axis nodes must be increasing, got {a}")
            if not _sub and len(a) % 2 == 0:
                raise ValueError(f"axis nodes need an odd count, got {a}")
        if not np.all(np.abs(axes[2]) < 1):
            raise ValueError(f"tau nodes must lie inside (-1, 1), got {axes[2]}")
        if rho_count < 1 or not rho_step > 0 or (not _sub and rho_count % 2 == 0):
            raise ValueError(f"rho_count must be odd >= 1 and rho_step > 0, got {rho_count}, {rho_step}")
        self.name = str(name)
        self.log_side_nodes, self.gap_nodes, self.tau_nodes = axes
        self.rho_step = float(rho_step)
        self.rho_count = int(rho_count)

    @property
    def axes(self):
        p = self.rho_nodes
        return [self.log_side_nodes, self.gap_nodes, self.tau_nodes, p, p]

    def to_dict(self):
        return {"name": self.name, "kind": self.kind,
                "log_side_nodes": self.log_side_nodes.tolist(), "gap_nodes": self.gap_nodes.tolist(),
                "tau_nodes": self.tau_nodes.tolist(), "rho_step": self.rho_step,
                "rho_count": self.rho_count}

    @classmethod
    def from_dict(cls, d):
        return cls(d["name"], d["log_side_nodes"], d["gap_nodes"], d["tau_nodes"], d["rho_step"],
                   d["rho_count"])

    def coarse(self):
        """Every other node on each axis (the error estimate's sub-grid)."""
        return PairSpec(self.name + "/2", self.log_side_nodes[::2], self.gap_nodes[::2],
                        self.tau_nodes[::2], 2 * self.rho_step, (self.rho_count + 1) // 2,
                        _sub=True)

    def node_shapes(self):
        """All nodes as throats ``(radii (M, 3), sides (M, 3))``, r̄ = 1, C order: radii
        :math:`1 + \\rho_1, 1 + \\rho_2, 1 - \\rho_1 - \\rho_2`, :math:`l_{12} = e^{x_0}`,
        :math:`l_{13} = r_1 + r_3 + \\delta_{13}`, :math:`l_{23} = l_{13} - \\tau l_{12}`."""
        mesh = np.meshgrid(*self.axes, indexing="ij")
        x = np.stack([m.ravel() for m in mesh], axis=1)
        r = np.stack([1 + x[:, 3], 1 + x[:, 4], 1 - x[:, 3] - x[:, 4]], axis=1)
        l12 = np.exp(x[:, 0])
        l13 = r[:, 0] + r[:, 2] + x[:, 1]
        return r, np.stack([l12, l13, l13 - x[:, 2] * l12], axis=1)

    def needed(self):
        r"""Nodes (M,) bool, C order, of a cell that can hold a looked-up window: the lookup puts
        the pair's sphere nearer the third first, so :math:`\tau\, l_{12} \le r_1 - r_2`; a
        node whose lower tau neighbour exceeds that bound over its neighbouring cells is never
        a corner of a served cell, and is not solved (NaN in the table)."""
        ls, _, tau, rho, _ = self.axes
        i = np.indices(self.shape).reshape(5, -1)

        def lo(a, k):
            return a[np.maximum(k - 1, 0)]

        def hi(a, k):
            return a[np.minimum(k + 1, len(a) - 1)]

        dr = hi(rho, i[3]) - lo(rho, i[4])               # the largest r1 - r2 over the cells
        side = np.where(dr > 0, np.exp(lo(ls, i[0])), np.exp(hi(ls, i[0])))
        return lo(tau, i[2]) <= dr / side

    def solve_shapes(self):
        """The nodes :func:`cache.precompute_grid` solves: :meth:`needed` ones."""
        r, s = self.node_shapes()
        keep = self.needed()
        return r[keep], s[keep]

    def describe(self):
        """The box in words (``cache.table_coverage``)."""
        side = np.exp(self.log_side_nodes[[0, -1]])
        return (f"{self.name}: deep pairs of side {side[0]:.2g} to {side[1]:.2g}, third sphere's "
                f"gap {self.gap_nodes[0]:g} to {self.gap_nodes[-1]:g}, |tau| to "
                f"{self.tau_nodes[-1]:g}, radius deviations to {self.rho_nodes[-1]:g}")

    def __repr__(self):
        return f"PairSpec({self.name!r}, shape {self.shape})"


def pair_coordinates(radii, sides):
    """Coordinates (N, 5) of the module docstring and the rows with a deep pair (N,) bool;
    radii, sides (N, 3) float arrays in any order of the vertices and any length unit."""
    r = np.asarray(radii, dtype=float)
    s = np.asarray(sides, dtype=float)
    inv = 3.0 / (r[:, 0] + r[:, 1] + r[:, 2])
    rn = r * inv[:, None]
    sn = s * inv[:, None]
    # gaps of the pairs (0,1), (0,2), (1,2): side columns 0, 1, 2
    g = np.stack([sn[:, 0] - rn[:, 0] - rn[:, 1], sn[:, 1] - rn[:, 0] - rn[:, 2],
                  sn[:, 2] - rn[:, 1] - rn[:, 2]], axis=1)
    k = np.argmin(g, axis=1)                       # the pair's side column
    deep = g[np.arange(len(g)), k] < DEEP_GAP
    # per pair column: (vertex i, vertex j, third vertex, side i-third, side j-third)
    table = np.array([[0, 1, 2, 1, 2], [0, 2, 1, 0, 2], [1, 2, 0, 0, 1]])
    vi, vj, vk, si, sj = table[k].T
    n = np.arange(len(r))
    ri, rj, rk = rn[n, vi], rn[n, vj], rn[n, vk]
    l12, lik, ljk = sn[n, k], sn[n, si], sn[n, sj]
    gi, gj = lik - ri - rk, ljk - rj - rk
    swap = (gj < gi) | ((gj == gi) & (rj < ri))
    r1, r2 = np.where(swap, rj, ri), np.where(swap, ri, rj)
    l13, l23 = np.where(swap, ljk, lik), np.where(swap, lik, ljk)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.column_stack([np.log(l12), np.minimum(gi, gj), (l13 - l23) / l12,
                             r1 - 1.0, r2 - 1.0])
    return x, deep


def geometric_factor(radii, sides):
    r"""The shape factor's geometric part :math:`A^{*3}/P^{*2}` (units of r̄⁴: open area
    :math:`A^*` and no-slip perimeter :math:`P^*` in mean radii, ``docs/throats-shape-factor.md``)
    of throats (N, 3) in any order and length unit; 0 where the disks cover the triangle, NaN
    for a row that is not a triangle."""
    r = np.asarray(radii, dtype=float)
    s = np.asarray(sides, dtype=float)
    out = np.full(len(r), np.nan)
    ok = validate_throats(r, s)[0]
    if ok.any():
        inv = 3.0 / r[ok].sum(axis=1)
        area, per = open_area_perimeter(r[ok] * inv[:, None], s[ok] * inv[:, None])
        with np.errstate(invalid="ignore", divide="ignore"):
            out[ok] = np.where(area > 0, area**3 / per**2, 0.0)
    return out


class PairTable(GridTable):
    r""":class:`cache.GridTable` on a :class:`PairSpec`, read in the deep-pair coordinates
    (:func:`pair_coordinates`), of FE's Q* over the shape factor's geometric part:

    .. math:: Q^* = \frac{A^{*3}}{P^{*2}}(x)\; \exp I\Bigl[\ln \frac{Q^*_{FE}}
              {A^{*3}/P^{*2}}\Bigr](x),

    :math:`I` the table's interpolation (multilinear with the curvature correction) of the
    nodes' values (:func:`geometric_factor`). The geometric part carries the steep dependence on
    the sliver's width; the ratio left to the table is the shape factor's constant, smooth across
    the contact types and the deep-overlap threshold where the estimate's constants jump; at the
    nodes the answer is the FE value. A node FE finds closed (its open region narrower than the
    solver's closing width) takes the ratio of its open neighbours and its cells are served: the
    window's own open area decides. The error estimate (coarse sub-grid) is relative. A row
    without a deep pair is not served (error inf).

    ``qstar`` is the FE Q* at the nodes, as stored (NaN: invalid or not solved, 0: closed).
    """

    def __init__(self, spec, qstar, fe_error=None, **kwargs):
        self.fe_qstar = np.asarray(qstar, dtype=float).reshape(spec.shape)
        saved = None if kwargs.get("derived") is None else kwargs["derived"].get("geometric")
        g = (geometric_factor(*spec.node_shapes()) if saved is None
             else np.asarray(saved)).reshape(spec.shape)
        self.node_geometric = g
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where((self.fe_qstar > 0) & (g > 0), self.fe_qstar / g, np.nan)
        ratio[~((ratio < RATIO_MAX) & (ratio > 1.0 / RATIO_MAX))] = np.nan
        closed = self.fe_qstar == 0
        super().__init__(spec, ratio, fe_error, **kwargs)
        if kwargs.get("derived") is None:
            self.cell_ok = cell_all(self.node_ok | closed)
        self._uniform = [False, False, False, True, True]

    def derived(self):
        """:meth:`cache.GridTable.derived` with the nodes' geometric part (a whole-grid pass of
        exact open areas, kept with the other derived arrays)."""
        return dict(super().derived(), geometric=self.node_geometric)

    def coarse_spec(self):
        return self.spec.coarse()

    def kernel_arrays(self, snap=None):
        return None                                # the compiled kernel reads gap coordinates

    def at_throats(self, radii, sides, *, errors=True, chunk=None):
        """``(qstar (N,), rel_error (N,))`` of throats in any vertex order; rows without a deep
        pair get error inf."""
        x, deep = pair_coordinates(radii, sides)
        v, err = self(x, _log=True, errors=errors)
        err[~deep] = np.inf
        q = np.zeros(len(x))
        use = ~np.isinf(err)
        if use.any():
            with np.errstate(over="ignore"):
                q[use] = geometric_factor(np.asarray(radii)[use], np.asarray(sides)[use]) * np.exp(v[use])
        return q, err


def _nodes(lo, hi, step):
    return [round(lo + k * step, 10) for k in range(int(round((hi - lo) / step)) + 1)]


#: the shipped deep-pair grid (``cache/data/grid_p1.npz``, ``docs/cache-table.md``, "p1")
GRIDS["p1"] = PairSpec("p1", _nodes(-3.0, 1.0, 0.5),
                       [-0.2, -0.1, 0.0, 0.025, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0,
                        1.4, 1.8, 2.2, 2.6],
                       _nodes(-0.9, 0.9, 0.225), 0.2, 5)
