r"""Regular-grid interpolation of Q* over the 5-D shape space, with a per-cell error estimate.

Coordinates
-----------
A throat in its *given* vertex order, lengths scaled by :math:`\bar r`, is mapped to

.. math::
    x = (\delta_{12}, \delta_{13}, \delta_{23}, \rho_1, \rho_2), \qquad
    \delta_{ij} = \frac{l_{ij} - r_i - r_j}{\bar r}, \qquad \rho_i = \frac{r_i}{\bar r} - 1

(:math:`\rho_3 = -\rho_1-\rho_2`).  The gaps :math:`\delta_{ij}` are what Q* is most sensitive
to, and the contact type changes exactly at :math:`\delta_{ij} = 0`, where Q* has a kink: the
gap axis has a node at 0.  The grid (:mod:`cache._grids`) is the full box, with
the same node set on the three gap axes and a uniform, symmetric lattice
:math:`\rho \in h\,\mathbb{Z}` on the radius axes: a permutation of the vertices maps grid
nodes to grid nodes, so precomputation solves each distinct shape only once (about 1/6 of
the nodes); it does not map cells to cells, so a lookup reads each throat in one order
(:mod:`cache._order`).

Interpolated value and error estimate
-------------------------------------
The table interpolates :math:`v = \ln Q^*`: multilinearly over the 32 corners of the cell,
plus a curvature correction per direction (see :class:`GridTable`), which makes the
interpolant exact for every quadratic in :math:`x` and third-order accurate.  The error
estimate compares the grid with its own coarse sub-grid (every other node): at a fine node
:math:`D = |v - I_{2h} v|` is the coarse interpolant's error; a third-order interpolant's
error scales as :math:`h^3`, so a fine cell's error is estimated as

.. math:: e_\text{cell} = c_s \max_\text{corners} D / 8 + \max_\text{corners} e_\text{FE},

with safety factor :math:`c_s` and the solver's own error estimate at the corners.
:math:`c_s` is measured per grid (``CALIBRATED_SAFETY``: 0.85 for the shipped ``g1``, so that
the estimate covers the error against FE on 95 % or more of random-packing throats; history
and numbers in ``docs/cache-error-estimate.md``); an uncalibrated grid uses the conservative
``ERROR_SAFETY`` = 2.  Where the coarse sub-grid cannot judge a cell
(one of its coarse corners is invalid) the estimate is the size of the curvature correction.
Cells with a corner that is missing, invalid or closed (Q* = 0), and points outside the box,
get :math:`e = \infty` (never served from the table).  :math:`|\Delta \ln Q^*|` is the
relative error of Q*, so the estimate is relative.
"""

from __future__ import annotations

import logging

import numpy as np

from ._cells import cell_all, cell_max, cell_mean, fill_nan, second_difference
from ._grids import GridSpec
from ._order import lookup_order

logger = logging.getLogger(__name__)

__all__ = ["GridTable", "grid_coordinates", "ERROR_SAFETY", "CALIBRATED_SAFETY"]

#: points per chunk of a lookup (the 32 corner arrays of a chunk stay in cache)
CHUNK = 16384

#: a gap within this distance below a node (units of r̄) is served by the cell above the node
GAP_SNAP = 5e-3

#: safety factor on the coarse/fine difference for grids without a calibration (conservative:
#: on g1 it covered 100 % of 2400 packing throats and sent 99 % of them to FE at rtol 1e-3)
ERROR_SAFETY = 2.0

#: safety factor per grid name (curvature-corrected tables), against FE (rtol 1e-4): g1 on
#: network.sample_throats(1600, rng=2026), covers 98.5 % (98.1 % of 800 others, rng=99); x1 on
#: clump beds and 1-6 mm spheres, >= 95.1 % of each (checked: 96.6 %; d1: none covers 95 %)
CALIBRATED_SAFETY = {"g1": 0.85, "x1": 1.07}


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


