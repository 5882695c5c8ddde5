r"""Regular-grid interpolation of Q* over the 5-D shape space, with a per-cell error estimate.

Coordinates
-----------
A throat in its *given* vertex order, lengths scaled by :math:`\bar r`, is mapped to

.. math::
    x = (\delta_{12}, \delta_{13}, \delta_{23}, \rho_1, \rho_2), \qquad
    \delta_{ij} = \frac{l_{ij} - r_i - r_j}{\bar r}, \qquad \rho_i = \frac{r_i}{\bar r} - 1

(:math:`\rho_3 = -\rho_1-\rho_2`).  The gaps :math:`\delta_{ij}` are what Q* is most sensitive
to, and the contact type changes exactly at :math:`\delta_{ij} = 0`, where Q* has a kink: the
gap axis has a node at 0, nodes close together near 0 (contacts and small overlaps are what
dense packings are made of) and wider apart at large gaps.  The grid is the full box, with
the same node set on the three gap axes and a uniform, symmetric lattice
:math:`\rho \in h\,\mathbb{Z}` on the radius axes: a permutation of the vertices maps grid
nodes to grid nodes, so no canonical reordering is needed at lookup time (one multilinear
evaluation on the raw order) while precomputation solves each distinct shape only once
(deduplicated by signature, about 1/6 of the nodes).

Interpolated value and error estimate
-------------------------------------
The table interpolates :math:`v = \ln Q^*` multilinearly (32 corners).  The error estimate
compares the grid with its own coarse sub-grid (every other node): at a fine node
:math:`D = |v - I_{2h} v|` is the coarse interpolant's error, and a multilinear interpolant's
error scales as :math:`h^2`, so a fine cell's error is estimated as

.. math:: e_\text{cell} = c_s \max_\text{corners} D / 4 + \max_\text{corners} e_\text{FE},

with safety factor :math:`c_s` (``ERROR_SAFETY``) calibrated on held-out FE solves, plus the
solver's own error estimate at the corners.  Cells with a corner that is missing, invalid or
closed (Q* = 0) get :math:`e = \infty`: the lookup never serves them from the table.
Because :math:`|\Delta \ln Q^*|` is the relative error of Q*, the estimate is relative.
"""

from __future__ import annotations

import itertools
import logging

import numpy as np

logger = logging.getLogger(__name__)

__all__ = ["GridSpec", "GridTable", "grid_coordinates", "GRIDS", "ERROR_SAFETY"]

#: safety factor on the coarse/fine difference (calibrated: see tests and cache.bench)
ERROR_SAFETY = 2.0


def grid_coordinates(radii, sides):
    """Interpolation coordinates (N, 5) ``[d12, d13, d23, rho1, rho2]`` of throats in given order."""
    r = np.asarray(radii, dtype=float)
    s = np.asarray(sides, dtype=float)
    rbar = (r[:, 0] + r[:, 1] + r[:, 2]) * (1.0 / 3.0)
    inv = 1.0 / rbar
    x = np.empty((len(r), 5))
    x[:, 0] = (s[:, 0] - r[:, 0] - r[:, 1]) * inv
    x[:, 1] = (s[:, 1] - r[:, 0] - r[:, 2]) * inv
    x[:, 2] = (s[:, 2] - r[:, 1] - r[:, 2]) * inv
    x[:, 3] = r[:, 0] * inv - 1.0
    x[:, 4] = r[:, 1] * inv - 1.0
    return x


