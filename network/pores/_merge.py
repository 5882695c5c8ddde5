r"""Merging co-spherical Delaunay tetrahedra into one pore body.

Why
---
Where more than four sphere centres lie on one empty sphere (the 8 corners of a simple-cubic
cell, the 6 vertices of an FCC octahedral hole, near-regular spots of real packings) the
Delaunay tessellation is not unique: Qhull splits the group into tetrahedra in one of several
valid ways, and each way adds different internal "throats" — faces through the middle of one
void — that carry a spurious resistance and make the answer depend on how the tie was broken.
Those tetrahedra are one pore body; this module finds them and labels them as one group.

Criterion
---------
Two tetrahedra *p*, *q* sharing a face are merged when each one's fourth vertex lies on the
other's circumsphere to a relative tolerance :math:`\tau`:

.. math:: \bigl|\, |\mathbf v_q - \mathbf c_p| - R_p \bigr| \le \tau R_p
          \quad\text{and}\quad
          \bigl|\, |\mathbf v_p - \mathbf c_q| - R_q \bigr| \le \tau R_q ,

with :math:`\mathbf c, R` circumcentre and circumradius and :math:`\mathbf v_q` the vertex of
*q* not on the shared face. Exactly co-spherical groups give 0 (to round-off); a Gaussian
jitter of standard deviation :math:`\sigma` moves the left side by a few :math:`\sigma`, so the
default :math:`\tau` = 0.02 merges lattices jittered by 0.1-0.3 % of the lattice constant
completely. Slivers and near-slivers (radius ratio :math:`3r_{in}/R` below ``min_quality``) are
never merged on this test, because their circumsphere is ill-defined or huge and would chain
unrelated voids together. A flat sliver (radius ratio below
``flat_quality``) instead joins the one neighbour across its largest face (a non-flat one when
it has any), as in ``network.tie_groups``: joining both sides would fuse two voids. (Left alone a
sliver would do little harm in the conduit model, whose conduit lengths are measured from pore
centres and are ~0 inside a sliver, but it would be an extra pore of the sample.) Groups are
the connected components of the merge graph
(union-find through ``scipy.sparse.csgraph.connected_components``).

Each group's centre is the mean of the distinct sphere centres of its non-sliver tetrahedra
(the cube centre, the octahedron centre; for a single tetrahedron its centroid).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
import scipy.sparse as sp

from .._deferred import csgraph
from ._simplex import circumcentres, column_norm, pair_distances

__all__ = ["PoreMerge", "merge_pores", "circumspheres"]

logger = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class PoreMerge:
    """Pore bodies made of one or more tetrahedra.

    Attributes
    ----------
    labels : (Np,) int ndarray
        Group (pore body) of every tetrahedron, 0 .. n_groups-1.
    n_groups : int
    group_size : (Ng,) int ndarray
        Tetrahedra per group.
    center : (Ng, 3) ndarray, m
        Mean of the group's distinct sphere centres.
    internal_throat : (Nt,) bool ndarray
        Interior throat whose two tetrahedra are in the same group (no resistance).
    tolerance : float
        The relative co-sphericity tolerance used.
    """

    labels: np.ndarray
    n_groups: int
    group_size: np.ndarray
    center: np.ndarray
    internal_throat: np.ndarray
    tolerance: float

    @property
    def n_merged(self) -> int:
        """Tetrahedra that belong to a group of two or more."""
        return int(self.group_size[self.group_size > 1].sum())


def circumspheres(points):
    r"""Circumcentres and circumradii of tetrahedra, given as (N, 4, 3) vertex coordinates.

    Solves :math:`2(\mathbf v_i - \mathbf v_0)\cdot \mathbf c' = |\mathbf v_i - \mathbf v_0|^2`
    for :math:`\mathbf c' = \mathbf c - \mathbf v_0` by Cramer's rule
    (:func:`network.pores._simplex.circumcentres`). Flat tetrahedra (:math:`|D| \le 10^{-12}`
    of the mean squared edge to the power 3/2) give NaN.

    Returns
    -------
    center : (N, 3) ndarray
    radius : (N,) ndarray

    Examples
    --------
    >>> c, r = circumspheres(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]], float))
    >>> c.round(6).tolist(), round(float(r[0]) ** 2, 6)
    ([[0.5, 0.5, 0.5]], 0.75)
    """
    p = np.asarray(points, dtype=float)
    c, _ = circumcentres(p.reshape(-1, 3), np.arange(4 * p.shape[0]).reshape(-1, 4),
                         flat_tol=1e-12)
    return c, column_norm((c - p[:, 0]).T)


def merge_pores(tessellation, *, tolerance: float = 0.02, min_quality: float = 0.2,
                flat_quality: float = 0.05) -> PoreMerge:
    r"""Group co-spherical neighbouring tetrahedra into pore bodies.

    Parameters
    ----------
    tessellation : Tessellation
        From :func:`network.tessellate` (uses ``pore_vertices``, ``pore_throats``,
        ``throat_pores``, ``throat_vertices``, ``throat_area``, ``pore_volume`` and the
        packing's centres).
    tolerance : float, keyword-only
        Relative co-sphericity tolerance :math:`\tau` (default 0.02; 0 merges only exact ties
        to 1e-9).
    min_quality : float, keyword-only
        Tetrahedra whose radius ratio :math:`3 r_{in}/R` is below this (slivers and
        near-slivers, whose circumspheres are large and unstable) are not merged on the
        circumsphere test (default 0.2; a regular tetrahedron has 1, the corner tetrahedron
        of a cube 0.73).
    flat_quality : float, keyword-only
        Tetrahedra with radius ratio below this are flat slivers: each joins the one
        neighbour across its largest face, preferring non-flat neighbours (never both sides,
        which would fuse two voids). Default 0.05.

    Returns
    -------
    PoreMerge

    Raises
    ------
    ValueError
        Negative tolerance.

    Examples
    --------
    A cube of 8 co-spherical centres is one pore body however Qhull splits it:

    >>> import itertools
    >>> from network import Packing, tessellate
    >>> c = np.array(list(itertools.product([0., 1.], repeat=3)))
    >>> m = merge_pores(tessellate(Packing(c, np.full(8, 0.4))))
    >>> m.n_groups, int(m.group_size[0]) >= 5
    (1, True)
    """
    tol = float(tolerance)
    if not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"tolerance must be >= 0, got {tolerance!r}")
    t = tessellation
    pts = t.packing.centers
    pv = t.pore_vertices
    n_p = pv.shape[0]
    pts_c = np.ascontiguousarray(pts.T)     # component-major: each gather reads one row
    x = pts_c[:, pv.T]                      # (3 components, 4 vertices, Np)
    # the tessellation's circumcentres (the same solve; NaN only for |det| = 0, where the
    # quality below is 0 and the tetrahedron flat either way)
    cen = t.pore_circumcenter
    cen_c = np.ascontiguousarray(cen.T)
    rad = column_norm(cen_c - x[:, 0])
    # radius ratio 3 r_in / R, r_in = 3 V / (sum of face areas)
    # (the four face areas are the tessellation's throat areas: face k opposite vertex k)
    ta = t.throat_area[t.pore_throats]
    fa = ((ta[:, 0] + ta[:, 1]) + ta[:, 2]) + ta[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        quality = 9.0 * t.pore_volume / (fa * rad)
    flat = ~(quality >= min_quality)
    ok = ~flat & np.isfinite(rad)

    tp = t.throat_pores
    inner = np.flatnonzero(tp[:, 1] >= 0)
    p, q = tp[inner, 0], tp[inner, 1]
    # fourth vertex of each tetrahedron: the one not on the shared face (the face's three
    # vertices are three of the tetrahedron's four, so the vertex sums differ by the fourth)
    tv = t.throat_vertices
    face_sum = (tv[:, 0] + tv[:, 1] + tv[:, 2])[inner]
    vertex_sum = pv[:, 0] + pv[:, 1] + pv[:, 2] + pv[:, 3]
    vp, vq = vertex_sum[p] - face_sum, vertex_sum[q] - face_sum
    both = ok[p] & ok[q]
    # |distance of the fourth vertex from the other circumcentre - its radius| / radius
    dq, dp = pair_distances(pts_c, vq, cen_c, p), pair_distances(pts_c, vp, cen_c, q)
    with np.errstate(invalid="ignore"):
        for d, r in ((dq, rad[p]), (dp, rad[q])):
            d -= r
            np.abs(d, out=d)
            d /= r
    thr = max(tol, 1e-9)
    merge = both & (dq <= thr) & (dp <= thr)
    mp, mq = p[merge], q[merge]
    # flat slivers: join one neighbour, across the largest face, non-flat preferred
    sliver = ~(quality >= flat_quality)
    fl = np.flatnonzero(sliver)
    if fl.size:
        nb = t.pore_neighbors[fl]
        area = t.throat_area[t.pore_throats[fl]]
        valid = nb >= 0
        good = valid & ~sliver[np.maximum(nb, 0)]
        score = (np.where(good, 2.0, np.where(valid, 1.0, 0.0))
                 * (1.0 + area / (area.max() + 1e-300)))
        pick = nb[np.arange(fl.size), np.argmax(score, axis=1)]
        okp = pick >= 0
        mp = np.concatenate([mp, fl[okp]])
        mq = np.concatenate([mq, pick[okp]])
    g = sp.coo_array((np.ones(mp.size), (mp, mq)), shape=(n_p, n_p))
    n_g, labels = csgraph.connected_components(g, directed=False)
    size = np.bincount(labels, minlength=n_g)
    # centre: mean of distinct sphere centres of each group's non-sliver tetrahedra (all of
    # them for a group of slivers only)
    core = ~sliver
    has_core = np.bincount(labels, weights=core.astype(float), minlength=n_g) > 0
    use = core | ~has_core[labels]
    # singletons: the tetrahedron's centroid; groups: unique vertices of their members
    center = np.zeros((3, n_g))             # component-major, transposed at the end
    single = size[labels] == 1
    # the centroid of every tetrahedron summed as mean(axis=1) sums it, kept for singletons
    total = ((x[:, 0] + x[:, 1]) + x[:, 2]) + x[:, 3]
    center[:, labels[single]] = total[:, single] / 4.0
    sel = ~single & use
    if sel.any():
        key = np.unique(labels[sel, None].astype(np.int64) * (pts.shape[0] + 1) + pv[sel])
        grp = key // (pts.shape[0] + 1)
        vtx = key % (pts.shape[0] + 1)
        cnt = np.bincount(grp, minlength=n_g).astype(float)
        multi = cnt > 0
        sums = np.stack([np.bincount(grp, weights=pts_c[k, vtx], minlength=n_g)
                         for k in range(3)])
        center[:, multi] = sums[:, multi] / cnt[multi]
    center = np.ascontiguousarray(center.T)
    internal = np.zeros(tp.shape[0], dtype=bool)
    internal[inner] = labels[p] == labels[q]
    logger.info("merged %d of %d tetrahedra into %d multi-tetrahedron pore bodies "
                "(largest %d); %d internal throats; %d slivers joined to a neighbour",
                int(size[size > 1].sum()), n_p, int((size > 1).sum()),
                int(size.max()) if n_g else 0, int(internal.sum()), int(fl.size))
    return PoreMerge(labels, int(n_g), size, center, internal, tol)
