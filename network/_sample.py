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
from scipy.sparse.csgraph import connected_components

__all__ = [
    "Region",
    "SampleNetwork",
    "default_region",
    "select_sample",
    "prune_disconnected",
    "core_permeability",
    "AXES",
]

log = logging.getLogger(__name__)

AXES = {"x": 0, "y": 1, "z": 2}


def _axis_index(axis) -> int:
    if isinstance(axis, str) and axis.lower() in AXES:
        return AXES[axis.lower()]
    if isinstance(axis, (int, np.integer)) and 0 <= int(axis) <= 2:
        return int(axis)
    raise ValueError(f"axis must be one of 'x', 'y', 'z' (or 0, 1, 2), got {axis!r}")


@dataclasses.dataclass(frozen=True)
class Region:
    """A box (``lo``, ``hi`` (3,) m) or, when ``radius`` is set, a cylinder.

    The cylinder's axis is the flow axis; it spans ``lo[axis]``–``hi[axis]`` and is centred on
    the middle of the box's lateral extent, with radius ``radius`` (m).
    """

    lo: np.ndarray
    hi: np.ndarray
    radius: float | None = None

    def __post_init__(self):
        lo = np.asarray(self.lo, dtype=float)
        hi = np.asarray(self.hi, dtype=float)
        if lo.shape != (3,) or hi.shape != (3,):
            raise ValueError(f"region bounds must be 3 numbers each, got {lo.shape}, {hi.shape}")
        if not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)) or np.any(hi <= lo):
            raise ValueError(f"region needs lo < hi on every axis, got lo={lo}, hi={hi}")
        if self.radius is not None and not self.radius > 0:
            raise ValueError(f"cylinder radius must be > 0, got {self.radius!r}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def contains(self, pts, axis: int) -> np.ndarray:
        """(N,) bool: points inside the region (cylinder along ``axis`` if a radius is set)."""
        pts = np.asarray(pts)
        s = pts[:, axis]
        inside = (s >= self.lo[axis]) & (s <= self.hi[axis])
        lat = [k for k in range(3) if k != axis]
        if self.radius is None:
            for k in lat:
                inside &= (pts[:, k] >= self.lo[k]) & (pts[:, k] <= self.hi[k])
        else:
            c = 0.5 * (self.lo[lat] + self.hi[lat])
            inside &= np.sum((pts[:, lat] - c) ** 2, axis=1) <= self.radius**2
        return inside

    def cross_section(self, axis: int) -> float:
        """Area normal to ``axis``, m²."""
        if self.radius is not None:
            return float(np.pi * self.radius**2)
        lat = [k for k in range(3) if k != axis]
        return float(np.prod(self.hi[lat] - self.lo[lat]))


#: A tetrahedron whose empty sphere is wider than this many mean diameters is outside the bed.
OUTSIDE_BED_DIAMETERS = 2.0

#: Thinnest interior (in mean diameters) that :func:`default_region` accepts on any axis.
MIN_INTERIOR_DIAMETERS = 2.0


def default_region(packing, *, margin: float | None = None, cylinder: bool = False,
                   container: dict | None = None, axis="z") -> Region:
    r"""Interior box (or cylinder) of a packing, ``margin`` inside its container or its spheres.

    Parameters
    ----------
    packing : Packing
    margin : float, optional, m
        Distance kept from the walls (or from the outer sphere surfaces) on every side.
        Default: 1.5 mean diameters, the thickness over which wall ordering raises the local
        porosity of random sphere packings. (The thesis's box, |x|, |y| < 0.051 m in a 0.15 m
        cylinder, stayed 3.7 d from the wall at mid-faces but came within 0.5 d of it at the
        corners; pass ``--sample`` to reproduce it.)
    cylinder : bool
        Return the largest cylinder (axis = flow axis) inside the interior box.
    container : dict, optional
        From :func:`network.read_container`. A vertical ``'cylinder'`` (``size_m = [D]``,
        axis z, centre ``center_xy`` or the middle of the packing) gives a cylinder of radius
        D/2 − margin for flow along z, and the square inscribed in it for flow along x or y:
        the bounding box of a cylindrical bed would reach past the wall, where the convex
        hull's large outer tetrahedra make a spurious high-conductance channel.
    axis : {'x', 'y', 'z'}
        Flow axis (matters for a cylindrical container only).
    """
    lo = (packing.centers - packing.radii[:, None]).min(axis=0)
    hi = (packing.centers + packing.radii[:, None]).max(axis=0)
    m = 1.5 * packing.mean_diameter if margin is None else float(margin)
    if m < 0:
        raise ValueError(f"margin must be >= 0, got {m}")
    if np.any(hi - lo <= 2 * m):
        raise ValueError(f"margin {m:g} leaves no interior in a packing of extent {hi - lo}")
    d = packing.mean_diameter
    thin = np.flatnonzero(hi - lo - 2 * m < MIN_INTERIOR_DIAMETERS * d)
    if thin.size:
        k = int(thin[0])
        w = float(hi[k] - lo[k] - 2 * m)
        raise ValueError(
            f"a margin of {m:.4g} (kept from the walls on every side) leaves an interior only "
            f"{w:.3g} ({w / d:.2f} mean diameters) thick along {'xyz'[k]}, where the packing is "
            f"{hi[k] - lo[k]:.4g} thick: too thin for a sample away from the walls (the "
            f"tessellation has no walls). Give a smaller --margin (the wall layer then enters "
            f"the sample) or an explicit --sample box")
    lo, hi = lo + m, hi - m
    if container is not None and container.get("kind") == "cylinder":
        c = np.asarray(container.get("center_xy", 0.5 * (lo[:2] + hi[:2])), dtype=float)
        r_in = 0.5 * float(container["size_m"][0]) - m
        if r_in <= 0:
            raise ValueError(f"margin {m:g} leaves no interior in a cylinder of diameter "
                             f"{container['size_m'][0]:g}")
        if _axis_index(axis) == 2:
            return Region([c[0] - r_in, c[1] - r_in, lo[2]], [c[0] + r_in, c[1] + r_in, hi[2]],
                          r_in)
        h = r_in / np.sqrt(2.0)
        return Region([c[0] - h, c[1] - h, lo[2]], [c[0] + h, c[1] + h, hi[2]])
    radius = None
    if cylinder:
        radius = 0.5 * float(np.min(np.delete(hi - lo, _axis_index(axis))))
    return Region(lo, hi, radius)


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
    ax = _axis_index(axis)
    t = tessellation
    if groups is None:
        lab = np.arange(t.n_pores, dtype=np.int64)
        xyz_all = t.pore_centroid
    else:
        lab = np.asarray(groups, dtype=np.int64)
        if lab.shape != (t.n_pores,) or lab.min() < 0:
            raise ValueError(f"groups must be (Np,) = ({t.n_pores},) labels >= 0, got {lab.shape}")
        ng = int(lab.max()) + 1
        vol = np.bincount(lab, t.pore_volume, ng)
        cnt = np.bincount(lab, None, ng)
        w = np.where(vol[lab] > 0, t.pore_volume / np.where(vol[lab] > 0, vol[lab], 1.0),
                     1.0 / cnt[lab])
        xyz_all = np.column_stack([np.bincount(lab, w * t.pore_centroid[:, k], ng)
                                   for k in range(3)])
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
        raise ValueError(f"sample has {inlet.size} inlet and {outlet.size} outlet pores along "
                         f"axis {'xyz'[ax]}: region too thin or outside the packing")
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
    _, lab = connected_components(adj, directed=False)
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


def core_permeability(sample, g, p, *, margin_m: float, viscosity_pa_s: float = 1.0,
                      n_planes: int = 9):
    r"""Permeability of the core of a solved sample, free of its boundary layer, m².

    The whole-box estimate :math:`k = \mu Q H/(A\,\Delta p)` includes the layer of pores
    along the six faces of the sample, where conduits are cut (lateral faces) and the
    pressure is imposed on pores that are not a lattice plane (inlet/outlet). That layer
    lowers k by a term that falls as 1/H: on BCC/FCC arrays with the 4-cell sample of
    :func:`network._lattices.lattice_sample_permeability`, -11 to -18 % at 4 cells, still -7 to -9 % at
    8 cells (measured). Here Darcy's law is applied to the core only,

    .. math:: k = \frac{\mu\,\overline{Q_c}}{A_c\,G},

    with :math:`Q_c` the flow through a plane normal to the axis counted over the throats
    whose segment (pore centre to pore centre) crosses the plane inside the core
    cross-section :math:`A_c` (the region shrunk by ``margin_m`` on every lateral side),
    averaged over ``n_planes`` planes spread over the core length, and :math:`G` the pressure
    gradient from a least-squares line through the pressures of the core pores (region
    shrunk by ``margin_m`` on all sides). In a periodic array with integer-cell margins both
    are exact up to the decaying boundary disturbance (measured: k/k_exact constant to
    0.3 % from 6 to 11 cells; the whole-box estimate drifts by 8-10 %). The core averages
    over fewer cells, so it is the noisier of the two in a disordered sample: on 7-cell
    lattices jittered by 1e-3 lattice constants it varies by about 1 %, the box by 0.2 %.

    Parameters
    ----------
    sample : SampleNetwork
        The solved sample (``pore_xyz``, ``conns``, ``axis``, ``region``).
    g : (Ms,) array_like
        Throat conductances, m³ Pa⁻¹ s⁻¹.
    p : (Ns,) array_like
        Pore pressures, Pa.
    margin_m : float, keyword-only
        Width of the excluded boundary layer, m (> 0; e.g. one lattice constant, or a few
        sphere diameters in a random packing).
    viscosity_pa_s : float, keyword-only
        μ used for ``g`` (default 1).
    n_planes : int, keyword-only
        Flux planes (default 9).

    Returns
    -------
    k : float
        m².

    Raises
    ------
    ValueError
        Non-positive margin, a core with fewer than two distinct pore positions along the
        axis, or no throat crossing the planes.
    """
    margin = float(margin_m)
    if not (np.isfinite(margin) and margin > 0):
        raise ValueError(f"margin_m must be positive, got {margin_m!r}")
    ax = int(sample.axis)
    lat = [i for i in range(3) if i != ax]
    lo = np.asarray(sample.region.lo, dtype=float) + margin
    hi = np.asarray(sample.region.hi, dtype=float) - margin
    if np.any(hi <= lo):
        raise ValueError(f"margin_m={margin_m!r} leaves no core in the region")
    x = np.asarray(sample.pore_xyz, dtype=float)
    p = np.asarray(p, dtype=float)
    g = np.asarray(g, dtype=float)
    core = np.all((x >= lo) & (x < hi), axis=1)
    xa = x[core, ax]
    if np.unique(np.round(xa / (hi[ax] - lo[ax]), 9)).size < 2:
        raise ValueError("the core holds fewer than two distinct pore positions along the "
                         "axis: enlarge the sample or reduce margin_m")
    grad = -np.polyfit(xa, p[core], 1)[0]
    i, j = sample.conns[:, 0], sample.conns[:, 1]
    xi, xj = x[i], x[j]
    q = g * (p[i] - p[j])                                       # flow from i to j
    ai, aj = xi[:, ax], xj[:, ax]
    flows = []
    for x0 in np.linspace(lo[ax], hi[ax], int(n_planes) + 2)[1:-1]:
        cross = (ai < x0) != (aj < x0)
        t = np.where(cross, (x0 - ai) / np.where(cross, aj - ai, 1.0), 0.0)
        pt = xi[:, lat] + t[:, None] * (xj[:, lat] - xi[:, lat])
        ok = cross & np.all((pt >= lo[lat]) & (pt < hi[lat]), axis=1)
        flows.append(np.sum(q[ok] * np.sign(aj[ok] - ai[ok])))
    if not np.any(flows):
        raise ValueError("no throat crosses the core planes")
    area = float(np.prod(hi[lat] - lo[lat]))
    return float(viscosity_pa_s) * float(np.mean(flows)) / (area * grad)