class GridSpec:
    """Definition of a grid: gap nodes (shared by the 3 gap axes) and the radius lattice.

    Parameters
    ----------
    name : str
    gap_nodes : sequence of float
        Increasing, odd count, must contain 0 (units of r̄).
    rho_step : float
        Spacing h of the radius-deviation lattice.
    rho_count : int
        Odd number of nodes per radius axis, centred on 0: ``h * (arange(n) - n // 2)``.
    """

    def __init__(self, name, gap_nodes, rho_step, rho_count):
        g = np.asarray(gap_nodes, dtype=float)
        if g.ndim != 1 or len(g) < 3 or len(g) % 2 == 0 or np.any(np.diff(g) <= 0):
            raise ValueError(f"gap_nodes must be increasing with an odd count >= 3, got {g}")
        if not np.any(g == 0.0):
            raise ValueError("gap_nodes must contain 0 (the contact-type kink)")
        if rho_count < 1 or rho_count % 2 == 0 or not rho_step > 0:
            raise ValueError(f"rho_count must be odd >= 1 and rho_step > 0, got {rho_count}, {rho_step}")
        self.name = str(name)
        self.gap_nodes = g
        self.rho_step = float(rho_step)
        self.rho_count = int(rho_count)

    @property
    def rho_nodes(self):
        return self.rho_step * (np.arange(self.rho_count) - self.rho_count // 2)

    @property
    def axes(self):
        g, p = self.gap_nodes, self.rho_nodes
        return [g, g, g, p, p]

    @property
    def shape(self):
        return tuple(len(a) for a in self.axes)

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


def _gap_nodes(neg, pos):
    return sorted(set([-v for v in neg] + [0.0] + list(pos)))


#: named grids for ``python -m cache.precompute --grid NAME``
GRIDS = {
    # a few hundred distinct shapes: tests and smoke runs
    "tiny": GridSpec("tiny", [-0.05, 0.0, 0.1, 0.3, 0.6], 0.15, 3),
    # coarse production grid: range of random packings with radius ratios up to 1.5
    "coarse": GridSpec("coarse", _gap_nodes([0.08, 0.04],
                                            [0.02, 0.05, 0.1, 0.17, 0.27, 0.4, 0.57, 0.78,
                                             1.03, 1.33, 1.7, 2.2]),
                       0.125, 5),
}


class GridTable:
    """Interpolation table on a :class:`GridSpec`: values, per-cell errors, vectorised lookup.

    Parameters
    ----------
    spec : GridSpec
    qstar : ndarray of ``spec.shape``
        Q* at the nodes (NaN where missing/failed/invalid, 0 where closed).
    fe_error : ndarray of ``spec.shape``, optional
        Relative error estimate of the solver at the nodes.
    safety : float, keyword-only
        :data:`ERROR_SAFETY` by default.
    """

    def __init__(self, spec, qstar, fe_error=None, *, safety=ERROR_SAFETY):
        self.spec = spec
        q = np.asarray(qstar, dtype=float).reshape(spec.shape)
        self.qstar = q
        good = np.isfinite(q) & (q > 0)
        self.node_ok = good
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.where(good, np.log(np.where(good, q, 1.0)), np.nan)
        self.values = _fill_nan(v)
        fe = np.zeros(spec.shape) if fe_error is None else np.asarray(fe_error, float).reshape(spec.shape)
        fe = np.where(np.isfinite(fe), np.abs(fe), 0.0)
        self.fe_error = fe
        self._axes = [np.ascontiguousarray(a) for a in spec.axes]
        self._strides = np.array([int(np.prod(spec.shape[d + 1:])) for d in range(5)], dtype=np.int64)
        d = self._coarse_difference(v)
        e_cell = safety * _cell_max(np.where(np.isfinite(d), d, np.inf)) / 4.0 + _cell_max(fe)
        e_cell[~_cell_all(good)] = np.inf
        self.cell_error = e_cell
        self._flat_values = np.ascontiguousarray(self.values.ravel())
        self._flat_error = np.ascontiguousarray(e_cell.ravel())
        self._offsets = np.array([sum(b * self._strides[k] for k, b in enumerate(bits))
                                  for bits in itertools.product((0, 1), repeat=5)], dtype=np.int64)
        self._uniform = [False, False, False, True, True]

    @property
    def coverage(self):
        """Fraction of cells with a finite error estimate."""
        inner = self.cell_error[tuple(slice(0, n - 1) for n in self.spec.shape)]
        return float(np.isfinite(inner).mean())

    def _coarse_difference(self, v):
        """|v - I_2h v| at every fine node (0 on the coarse nodes)."""
        sub = tuple(slice(None, None, 2) for _ in range(5))
        coarse_axes = [a[::2] for a in self._axes]
        vc = v[sub]
        x = np.stack([m.ravel() for m in np.meshgrid(*self._axes, indexing="ij")], axis=1)
        ic = _multilinear(coarse_axes, vc, x)
        return np.abs(v.ravel() - ic).reshape(v.shape)

    def __call__(self, x):
        """Interpolate at points ``x`` (N, 5): returns ``(qstar (N,), rel_error (N,))``.

        Points outside the grid box get ``rel_error = inf`` (value from the clamped cell).
        """
        x = np.asarray(x, dtype=float)
        n = len(x)
        base = np.zeros(n, dtype=np.int64)
        t = np.empty((5, n))
        outside = np.zeros(n, dtype=bool)
        for d in range(5):
            a = self._axes[d]
            xd = x[:, d]
            if len(a) == 1:
                t[d] = 0.0
                outside |= xd != a[0]
                continue
            if self._uniform[d]:
                h = a[1] - a[0]
                f = (xd - a[0]) * (1.0 / h)
                i = np.floor(f)
                np.clip(i, 0, len(a) - 2, out=i)
                i = i.astype(np.int64)
                td = f - i
            else:
                i = np.searchsorted(a, xd, side="right") - 1
                np.clip(i, 0, len(a) - 2, out=i)
                lo = a[i]
                td = (xd - lo) / (a[i + 1] - lo)
            outside |= (td < -1e-12) | (td > 1 + 1e-12)
            t[d] = td
            base += i * self._strides[d]
        vals = self._flat_values
        # weights of the 32 corners by successive doubling over the 5 dimensions
        weights = [np.ones(n)]
        offsets = [0]
        for d in range(5):
            if len(self._axes[d]) == 1:
                continue
            td, sd = t[d], self._strides[d]
            new_w, new_o = [], []
            for w, o in zip(weights, offsets):
                new_w += [w * (1.0 - td), w * td]
                new_o += [o, o + sd]
            weights, offsets = new_w, new_o
        v = np.zeros(n)
        for w, o in zip(weights, offsets):
            v += w * vals.take(base + o)
        err = self._flat_error.take(base)
        err[outside] = np.inf
        return np.exp(v), err


def _cell_max(a):
    """Max over the 2^5 corners of each cell, stored at the cell's lower node (same shape as a)."""
    out = a.copy()
    for d in range(a.ndim):
        if a.shape[d] == 1:
            continue
        sl_lo = [slice(None)] * a.ndim
        sl_hi = [slice(None)] * a.ndim
        sl_lo[d] = slice(0, -1)
        sl_hi[d] = slice(1, None)
        out[tuple(sl_lo)] = np.maximum(out[tuple(sl_lo)], out[tuple(sl_hi)])
    return out


def _cell_all(mask):
    """True where all corners of the cell at that lower node are True (last layers: False)."""
    out = mask.copy()
    for d in range(mask.ndim):
        if mask.shape[d] == 1:
            continue
        sl_lo = [slice(None)] * mask.ndim
        sl_hi = [slice(None)] * mask.ndim
        sl_lo[d] = slice(0, -1)
        sl_hi[d] = slice(1, None)
        out[tuple(sl_lo)] &= out[tuple(sl_hi)]
        last = [slice(None)] * mask.ndim
        last[d] = -1
        out[tuple(last)] = False
    return out


def _fill_nan(v, max_sweeps=50):
    """Replace NaN nodes by the mean of finite axis neighbours, sweep by sweep (keeps lookups finite)."""
    v = v.copy()
    for _ in range(max_sweeps):
        bad = ~np.isfinite(v)
        if not bad.any():
            break
        acc = np.zeros_like(v)
        cnt = np.zeros_like(v)
        for d in range(v.ndim):
            if v.shape[d] == 1:
                continue
            for shift in (1, -1):
                nb = np.roll(v, shift, axis=d)
                edge = [slice(None)] * v.ndim
                edge[d] = 0 if shift == 1 else -1
                nb[tuple(edge)] = np.nan
                ok = np.isfinite(nb)
                acc[ok] += nb[ok]
                cnt[ok] += 1
        fill = bad & (cnt > 0)
        v[fill] = acc[fill] / cnt[fill]
    v[~np.isfinite(v)] = 0.0
    return v


def _multilinear(axes, values, x):
    """Plain multilinear interpolation (clamped), used for the coarse sub-grid."""
    n = len(x)
    idx = []
    ts = []
    for d, a in enumerate(axes):
        if len(a) == 1:
            idx.append(np.zeros(n, dtype=np.int64))
            ts.append(np.zeros(n))
            continue
        i = np.clip(np.searchsorted(a, x[:, d], side="right") - 1, 0, len(a) - 2)
        idx.append(i)
        ts.append((x[:, d] - a[i]) / (a[i + 1] - a[i]))
    out = np.zeros(n)
    for bits in itertools.product((0, 1), repeat=len(axes)):
        if any(b and len(a) == 1 for b, a in zip(bits, axes)):
            continue
        w = np.ones(n)
        ii = []
        for d, b in enumerate(bits):
            w = w * (ts[d] if b else 1.0 - ts[d])
            ii.append(idx[d] + b)
        out += w * values[tuple(ii)]
    return out
