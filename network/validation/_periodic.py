r"""Permeability of the network model on a periodic packing: no sample boundary at all.

A sample cut from a packing has boundaries: conduits cut on its lateral faces, pressures fixed
on inlet and outlet pores. Their effect on the estimate is what :func:`periodic_permeability`
removes. The periodic cell of side :math:`L` is copied 3 x 3 x 3 and tessellated; the pore bodies
of the middle copy are the unknowns, every other body is the image of one of them shifted by
:math:`\mathbf s L` (:math:`\mathbf s` integer), and a mean gradient :math:`G` along the axis
enters as a jump :math:`p(\mathbf x + \mathbf s L) = p(\mathbf x) - G s_a L`. Mass balance in
every body, :math:`\sum_j g_{ij}(p_j - G s_{ij,a} L - p_i) = 0`, is solved (one pressure fixed),
and the mean flux density :math:`U = L^{-3}\sum_{ij} q_{ij}\,(x_j + s_{ij} L - x_i)_a` over the
throats of the cell gives :math:`k = \mu U / G`. This is the network model's own permeability of
the packing, the reference for the sample estimators (``docs/sample-boundary.md``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .._deferred import sparse_linalg, spatial
from ..conductance import throat_conductance
from ..packing import Packing, periodic_copies
from ..pores import axis_index, body_centroids, merge_pores, tessellate

__all__ = ["periodic_permeability"]


def periodic_permeability(packing: Packing, side: float, *, axes=("x", "y", "z"),
                          model: str = "conduit", policy: str = "table-only",
                          qstar_fn=None) -> dict:
    """Network-model permeability (viscosity 1, units of the packing squared) of a periodic cell.

    Parameters
    ----------
    packing : Packing
        Spheres of one periodic cube of side ``side`` (centres are wrapped into it).
    side : float
        Period, same unit as the packing.
    axes : iterable of {'x', 'y', 'z'} or int
        Directions of the mean gradient.
    model, policy, qstar_fn
        Conductance model and Q* source, as :func:`network.solve_network`.

    Returns
    -------
    dict
        ``{axis letter: k}``.

    Examples
    --------
    A simple cubic array, one sphere in the cell, is its own periodic packing:

    >>> from network.packing import Packing
    >>> k = periodic_permeability(Packing([[0.5, 0.5, 0.5]] * 1, [0.4]), 1.0, axes="x",
    ...                           policy="shape-factor")
    >>> k["x"] > 0
    True
    """
    L = float(side)
    big = periodic_copies(packing, L, 3)
    t = tessellate(big)
    pm = merge_pores(t)
    lab = np.asarray(pm.labels)
    xyz = body_centroids(t, lab)
    mid = np.all((xyz >= L) & (xyz < 2 * L), axis=1)
    cell = np.flatnonzero(mid)
    near, j = spatial.cKDTree(np.mod(xyz[cell], L), boxsize=L).query(np.mod(xyz, L))
    image = cell[j]
    shift = np.round((xyz - xyz[image]) / L).astype(np.int64)
    # throats between two bodies with one in the cell, each periodic throat once
    tp = t.throat_pores
    inner = tp[:, 1] >= 0
    a = lab[tp[:, 0]]
    b = np.where(inner, lab[np.maximum(tp[:, 1], 0)], -1)
    keep = np.flatnonzero(inner & (a != b) & (mid[a] | mid[np.maximum(b, 0)]))
    g = throat_conductance(t, keep, model=model, policy=policy, viscosity_pa_s=1.0,
                           qstar_fn=qstar_fn,
                           **({"merge": pm} if model == "conduit" else {})).g
    A, B = a[keep], b[keep]
    swap = ~mid[A]
    A, B = np.where(swap, B, A), np.where(swap, A, B)            # A in the cell
    ia = np.searchsorted(cell, A)
    jb = np.searchsorted(cell, image[B])
    s = shift[B] - shift[A]
    # one periodic throat can appear several times (images on the cell's faces): identify it
    # by its three spheres, (base sphere, copy offset) sorted, offsets taken from the first
    n = packing.n
    v = t.throat_vertices[keep]
    base, copy = v % n, v // n
    off = np.stack([copy // 9, (copy // 3) % 3, copy % 3], axis=-1)          # (M, 3, 3)
    rank = np.lexsort((off[..., 2], off[..., 1], off[..., 0], base), axis=-1)
    base = np.take_along_axis(base, rank, axis=1)
    off = np.take_along_axis(off, rank[..., None], axis=1)
    key = np.column_stack([base, (off[:, 1:] - off[:, :1]).reshape(-1, 6)])
    _, first = np.unique(key, axis=0, return_index=True)
    ia, jb, s, g = ia[first], jb[first], s[first], g[first]
    m = cell.size
    lap = sp.coo_array((np.concatenate([-g, -g]), (np.concatenate([ia, jb]),
                                                    np.concatenate([jb, ia]))), shape=(m, m))
    lap = (lap + sp.diags_array(np.bincount(ia, g, m) + np.bincount(jb, g, m))).tolil()
    lap[0, :] = 0.0
    lap[0, 0] = 1.0
    lap = sp.csc_matrix(lap)
    out = {}
    for ax in axes:
        k = axis_index(ax)
        jump = -s[:, k] * L                                       # G = 1
        rhs = np.bincount(ia, g * jump, m) - np.bincount(jb, g * jump, m)
        rhs[0] = 0.0
        p = sparse_linalg.spsolve(lap, rhs)
        q = g * (p[ia] - p[jb] - jump)
        dx = (xyz[cell[jb]] + s * L - xyz[cell[ia]])[:, k]
        out["xyz"[k]] = float(np.sum(q * dx) / L**3)
    return out
