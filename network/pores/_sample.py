r"""The flow sample: an interior box or cylinder of the tessellation, its inlet and outlet.

Like the thesis (4.2.3, Appendix G), only tetrahedra well inside the packing are used, away from
the container walls where the packing is looser. A pore belongs to the sample when its centroid
lies inside the region. Flow runs along ``axis``; a sample pore is an *inlet* pore when one of
its faces leads to a pore (or a hull face) beyond the lower end of the region along the axis,
an *outlet* pore when one leads beyond the upper end. Faces leaving through the lateral sides
are no-flow (they are simply not part of the network).

The sample length used in Darcy's law is the distance between the mean positions of the
inlet and of the outlet pore centroids along the axis, where the fixed pressures act:

.. math:: H = \langle s \rangle_\mathrm{outlet} - \langle s \rangle_\mathrm{inlet},

and the cross-section is the region's: :math:`A = w_1 w_2` for a box, :math:`\pi R^2` for a
cylinder.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
import scipy.sparse as sp

from .._deferred import csgraph
from ._region import OUTSIDE_BED_DIAMETERS, Region, axis_index

__all__ = ["EmptySampleError", "SampleNetwork", "body_centroids", "select_sample",
           "prune_disconnected"]


class EmptySampleError(ValueError):
    """The sample region holds no inlet or no outlet pore: the packing is too small for the
    region (or the region lies outside it), an input fault (``bad_input``: exit 2 in a CLI)."""

    bad_input = True

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class SampleNetwork:
    """The network of one flow sample, numbered locally.

    Attributes
    ----------
    axis : int
        Flow axis (0, 1, 2).
    region : Region
    pores : (Ns,) int ndarray
        Pore-body ids of the sample pores (local pore i is ``pores[i]``): tessellation pore
        ids, or group labels when tetrahedra were grouped (see ``groups``).
    pore_xyz : (Ns, 3) ndarray, m
        Position of each sample pore (volume-weighted centroid of its tetrahedra).
    throats : (Ms,) int ndarray
        Tessellation throat ids joining two sample pores.
    conns : (Ms, 2) int ndarray
        Local pore indices of those throats.
    inlet, outlet : (k,) int ndarray
        Local indices of the inlet and outlet pores.
    length_m : float
        Sample length H along the axis (mean outlet − mean inlet centroid), m.
    area_m2 : float
        Cross-section A, m².
    n_dropped : int
        Pores removed because they do not connect inlet and outlet (0 before pruning).
    groups : (Np,) int ndarray or None
        Pore body of every tetrahedron when tetrahedra were grouped, else None.
    """

    axis: int
    region: Region
    pores: np.ndarray
    pore_xyz: np.ndarray
    throats: np.ndarray
    conns: np.ndarray
    inlet: np.ndarray
    outlet: np.ndarray
    length_m: float
    area_m2: float
    n_dropped: int = 0
    groups: np.ndarray | None = None

    @property
    def n_pores(self) -> int:
        return int(self.pores.size)

    @property
    def n_throats(self) -> int:
        return int(self.throats.size)


def _length(xyz, inlet, outlet, axis):
    s = xyz[:, axis]
    if inlet.size == 0 or outlet.size == 0:
        return float("nan")
    return float(s[outlet].mean() - s[inlet].mean())


def body_centroids(tessellation, labels) -> np.ndarray:
    """(n_bodies, 3) position of each pore body, m: the volume-weighted centroid of its
    tetrahedra (their plain mean for a body of zero volume); ``labels`` (Np,) >= 0.
    """
    t = tessellation
    lab = np.asarray(labels, dtype=np.int64)
    if lab.shape != (t.n_pores,) or lab.min() < 0:
        raise ValueError(f"groups must be (Np,) = ({t.n_pores},) labels >= 0, got {lab.shape}")
    ng = int(lab.max()) + 1
    vol = np.bincount(lab, t.pore_volume, ng)
    cnt = np.bincount(lab, None, ng)
    w = np.where(vol[lab] > 0, t.pore_volume / np.where(vol[lab] > 0, vol[lab], 1.0),
                 1.0 / cnt[lab])
    return np.column_stack([np.bincount(lab, w * t.pore_centroid[:, k], ng) for k in range(3)])


def select_sample(tessellation, region: Region, *, axis="z", groups=None) -> SampleNetwork:
    """Pores of a region, the throats joining them, and the inlet/outlet pores along ``axis``.

    Parameters
    ----------
    tessellation : Tessellation
    region : Region
    axis : {'x', 'y', 'z'} or int
    groups : (Np,) array_like of int, optional
        Pore body of every tetrahedron (e.g. from :func:`network.tie_groups` or the conduit
        model's merge). Faces inside a body are dropped; a body's position is the
        volume-weighted centroid of its tetrahedra. Default: every tetrahedron is a pore.

    Returns
    -------
    SampleNetwork
        Not yet pruned for connectivity (see :func:`prune_disconnected`).

    Raises
    ------
    ValueError
        The region holds no pore, or no inlet / outlet pore.
    """
    ax = axis_index(axis)
    t = tessellation
    if groups is None:
        lab = np.arange(t.n_pores, dtype=np.int64)
        xyz_all = t.pore_centroid
    else:
        lab = np.asarray(groups, dtype=np.int64)
        xyz_all = body_centroids(t, lab)
    inside = region.contains(xyz_all, ax)
    # tetrahedra whose empty sphere is wider than 2 mean diameters lie outside the packed bed
    # (convex-hull artefacts along walls, free surfaces and open sides: a bed has no void
    # that wide); the tessellation has no walls, so their huge windows would make a
    # spurious channel (measured: k 1e8 times too high with a sample reaching a bin wall).
    # Pore bodies holding one are left out of the sample: no flow, as at a wall.
    big = t.outside_bed(OUTSIDE_BED_DIAMETERS)
    outside_bed = np.bincount(lab, big, xyz_all.shape[0]) > 0
    n_big = int(np.sum(inside & outside_bed))
    if n_big:
        log.warning("%d pore bodies of the sample region have an empty sphere wider than 2 mean "
                    "diameters: they lie outside the packed bed and are left out (no flow). If "
                    "that is many, the region reaches past the bed (give --sample, --margin, "
                    "or a companion JSON with the container)", n_big)
        inside &= ~outside_bed
    # pore bodies made only of tetrahedra inside one grain are solid (multi-sphere grains)
    solid_t = t.solid_pores()
    if solid_t.any():
        n_t = np.bincount(lab, None, xyz_all.shape[0])
        solid = np.bincount(lab, solid_t, xyz_all.shape[0]) >= np.maximum(n_t, 1)
        log.info("%d pore bodies of the sample region lie inside one grain: solid, left out",
                 int(np.sum(inside & solid)))
        inside &= ~solid
    pores = np.flatnonzero(inside)
    if pores.size == 0:
        raise ValueError(f"the sample region {region.lo}–{region.hi} contains no pore")
    local = np.full(xyz_all.shape[0] + 1, -1, dtype=np.int64)   # index -1 (hull) maps to -1
    local[pores] = np.arange(pores.size)
    tp = t.throat_pores
    gb_raw = np.where(tp[:, 1] >= 0, lab[np.maximum(tp[:, 1], 0)], -1)
    ga_raw = lab[tp[:, 0]]
    same = ga_raw == gb_raw
    a = local[ga_raw]
    b = local[gb_raw]
    internal = (a >= 0) & (b >= 0) & ~same
    # boundary throats: one side inside, other outside or hull
    cross = (a >= 0) ^ (b >= 0)
    th = np.flatnonzero(cross)
    inner_local = np.where(a[th] >= 0, a[th], b[th])
    outer = np.where(a[th] >= 0, gb_raw[th], ga_raw[th])
    s_out = np.where(outer >= 0, xyz_all[np.maximum(outer, 0), ax], t.throat_centroid[th, ax])
    inlet = np.unique(inner_local[s_out < region.lo[ax]])
    outlet = np.unique(inner_local[s_out > region.hi[ax]])
    both = np.intersect1d(inlet, outlet)
    if both.size:  # a pore touching both ends (sample one pore thick): keep it as inlet
        outlet = np.setdiff1d(outlet, both)
    if inlet.size == 0 or outlet.size == 0:
        raise EmptySampleError(f"sample has {inlet.size} inlet and {outlet.size} outlet pores "
                               f"along axis {'xyz'[ax]}: region too thin or outside the packing")
    throats = np.flatnonzero(internal)
    conns = np.column_stack([a[throats], b[throats]])
    xyz = xyz_all[pores]
    length = _length(xyz, inlet, outlet, ax)
    log.info("sample along %s: %d pores (%d inlet, %d outlet), %d throats, H = %.4g, A = %.4g",
             "xyz"[ax], pores.size, inlet.size, outlet.size, throats.size, length,
             region.cross_section(ax))
    return SampleNetwork(ax, region, pores, xyz, throats, conns, inlet, outlet, length,
                         region.cross_section(ax), 0, None if groups is None else lab)


def prune_disconnected(sample: SampleNetwork, tessellation, g) -> tuple[SampleNetwork, np.ndarray]:
    """Keep only pores connected (through throats with g > 0) to both inlet and outlet.

    Parameters
    ----------
    sample : SampleNetwork
    tessellation : Tessellation
        Unused (kept for a stable signature); pore positions come from the sample.
    g : (Ms,) array_like
        Conductance of ``sample.throats``; throats with g = 0 (closed) do not connect.

    Returns
    -------
    pruned : SampleNetwork
        Renumbered; ``n_dropped`` counts the removed pores (logged).
    g_kept : (Ms',) ndarray
        Conductances of the kept throats (g > 0 only).
    """
    g = np.asarray(g, dtype=float)
    n = sample.n_pores
    if g.shape != (sample.n_throats,):
        raise ValueError(f"g must have shape ({sample.n_throats},), got {g.shape}")
    live = g > 0
    c = sample.conns[live]
    adj = sp.coo_array((np.ones(c.shape[0]), (c[:, 0], c[:, 1])), shape=(n, n))
    _, lab = csgraph.connected_components(adj, directed=False)
    ok_lab = np.intersect1d(lab[sample.inlet], lab[sample.outlet])
    keep = np.isin(lab, ok_lab)
    # an inlet pore whose only conducting faces go out of the sample is isolated here too
    new = np.full(n, -1, dtype=np.int64)
    new[keep] = np.arange(int(keep.sum()))
    tkeep = live & keep[sample.conns[:, 0]] & keep[sample.conns[:, 1]]
    inlet = new[sample.inlet[keep[sample.inlet]]]
    outlet = new[sample.outlet[keep[sample.outlet]]]
    pores = sample.pores[keep]
    xyz = sample.pore_xyz[keep]
    n_drop = int(n - keep.sum())
    if inlet.size == 0 or outlet.size == 0:
        raise ValueError("no conducting path joins inlet and outlet (all throats closed?)")
    if n_drop:
        log.info("dropped %d of %d sample pores not connected to both inlet and outlet", n_drop, n)
    pruned = dataclasses.replace(
        sample, pores=pores, pore_xyz=xyz, throats=sample.throats[tkeep],
        conns=new[sample.conns[tkeep]], inlet=inlet, outlet=outlet,
        length_m=_length(xyz, inlet, outlet, sample.axis),
        n_dropped=sample.n_dropped + n_drop)
    return pruned, g[tkeep]