class GridTable:
    r"""Interpolation table on a :class:`GridSpec`: values, per-cell errors, vectorised lookup.

    The interpolant is multilinear in :math:`v = \ln Q^*` plus a per-cell curvature
    correction in each direction,

    .. math:: v(x) = \sum_{c \in \{0,1\}^5} w_c(t)\, v_c \;-\;
              \sum_{d=1}^{5} \tfrac12 t_d (1 - t_d) H_d^2 \bar v''_d,

    where :math:`t_d \in [0, 1]` is the position in the cell of width :math:`H_d` and
    :math:`\bar v''_d` the mean over the cell's 32 corners of the second difference of
    :math:`v` along d.  It is exact for multilinear functions and for separable quadratics
    and costs 38 gathers per point (32 corners, 5 curvatures, 1 error).

    Parameters
    ----------
    spec : GridSpec
    qstar : ndarray of ``spec.shape``
        Q* at the nodes (NaN where missing/failed/invalid, 0 where closed).
    fe_error : ndarray of ``spec.shape``, optional
        Relative error estimate of the solver at the nodes.
    safety : float, keyword-only
        Default: ``CALIBRATED_SAFETY[spec.name]`` for a curvature-corrected table of a
        calibrated grid, else :data:`ERROR_SAFETY`.
    curvature : bool, keyword-only, default True
        Apply the curvature correction (False: plain multilinear).
    estimate : bool, keyword-only, default True
        Compute the per-cell error estimate from the coarse sub-grid (needs odd node counts).
    derived : dict, keyword-only, optional
        :meth:`derived` of a table built from the same ``spec``, ``qstar`` and ``curvature``
        by this code (a saved copy, :func:`cache.load_grid_table`): taken instead of
        recomputing the filled values, curvature coefficients and served cells.
    """

    single = True      # False: gathers from the float64 arrays, no float32 copies (few rows)

    def __init__(self, spec, qstar, fe_error=None, *, safety=None, curvature=True,
                 estimate=True, derived=None):
        if safety is None:
            safety = CALIBRATED_SAFETY.get(spec.name, ERROR_SAFETY) if curvature else ERROR_SAFETY
        self.spec = spec
        self.safety = float(safety)
        shape = spec.shape
        self.qstar = np.asarray(qstar, dtype=float).reshape(shape)
        self._fe_given = fe_error
        self._fe = self._log_q = None      # whole-grid passes a lookup without errors never needs
        self.values = (fill_nan(self._node_log()[1]) if derived is None
                       else derived["values"].reshape(shape))
        self._axes = [np.ascontiguousarray(a) for a in spec.axes]
        self._strides = np.array([int(np.prod(shape[d + 1:])) for d in range(5)], dtype=np.int64)
        self._uniform = [False, False, False, True, True]
        self.curvature = bool(curvature)
        # per-cell curvature coefficients k_d = H_d^2 * mean(v''_d) / 2, stored at the lower node
        self._k = []
        for d in range(5):
            if shape[d] < 3 or derived is not None:
                self._k.append(None if shape[d] < 3 else derived[f"k{d}"])
                continue
            h = np.diff(self._axes[d])
            d2 = second_difference(self.values, self._axes[d], d)
            kd = cell_mean(d2)
            hh = np.append(h, h[-1]) ** 2
            kd *= 0.5 * hh.reshape([-1 if k == d else 1 for k in range(5)])
            self._k.append(np.ascontiguousarray(kd.ravel()))
        # the per-cell error estimate is built on first use (:attr:`cell_error`): a lookup that
        # needs only which cells serve (``errors=False``) skips it (0.1-0.2 s on g1)
        self._estimate = bool(estimate)
        self.cell_ok = (cell_all(self.node_ok) if derived is None
                        else derived["cell_ok"].reshape(shape))
        self._cell_error = None
        self._flat_values = np.ascontiguousarray(self.values.ravel())

    def _node_log(self):
        """(node_ok, ln Q* with NaN at the invalid nodes), computed on the first call."""
        if self._log_q is None:
            q = self.qstar
            good = np.isfinite(q) & (q > 0)
            with np.errstate(divide="ignore", invalid="ignore"):
                self._log_q = (good, np.where(good, np.log(np.where(good, q, 1.0)), np.nan))
        return self._log_q

    @property
    def node_ok(self):
        """Nodes with a finite positive Q* (bool, ``spec.shape``)."""
        return self._node_log()[0]

    @property
    def fe_error(self):
        """|relative FE error| at the nodes (0 where unknown), ``spec.shape``."""
        if self._fe is None:
            given = np.zeros(self.spec.shape) if self._fe_given is None else self._fe_given
            fe = np.asarray(given, float).reshape(self.spec.shape)
            self._fe = np.where(np.isfinite(fe), np.abs(fe), 0.0)
        return self._fe

    def derived(self):
        """The arrays a lookup needs that cost a whole-grid pass to make (``derived=``)."""
        out = {"values": self.values, "cell_ok": self.cell_ok}
        out.update({f"k{d}": k for d, k in enumerate(self._k) if k is not None})
        return out

    @property
    def cell_error(self):
        """Relative error estimate per cell, stored at its lower node (inf: never served)."""
        if self._cell_error is None:
            self._build_error()
        return self._cell_error

    @property
    def estimated(self):
        """Cells whose estimate comes from the coarse sub-grid (else the curvature size)."""
        if self._cell_error is None:
            self._build_error()
        return self._estimated

    def _build_error(self):
        shape = self.spec.shape
        # fallback estimate where the coarse sub-grid cannot judge a cell: the largest size of
        # the curvature correction, sum_d |k_d| / 4 (what plain multilinear would miss)
        k_size = np.zeros(shape)
        for d in range(5):
            if self._k[d] is not None:
                k_size += np.abs(self._k[d].reshape(shape)) / 4
        self._estimated = np.zeros(shape, dtype=bool)
        if self._estimate:
            dnode = self._coarse_difference(self._node_log()[1])
            # third order when the coarse sub-grid has its curvature terms in every direction
            # (>= 3 nodes); else it is partly multilinear and its error shrinks only as h^2
            cs = self.coarse_spec().shape
            third = self.curvature and all(c >= 3 for c, f in zip(cs, shape) if f > 1)
            order = 3.0 if third else 2.0
            e_cell = (self.safety * cell_max(np.where(np.isfinite(dnode), dnode, np.inf))
                      / 2**order)
            self._estimated = np.isfinite(e_cell)
            e_cell = np.where(self._estimated, e_cell, k_size) + cell_max(self.fe_error)
        else:
            e_cell = k_size + cell_max(self.fe_error)
        e_cell[~self.cell_ok] = np.inf
        self._cell_error = e_cell

    @property
    def coverage(self):
        """Fraction of cells with a finite error estimate."""
        inner = self.cell_error[tuple(slice(0, max(n - 1, 1)) for n in self.spec.shape)]
        return float(np.isfinite(inner).mean())

    def coarse_spec(self):
        s = self.spec
        return GridSpec(s.name + "/2", s.gap_nodes[::2], 2 * s.rho_step, (s.rho_count + 1) // 2,
                        _sub=True)

    def _coarse_difference(self, v):
        """|v - I_2h v| at every fine node (0 on the coarse nodes; NaN near invalid nodes)."""
        cs = self.coarse_spec()
        sub = tuple(slice(None, None, 2) for _ in range(5))
        coarse = GridTable(cs, np.exp(v[sub]), curvature=self.curvature, estimate=False)
        x = np.stack([m.ravel() for m in np.meshgrid(*self._axes, indexing="ij")], axis=1)
        ic, ec = coarse(x, _log=True)
        ic[~np.isfinite(ec)] = np.nan
        return np.abs(v.ravel() - ic).reshape(v.shape)

    def __call__(self, x, _log=False, chunk=CHUNK, *, errors=True):
        """Interpolate at points ``x`` (N, 5): returns ``(qstar (N,), rel_error (N,))``.

        Points outside the grid box get ``rel_error = inf`` (value from the clamped cell).
        Work is done in chunks of ``chunk`` points so that temporaries stay in cache.
        ``errors=False``: ``rel_error`` is NaN (not estimated) where the table serves the
        point and inf where it does not, without building the per-cell estimate.
        """
        x = np.asarray(x, dtype=float)
        return self._chunks(len(x), lambda lo, hi: [x[lo:hi, d] for d in range(5)], _log,
                            chunk, errors)

    def at_throats(self, radii, sides, *, errors=True, chunk=CHUNK):
        """``self(grid_coordinates(*lookup_order(radii, sides)))`` (one answer for every vertex
        order), both made chunk by chunk; radii, sides (N, 3) float arrays."""
        def cols(lo, hi):
            r, s = lookup_order(radii[lo:hi], sides[lo:hi])
            r0, r1, r2 = r[:, 0], r[:, 1], r[:, 2]
            inv = 1.0 / ((r0 + r1 + r2) * (1.0 / 3.0))
            return [(s[:, 0] - r0 - r1) * inv, (s[:, 1] - r0 - r2) * inv,
                    (s[:, 2] - r1 - r2) * inv, r0 * inv - 1.0, r1 * inv - 1.0]
        return self._chunks(len(radii), cols, False, chunk, errors)

    def _chunks(self, n, cols, _log, chunk, errors):
        v = np.empty(n)
        err = np.empty(n)
        for lo in range(0, n, chunk):
            hi = min(lo + chunk, n)
            v[lo:hi], err[lo:hi] = self._eval(cols(lo, hi), errors)
        if _log:
            return v, err
        # only the clamped extrapolation outside the box (rel_error = inf) can overflow
        with np.errstate(over="ignore"):
            return np.exp(v, out=v), err

    def _prepare(self):
        """float32 copies (``single``) or the float64 arrays, and offset views (on first use)."""
        if getattr(self, "_f32", None) is not None:
            return
        vals = self._flat_values.astype(np.float32 if self.single else np.float64, copy=False)
        dims = [d for d in range(5) if len(self._axes[d]) > 1]
        offsets = [0]
        for d in dims:
            offsets = [o + b * int(self._strides[d]) for o in offsets for b in (0, 1)]
        # vals[o:] is a view: take(base) from it gathers v[base + o] without an index array
        self._f32 = {"views": [vals[o:] for o in offsets], "dims": dims,
                     "k": [None if (k is None or not self.curvature) else k.astype(vals.dtype, copy=False)
                           for k in self._k],
                     "ok": self.cell_ok.ravel(), "err": None}

    def kernel_arrays(self, snap=GAP_SNAP):
        """The arguments after the throat of :func:`cache.point_kernel`'s function: gap axis,
        radius axis (first, last, 1/step, count), strides, float32 values, and per node its
        five float32 curvatures and whether its cell is served (one row, (n, 6), one cache
        line per lookup); None for a grid the kernel cannot take (a one-node axis)."""
        if any(len(a) < 2 for a in self._axes) or not self.single:
            return None
        rho = self._axes[3]
        if not np.array_equal(rho, self._axes[4]) or not all(self._uniform[3:]):
            return None
        if getattr(self, "_kernel", None) is None:
            self._prepare()
            f = self._f32
            curv = np.zeros((f["views"][0].size, 6), dtype=np.float32)
            for d, k in enumerate(f["k"]):
                if k is not None:
                    curv[:, d] = k
            curv[:, 5] = f["ok"]
            self._kernel = (self._axes[0], float(rho[0]), float(rho[-1]),
                            1.0 / (rho[1] - rho[0]), len(rho), self._strides, f["views"][0], curv)
        return self._kernel + (float(snap),)

    def _eval(self, x, errors=True):
        """ln Q* and error of one chunk; ``x`` the 5 coordinate columns, each (n,)."""
        self._prepare()
        f = self._f32
        n = len(x[0])
        base = np.zeros(n, dtype=np.int64)
        t = {}
        outside = np.zeros(n, dtype=bool)
        for d in range(5):
            a = self._axes[d]
            xd = x[d]
            if len(a) == 1:
                outside |= xd != a[0]
                continue
            if self._uniform[d]:
                fd = (xd - a[0]) * (1.0 / (a[1] - a[0]))
                i = np.floor(fd)
                np.clip(i, 0, len(a) - 2, out=i)
                td = fd - i
                i = i.astype(np.int64)
            else:
                # just below a node (x = -1e-3): the cell above it, extrapolating <= GAP_SNAP
                i = np.searchsorted(a, xd + GAP_SNAP, side="right") - 1
                np.clip(i, 0, len(a) - 2, out=i)
                lo = a[i]
                td = (xd - lo) / (a[i + 1] - lo)
            outside |= (xd < a[0] - 1e-9) | (xd > a[-1] + 1e-9)
            t[d] = td.astype(f["views"][0].dtype)
            if self._strides[d] != 1:
                i *= self._strides[d]
            base += i
        # gather the 2^k corners, then reduce one dimension at a time by linear blending
        vals = [view.take(base) for view in f["views"]]
        for d in reversed(f["dims"]):
            td = t[d]
            for a, b in zip(vals[0::2], vals[1::2]):      # b <- a + td (b - a), in place
                np.subtract(b, a, out=b)
                np.multiply(td, b, out=b)
                np.add(a, b, out=b)
            vals = vals[1::2]
        v = vals[0].astype(np.float64)
        for d in f["dims"]:
            k = f["k"][d]
            if k is not None:
                v -= t[d] * (1.0 - t[d]) * k.take(base)
        if not errors:
            return v, np.where(f["ok"].take(base) & ~outside, np.nan, np.inf)
        if f["err"] is None:
            f["err"] = np.ascontiguousarray(self.cell_error.ravel()).astype(np.float32)
        err = f["err"].take(base).astype(np.float64)
        err[outside] = np.inf
        return v, err
