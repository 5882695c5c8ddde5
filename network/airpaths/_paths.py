r"""Airflow paths through the tetrahedra of a packing (thesis 3.4, 4.1.2-4.1.3; Appendices D, E).

A path is a chain of tetrahedra from the bed floor to the bed top, represented by the
centroids of the faces it crosses (thesis Fig. 3.9). Kinds and methods:

``'widest'`` / ``'narrowest'``, method ``'build'`` (:func:`build_paths`, the thesis's own
    construction, 3.4.1 after Sobieski et al. 2012): tetrahedra are built sphere by sphere
    upward from the three spheres nearest to the entry point, leaving each through the open
    exit face of largest (smallest) open area :math:`S_f` (Eq. 3.23), with the thesis's two
    reselection rules.
``'widest'`` / ``'narrowest'``, method ``'delaunay'`` (:func:`walk_paths`): the same exit rule
    walked on the Delaunay tessellation, whose tetrahedra are fixed.
``'maximin'`` (:func:`maximin_paths`): the optimal widest path on the tessellation, whose
    narrowest face is as wide as possible (maximin bottleneck, found in the maximum spanning
    tree), the shortest such path by default.
``'shortest'`` (:func:`shortest_paths`): the shortest chain of face centroids (Dijkstra).

On the tessellation, slivers (flat tetrahedra, mostly in the grain layer against flat walls)
are not entered (:func:`passable_pores`), and paths run from an enterable tetrahedron near the
floor to one near the top (:data:`END_BAND_DIAMETERS`).

Per path: length, tetrahedra count, tortuosity raw and smoothed (Eqs. 3.25-3.27), turning
angles and local widths :math:`d_f = 2\sqrt{S_f/\pi}` (Eq. 3.24); the branched-path model of
3.5.1 along it (:func:`branched_path_pressure_drop`, :func:`branched_table`) and the network
pressure along it (:func:`pressure_along_path`). Open areas are ``throats.open_area`` (exact
with overlapping grains).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from ..pores import axis_index
from .._air import MU_AIR_PA_S
from ._branched import (
    BranchedResult,
    branched_pressure_drop,
    equivalent_diameter,
    local_width,
)

__all__ = [
    "PATH_KINDS",
    "FaceGraph",
    "AirflowPath",
    "face_graph",
    "pore_quality",
    "passable_pores",
    "interior_angles",
    "turning_angles",
    "smoothing_factor",
    "path_length",
    "smoothed_length",
    "bed_depth",
    "entry_faces",
    "random_entry_points",
    "EXIT_FACES",
    "face_areas",
    "build_paths",
    "walk_paths",
    "maximin_paths",
    "shortest_paths",
    "trace_paths",
    "branched_path_pressure_drop",
    "branched_table",
    "pressure_along_path",
    "pore_pressure_array",
]

logger = logging.getLogger(__name__)

#: Path kinds accepted by :func:`trace_paths`.
PATH_KINDS = ("widest", "narrowest", "maximin", "shortest")
#: Coefficients of the smoothing factor, Eq. 3.26 (thesis: omega_a = 0.1, omega_b = 90 deg).
OMEGA_A = 0.1
OMEGA_B_DEG = 90.0


# --------------------------------------------------------------------------------------------
# geometry of a polyline: angles, smoothing, tortuosity (Eqs. 3.25-3.27)
# --------------------------------------------------------------------------------------------
def _as_points(points):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("points must be finite")
    return p


def interior_angles(points, *, rule="eq3.25"):
    r"""Angle :math:`\omega_i` at each interior point of a polyline, degrees (Eq. 3.25).

    .. math:: \cos\omega_i = \frac{a_i^2 + b_i^2 - c_i^2}{2 a_i b_i}

    with :math:`a_i, b_i` the segments before and after point *i* and :math:`c_i` the chord
    from point *i-1* to *i+1*: 180° is a straight continuation, 0° a full reversal.

    Parameters
    ----------
    points : (n, 3) array_like, m
        Path points (face centroids), n >= 2.
    rule : {'eq3.25', 'appendix-d'}, optional
        ``'eq3.25'`` (default) is :math:`\arccos` of the expression. ``'appendix-d'``
        reproduces the script of thesis Appendix D, which omits the arccos: it takes
        :math:`\omega = (180/3.14)\cos\omega` and adds 180 when that is negative. Use it only
        to reproduce the thesis's smoothed tortuosities.

    Returns
    -------
    (n - 2,) ndarray, degrees
        Zero-length segments (repeated points) count as straight (180°).

    Examples
    --------
    >>> interior_angles([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0]]).round(6).tolist()
    [180.0, 90.0]
    """
    p = _as_points(points)
    if p.shape[0] < 3:
        return np.zeros(0)
    a = p[1:-1] - p[:-2]
    b = p[2:] - p[1:-1]
    la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        # (a^2 + b^2 - c^2) / (2ab) with c = a + b  is  -a.b / (|a||b|)
        cos_w = -np.einsum("ij,ij->i", a, b) / (la * lb)
    cos_w = np.clip(np.where(np.isfinite(cos_w), cos_w, -1.0), -1.0, 1.0)
    if rule == "eq3.25":
        return np.degrees(np.arccos(cos_w))
    if rule == "appendix-d":
        w = cos_w * (180.0 / 3.14)
        return np.where(w < 0, 180.0 + w, w)
    raise ValueError(f"unknown angle rule {rule!r}; expected 'eq3.25' or 'appendix-d'")


def turning_angles(points):
    r"""Local turning angle at each interior point, :math:`180° - \omega_i`, degrees.

    0° is straight on, 90° a right-angle turn (thesis Fig. 4.6 plots these).

    Examples
    --------
    >>> turning_angles([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0]]).round(6).tolist()
    [0.0, 90.0]
    """
    return 180.0 - interior_angles(points)


def smoothing_factor(omega_deg, *, omega_a=OMEGA_A, omega_b_deg=OMEGA_B_DEG):
    r"""Length correction factor of a sharp turn, Eq. 3.26 (Sobieski et al. 2012).

    .. math:: \omega^{cor} = \frac{\exp(\omega_a(\omega - \omega_b))}
                                  {1 + \exp(\omega_a(\omega - \omega_b))}

    A logistic function of the interior angle :math:`\omega` (degrees): about 1 for a straight
    continuation (180°), 1/2 at :math:`\omega_b`, about 0 for a reversal (0°).

    Parameters
    ----------
    omega_deg : array_like, degrees
    omega_a : float, optional
        Steepness, 1/degree (thesis: 0.1).
    omega_b_deg : float, optional
        Midpoint, degrees (thesis: 90).

    Returns
    -------
    ndarray, dimensionless in (0, 1)

    Examples
    --------
    >>> float(smoothing_factor(90.0))
    0.5
    """
    x = omega_a * (np.asarray(omega_deg, dtype=float) - omega_b_deg)
    return 0.5 * (1.0 + np.tanh(0.5 * x))  # = e^x / (1 + e^x), without overflow


def path_length(points):
    """Length of a polyline, sum of its segments, m.

    Examples
    --------
    >>> float(path_length([[0, 0, 0], [3, 4, 0], [3, 4, 1]]))
    6.0
    """
    p = _as_points(points)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def smoothed_length(points, *, omega_a=OMEGA_A, omega_b_deg=OMEGA_B_DEG, rule="eq3.25"):
    r"""Length of a polyline with its sharp turns replaced by arcs, Eq. 3.27, m.

    .. math:: L^{cor} = \tfrac12 (a_1 + b_{n}) + \sum_{i=2}^{n-1} \tfrac12 (a_i + b_i)\,
              \omega_i^{cor}

    :math:`a_i, b_i` are the segments before and after interior point *i* (so
    :math:`a_1` is the first segment and :math:`b_n` the last), :math:`\omega_i^{cor}` the
    factor of :func:`smoothing_factor` at the angle of :func:`interior_angles`. A straight
    polyline keeps its length (factor 1 at 180°, up to :math:`e^{-9}`).

    Parameters
    ----------
    points : (n, 3) array_like, m
    omega_a, omega_b_deg : float, optional
        Eq. 3.26 coefficients (0.1, 90°).
    rule : {'eq3.25', 'appendix-d'}, optional
        Angle rule, see :func:`interior_angles`.

    Returns
    -------
    float, m
    """
    p = _as_points(points)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if seg.size <= 1:
        return float(seg.sum())
    cor = smoothing_factor(interior_angles(p, rule=rule), omega_a=omega_a, omega_b_deg=omega_b_deg)
    return float(0.5 * (seg[0] + seg[-1]) + np.sum(0.5 * (seg[:-1] + seg[1:]) * cor))


def bed_depth(centers, radii, axis="z"):
    """Bed depth along ``axis``: centre span plus the mean diameter, m (Appendix D's L0).

    Appendix D divides the path length by ``max(z) - min(z) + 0.0065`` (centre span plus a
    6.5 mm mean diameter); this is the same with the packing's own mean diameter.
    """
    c = np.asarray(centers, dtype=float)
    ax = axis_index(axis)
    return float(np.ptp(c[:, ax]) + 2.0 * np.mean(radii))


def _plane_axes(ax):
    return [i for i in range(3) if i != ax]


# --------------------------------------------------------------------------------------------
# the face graph
# --------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class FaceGraph:
    """What the path tracers need from a tessellation, as plain arrays.

    Attributes
    ----------
    points : (Ns, 3) ndarray, m
        Sphere centres.
    radii : (Ns,) ndarray, m
    pore_vertices : (Np, 4) int ndarray
    pore_throats : (Np, 4) int ndarray
        Throat (face) opposite local vertex k.
    throat_pores : (Nt, 2) int ndarray
        Owner pore first; second -1 on the hull.
    throat_centroid : (Nt, 3) ndarray, m
    throat_area : (Nt,) ndarray, m²
        Full triangle area (Eq. 3.18).
    throat_open_area : (Nt,) ndarray, m²
        Open area between the three grains (Eq. 3.23, exact with overlaps); <= 0 is closed.
    throat_normal : (Nt, 3) ndarray
        Unit normal pointing from ``throat_pores[:, 0]`` towards ``throat_pores[:, 1]``
        (outward on the hull).
    pore_quality : (Np,) ndarray
        :func:`pore_quality` of each tetrahedron (1 regular, 0 flat); computed if not given.
    """

    points: np.ndarray
    radii: np.ndarray
    pore_vertices: np.ndarray
    pore_throats: np.ndarray
    throat_pores: np.ndarray
    throat_centroid: np.ndarray
    throat_area: np.ndarray
    throat_open_area: np.ndarray
    throat_normal: np.ndarray
    pore_quality: np.ndarray = None

    def __post_init__(self):
        if self.pore_quality is None:
            object.__setattr__(self, "pore_quality",
                               pore_quality(self.points, self.pore_vertices))
        np_, nt = self.pore_vertices.shape[0], self.throat_pores.shape[0]
        want = {
            "points": (self.points.shape[0], 3), "radii": (self.points.shape[0],),
            "pore_vertices": (np_, 4), "pore_throats": (np_, 4), "throat_pores": (nt, 2),
            "throat_centroid": (nt, 3), "throat_area": (nt,), "throat_open_area": (nt,),
            "throat_normal": (nt, 3), "pore_quality": (np_,),
        }
        for name, shape in want.items():
            got = np.shape(getattr(self, name))
            if got != shape:
                raise ValueError(f"FaceGraph.{name} must have shape {shape}, got {got}")

    @property
    def n_pores(self):
        return int(self.pore_vertices.shape[0])

    @property
    def n_throats(self):
        return int(self.throat_pores.shape[0])

    @property
    def mean_diameter(self):
        return float(2.0 * self.radii.mean())

    def hull_mask(self):
        return self.throat_pores[:, 1] < 0


def pore_quality(points, pore_vertices):
    r"""Volume of each tetrahedron relative to the regular one of the same mean edge.

    .. math:: q = \frac{6\sqrt2\, V}{\bar e^{3}}

    1 for a regular tetrahedron, 0 for a flat one (a *sliver*: four nearly coplanar centres,
    typical of the grain layers lying against a flat wall or floor).

    Examples
    --------
    >>> import numpy as np
    >>> reg = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    >>> pore_quality(reg, [[0, 1, 2, 3]]).round(12).tolist()
    [1.0]
    """
    x = np.asarray(points, dtype=float)[np.asarray(pore_vertices)]
    e = x[:, 1:] - x[:, :1]
    vol = np.abs(np.linalg.det(e)) / 6.0
    i, j = np.triu_indices(4, k=1)
    ebar = np.linalg.norm(x[:, i] - x[:, j], axis=2).mean(axis=1)
    return 6.0 * np.sqrt(2.0) * vol / ebar**3


def face_graph(tessellation, *, open_area_m2=None):
    """Gather a :class:`FaceGraph` from a :class:`network.Tessellation`.

    Parameters
    ----------
    tessellation : network.Tessellation
    open_area_m2 : (Nt,) array_like, m², optional
        Open areas of the throats; default ``throats.open_area(throat_radii, throat_sides)``.

    Returns
    -------
    FaceGraph
    """
    t = tessellation
    pts = np.asarray(t.packing.centers, dtype=float)
    if open_area_m2 is None:
        from throats import open_area  # the throats package owns the exact open area

        # in chunks: open_area's work arrays take ~10 kB per row
        open_area_m2 = np.concatenate([
            open_area(t.throat_radii[i:i + 20000], t.throat_sides[i:i + 20000])
            for i in range(0, t.n_throats, 20000)]) if t.n_throats else np.zeros(0)
    oa = np.asarray(open_area_m2, dtype=float)
    return FaceGraph(
        points=pts,
        radii=np.asarray(t.packing.radii, dtype=float),
        pore_vertices=np.asarray(t.pore_vertices),
        pore_throats=np.asarray(t.pore_throats),
        throat_pores=np.asarray(t.throat_pores),
        throat_centroid=np.asarray(t.throat_centroid, dtype=float),
        throat_area=np.asarray(t.throat_area, dtype=float),
        throat_open_area=oa,
        throat_normal=_throat_normals(pts, t.pore_vertices, t.pore_throats, t.throat_pores,
                                      t.throat_centroid),
    )


def _throat_normals(points, pore_vertices, pore_throats, throat_pores, throat_centroid):
    """Unit face normals oriented away from the owner pore's opposite vertex."""
    nt = throat_pores.shape[0]
    owner = throat_pores[:, 0]
    # local index k of each throat in its owner pore
    k = np.argmax(pore_throats[owner] == np.arange(nt)[:, None], axis=1)
    fv = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])[k]
    pv = pore_vertices[owner]
    tri = points[np.take_along_axis(pv, fv, axis=1)]  # (Nt, 3, 3)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    apex = points[pv[np.arange(nt), k]]
    s = np.sign(np.einsum("ij,ij->i", n, throat_centroid - apex))
    return n * np.where(s == 0, 1.0, s)[:, None]


#: Default quality below which a tetrahedron is a sliver that paths do not enter.
MIN_QUALITY = 0.02


def passable_pores(graph, *, min_quality=MIN_QUALITY):
    """Tetrahedra a path on the tessellation may enter, (Np,) bool.

    Slivers (:func:`pore_quality` < ``min_quality``, default 0.02; 0 keeps all) are not
    entered. A sliver's four faces lie in one plane, so stepping through it moves a path along
    that plane by up to its whole size, through "open areas" that no air crosses in that
    direction. The grain layer against a flat wall or floor makes many of them: about 10 % of
    the tetrahedra of a three-diameter-thick bin, holding 97 % of its faces wider than 8 mm;
    with them allowed, greedy widest paths run along the walls with mean widths of 10-20 mm.
    """
    return graph.pore_quality >= min_quality


#: Paths start in a tetrahedron whose centroid is within this many mean diameters of the
#: lowest centre and end in one within it of the highest (the flat floor and lid make a layer
#: of slivers that paths cannot enter).
END_BAND_DIAMETERS = 1.5


def _ends(graph, ax, passable):
    """Start and end tetrahedra and their lowest / highest faces along the axis."""
    pc = graph.points[graph.pore_vertices].mean(axis=1)[:, ax]
    lo, hi = graph.points[:, ax].min(), graph.points[:, ax].max()
    band = END_BAND_DIAMETERS * graph.mean_diameter
    low = passable & (pc < lo + band)
    high = passable & (pc > hi - band)
    fh = graph.throat_centroid[graph.pore_throats][:, :, ax]  # (Np, 4)
    rows = np.arange(graph.n_pores)
    bottom = graph.pore_throats[rows, np.argmin(fh, axis=1)]
    top = graph.pore_throats[rows, np.argmax(fh, axis=1)]
    return low, high, bottom, top, pc


# --------------------------------------------------------------------------------------------
# entry points
# --------------------------------------------------------------------------------------------
def random_entry_points(centers, radii, n, *, axis="z", rng=None, margin_m=None):
    """``n`` random air-entry points on the bed floor, away from the walls, (n, 2) m.

    Uniform over the box spanned by the sphere centres in the plane normal to ``axis``, inset
    by ``margin_m`` (default two mean diameters, but at most a quarter of the extent), as the
    thesis keeps its entry points away from the walls (4.1.2).
    Coordinates are the two other axes in x, y, z order.
    """
    ax = axis_index(axis)
    rng = np.random.default_rng(rng)
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    plane = _plane_axes(ax)
    c = np.asarray(centers, dtype=float)
    lo = c[:, plane].min(axis=0)
    hi = c[:, plane].max(axis=0)
    m = 4.0 * float(np.mean(radii)) if margin_m is None else float(margin_m)
    m = np.minimum(m, 0.25 * (hi - lo))
    return rng.uniform(lo + m, hi - m, size=(int(n), 2))


def entry_faces(graph, entry_xy, *, axis="z", min_quality=MIN_QUALITY):
    """Start tetrahedron and face of a path on the tessellation for each entry point.

    The start tetrahedron is the enterable one (see :func:`passable_pores`) within
    :data:`END_BAND_DIAMETERS` mean diameters of the floor, connected to the top through open
    faces and enterable tetrahedra, whose centroid is nearest to the entry point on the floor;
    the path starts at its lowest face.

    Returns
    -------
    start_face, start_pore : (n,) int ndarrays
    """
    ax = axis_index(axis)
    xy = np.atleast_2d(np.asarray(entry_xy, dtype=float))
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise ValueError(f"entry points must have shape (n, 2), got {xy.shape}")
    passable = passable_pores(graph, min_quality=min_quality)
    low, high, bottom, _, pc = _ends(graph, ax, passable)
    # keep start tetrahedra that open (through open faces and enterable tetrahedra) onto the top
    tp = graph.throat_pores
    inner = tp[:, 1] >= 0
    link = inner & (graph.throat_open_area > 0)
    link[inner] &= passable[tp[inner, 0]] & passable[tp[inner, 1]]
    adj = sparse.csr_array((np.ones(int(link.sum())), (tp[link, 0], tp[link, 1])),
                           shape=(graph.n_pores, graph.n_pores))
    _, comp = csgraph.connected_components(adj, directed=False)
    through = np.intersect1d(comp[low], comp[high])
    cand = np.flatnonzero(low & np.isin(comp, through))
    if cand.size == 0:
        raise ValueError("no enterable tetrahedron near the floor opens onto the top "
                         "(min_quality too high?)")
    plane = _plane_axes(ax)
    cc = graph.points[graph.pore_vertices[cand]].mean(axis=1)
    lo = graph.points[:, ax].min()
    out = np.empty(xy.shape[0], dtype=np.intp)
    for i0 in range(0, xy.shape[0], 256):  # chunks keep the (n, F) arrays small
        d2 = (np.sum((cc[None, :, plane] - xy[i0:i0 + 256, None]) ** 2, axis=2)
              + (pc[cand] - lo)[None] ** 2)
        out[i0:i0 + 256] = cand[np.argmin(d2, axis=1)]
    return bottom[out], out


# --------------------------------------------------------------------------------------------
# paths
# --------------------------------------------------------------------------------------------
#: Exit faces of a path tetrahedron [b0, b1, b2, n] (inlet face b0 b1 b2), Appendix D's order.
EXIT_FACES = np.array([[0, 1, 3], [0, 2, 3], [1, 2, 3]])
#: The inlet vertex left behind by each exit face.
_LEFT_BEHIND = np.array([2, 1, 0])


def face_areas(points, radii, triangles):
    """Full (Heron, Eq. 3.18) and open (Eq. 3.23, exact) areas of triangles of sphere centres.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    triangles : (..., 3) int array_like
        Sphere indices.

    Returns
    -------
    full_m2, open_m2 : (...) ndarrays, m²
        The open area comes from ``throats.open_area`` (0 when the disks cover the triangle;
        NaN for a degenerate triangle, which the path rules treat as closed).
    """
    from throats import open_area  # the throats package owns the exact open area

    tri = np.asarray(triangles, dtype=np.intp)
    shape = tri.shape[:-1]
    t = tri.reshape(-1, 3)
    x = np.asarray(points, dtype=float)[t]
    r = np.asarray(radii, dtype=float)[t]
    sides = np.column_stack([np.linalg.norm(x[:, 1] - x[:, 0], axis=1),
                             np.linalg.norm(x[:, 2] - x[:, 0], axis=1),
                             np.linalg.norm(x[:, 2] - x[:, 1], axis=1)])
    full = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if t.shape[0] == 0:
        return full.reshape(shape), full.reshape(shape)
    with np.errstate(invalid="ignore"):
        opened = open_area(r, sides)
    return full.reshape(shape), opened.reshape(shape)


def _eq323_negative(points, radii, triangles):
    r"""Reselection rule 2 of the thesis: is Eq. 3.23 negative for these triangles?

    Eq. 3.23 subtracts the three sectors :math:`\tfrac12\theta_i r_i^2` from the triangle,
    counting the lens of two overlapping disks twice; the thesis reselects a tetrahedron when
    the result is negative (Fig. 3.8, Appendix D ``if ai1<0 || ai2<0 || ai3<0``). This is
    that test only; open areas themselves come from ``throats.open_area``.
    """
    x = np.asarray(points, dtype=float)[np.asarray(triangles)]  # (..., 3, 3)
    r = np.asarray(radii, dtype=float)[np.asarray(triangles)]
    full = 0.5 * np.linalg.norm(np.cross(x[..., 1, :] - x[..., 0, :],
                                         x[..., 2, :] - x[..., 0, :]), axis=-1)
    sectors = 0.0
    for i in range(3):  # the three vertices
        u = x[..., (i + 1) % 3, :] - x[..., i, :]
        v = x[..., (i + 2) % 3, :] - x[..., i, :]
        cos = np.einsum("...j,...j->...", u, v) / (np.linalg.norm(u, axis=-1)
                                                   * np.linalg.norm(v, axis=-1))
        sectors = sectors + 0.5 * np.arccos(np.clip(cos, -1.0, 1.0)) * r[..., i] ** 2
    return full - sectors < 0


@dataclasses.dataclass(frozen=True)
class AirflowPath:
    """One airflow path and its measures.

    Attributes
    ----------
    kind : str
        'widest' | 'narrowest' | 'maximin' | 'shortest'.
    method : str
        'build' (thesis construction), 'delaunay' (step-increment on the tessellation) or
        'graph' (optimal path on the tessellation).
    entry_xy : (2,) ndarray, m
        Entry point on the floor (coordinates of the two axes normal to the flow axis).
    axis : str
    status : str
        'ok' (reached the top), 'stuck' (no way on), 'max-steps'.
    tetra_vertices : (n, 4) int ndarray
        Sphere indices of the n tetrahedra, inlet face first (columns 0-2), apex last.
    exit_local : (n,) int ndarray
        Exit face of each tetrahedron as a row of :data:`EXIT_FACES`.
    points : (n + 1, 3) ndarray, m
        Centroids of the entry face and of every exit face: the path polyline.
    widths_m : (n,) ndarray, m
        Width of each exit face, Eq. 3.24 with its open area.
    length_m, smoothed_length_m : float, m
        Polyline length; Eq. 3.27.
    depth_m : float, m
        Bed depth the tortuosity is relative to.
    turning_angles_deg : (n - 1,) ndarray, degrees
    pores : (n,) int ndarray
        Delaunay pores (methods 'delaunay' and 'graph'; -1 for 'build').
    n_relaxed, n_backtracks : int
        Steps taken under a relaxed rule (see the tracer); steps taken back.
    """

    kind: str
    method: str
    entry_xy: np.ndarray
    axis: str
    status: str
    tetra_vertices: np.ndarray
    exit_local: np.ndarray
    points: np.ndarray
    widths_m: np.ndarray
    length_m: float
    smoothed_length_m: float
    depth_m: float
    turning_angles_deg: np.ndarray
    pores: np.ndarray
    n_relaxed: int = 0
    n_backtracks: int = 0

    @property
    def n_tetrahedra(self):
        return int(self.tetra_vertices.shape[0])

    @property
    def tortuosity_raw(self):
        """Path length over bed depth."""
        return self.length_m / self.depth_m

    @property
    def tortuosity(self):
        """Smoothed path length (Eq. 3.27) over bed depth (thesis 3.4.2)."""
        return self.smoothed_length_m / self.depth_m

    @property
    def tortuosity_span(self):
        """Path length over the path's own extent along the axis (>= 1).

        Paths on the tessellation start and end up to :data:`END_BAND_DIAMETERS` inside the
        bed, so their thesis tortuosity (over the bed depth) undercounts; this one does not.
        """
        ext = float(np.ptp(self.points[:, axis_index(self.axis)])) if self.points.size else 0.0
        return self.length_m / ext if ext > 0 else float("nan")

    @property
    def mean_width_m(self):
        return float(np.nanmean(self.widths_m)) if self.widths_m.size else float("nan")

    @property
    def bottleneck_width_m(self):
        return float(np.nanmin(self.widths_m)) if self.widths_m.size else float("nan")

    def summary(self):
        """Scalars of the path, JSON-ready."""
        ta = self.turning_angles_deg
        return {
            "kind": self.kind, "method": self.method, "axis": self.axis, "status": self.status,
            "entry_xy_m": [float(v) for v in self.entry_xy],
            "n_tetrahedra": self.n_tetrahedra, "length_m": self.length_m,
            "smoothed_length_m": self.smoothed_length_m, "depth_m": self.depth_m,
            "tortuosity_raw": self.tortuosity_raw, "tortuosity": self.tortuosity,
            "tortuosity_span": self.tortuosity_span, "mean_width_m": self.mean_width_m,
            "bottleneck_width_m": self.bottleneck_width_m,
            "turning_below_30deg": float(np.mean(ta < 30.0)) if ta.size else float("nan"),
            "n_relaxed": self.n_relaxed, "n_backtracks": self.n_backtracks,
        }


def _path_record(points, radii, kind, method, entry_xy, axis, status, tetra, exit_local,
                 depth, *, pores=None, n_relaxed=0, n_back=0, angle_rule="eq3.25",
                 exit_open_m2=None):
    """Assemble an :class:`AirflowPath` from its tetrahedra (inlet face first)."""
    pts_all = np.asarray(points, dtype=float)
    tetra = np.asarray(tetra, dtype=np.intp).reshape(-1, 4)
    exit_local = np.asarray(exit_local, dtype=np.intp).reshape(-1)
    n = tetra.shape[0]
    if n:
        exit_tri = np.take_along_axis(tetra, EXIT_FACES[exit_local], axis=1)
        pts = np.concatenate([pts_all[tetra[:1, :3]].mean(axis=1),
                              pts_all[exit_tri].mean(axis=1)])
        if exit_open_m2 is None:
            _, exit_open_m2 = face_areas(pts_all, radii, exit_tri)
        widths = equivalent_diameter(np.nan_to_num(exit_open_m2, nan=0.0))
    else:
        pts = np.zeros((0, 3))
        widths = np.zeros(0)
    return AirflowPath(
        kind=kind, method=method, entry_xy=np.asarray(entry_xy, dtype=float), axis=axis,
        status=status, tetra_vertices=tetra, exit_local=exit_local, points=pts,
        widths_m=widths,
        length_m=path_length(pts) if n else 0.0,
        smoothed_length_m=smoothed_length(pts, rule=angle_rule) if n else 0.0,
        depth_m=float(depth), turning_angles_deg=turning_angles(pts) if n else np.zeros(0),
        pores=np.full(n, -1, dtype=np.intp) if pores is None else np.asarray(pores, np.intp),
        n_relaxed=int(n_relaxed), n_backtracks=int(n_back),
    )


def build_paths(points, radii, entry_xy, *, kind="widest", axis="z", k_neighbors=24,
                max_steps=None, depth_m=None, angle_rule="eq3.25", closed_rule="eq3.23",
                min_quality=0.0):
    r"""Step-increment paths built tetrahedron by tetrahedron, as the thesis does (3.4.1).

    All entries advance together, one tetrahedron per step.

    1. The base triangle of the first tetrahedron is the three spheres nearest to the entry
       point on the floor (the lowest centre height).
    2. The fourth sphere is the one nearest to the base centroid that (a) is higher than the
       centroid along ``axis``, (b) is not yet on the path (Appendix D), (c) lies on the other
       side of the base plane from the previous tetrahedron, so the new one does not fold back
       over it (reselection rule 1, Fig. 3.7), (d) makes a tetrahedron whose inscribed sphere
       is smaller than a mean grain (3.4.1), and (e) leaves no exit face closed
       (reselection rule 2, Fig. 3.8; see ``closed_rule``). Without any candidate meeting
       (e), the nearest meeting (a)-(d) with an open upward exit is taken (counted in
       ``n_relaxed``).
    3. The exit is the open face higher than the base centroid of largest (``'widest'``) or
       smallest (``'narrowest'``) open area (Eq. 3.23, exact: ``throats.open_area``); it is
       the next base. When a later tetrahedron finds no fourth sphere, the path returns to
       the previous one and takes its next-best exit (the thesis's "another triangle from the
       current tetrahedron would be selected"), dropping tetrahedra that have none left
       (counted in ``n_backtracks``).
    4. The path ends when the base centroid is within one mean radius of the highest centre.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    entry_xy : (n, 2) array_like, m
        Entry points (the two axes normal to ``axis``, in x, y, z order).
    kind : {'widest', 'narrowest'}
    axis : {'x', 'y', 'z'}
    k_neighbors : int, optional
        Candidates examined per step (nearest spheres to the base centroid; default 24).
    max_steps : int, optional
        Default 20 x the bed depth in mean diameters.
    depth_m : float, optional
        Bed depth for tortuosity (default :func:`bed_depth`).
    angle_rule : {'eq3.25', 'appendix-d'}
    min_quality : float, optional
        Not in the thesis (default 0, off): also refuse fourth spheres that make a sliver
        (:func:`pore_quality` below this). Against flat walls the nearest sphere above is
        often in the wall layer, and the flat tetrahedron it makes has faces of up to 100 mm²
        lying in the wall plane, which the widest rule then picks.
    closed_rule : {'eq3.23', 'exact'}
        When a face counts as closed for rule 2: ``'eq3.23'`` (default, as the thesis) when
        the triangle minus the three sectors is negative, which also rejects faces whose
        overlapping grains leave only a sliver of open area; ``'exact'`` when the exact open
        area is 0. With ``'exact'`` narrowest paths squeeze through faces a few micrometres
        wide.

    Returns
    -------
    list of AirflowPath
    """
    from scipy.spatial import cKDTree

    if closed_rule not in ("eq3.23", "exact"):
        raise ValueError(f"closed_rule must be 'eq3.23' or 'exact', got {closed_rule!r}")

    if kind not in ("widest", "narrowest"):
        raise ValueError(f"build kind must be 'widest' or 'narrowest', got {kind!r}")
    ax = axis_index(axis)
    x = _as_points(points)
    r = np.asarray(radii, dtype=float)
    if r.shape != (x.shape[0],):
        raise ValueError(f"radii must have shape ({x.shape[0]},), got {r.shape}")
    xy = np.atleast_2d(np.asarray(entry_xy, dtype=float))
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise ValueError(f"entry points must have shape (n, 2), got {xy.shape}")
    n, ns = xy.shape[0], x.shape[0]
    rbar = float(r.mean())
    h = x[:, ax]
    h_top = h.max()
    depth = bed_depth(x, r, axis) if depth_m is None else float(depth_m)
    if max_steps is None:
        max_steps = int(max(200, 20 * np.ptp(h) / (2 * rbar)))
    sign = 1.0 if kind == "widest" else -1.0
    k = int(min(k_neighbors, ns))
    tree = cKDTree(x)

    aep = np.zeros((n, 3))
    aep[:, _plane_axes(ax)] = xy
    aep[:, ax] = h.min()
    _, base = tree.query(aep, k=3)
    base = np.asarray(base, dtype=np.intp).reshape(n, 3)
    used = np.zeros((n, ns), dtype=bool)
    used[np.arange(n)[:, None], base] = True
    prev = np.full(n, -1, dtype=np.intp)
    tetra = np.full((n, max_steps, 4), -1, dtype=np.intp)
    exits = np.full((n, max_steps), -1, dtype=np.intp)
    step_areas = np.full((n, max_steps, 3), np.nan)
    step_up = np.zeros((n, max_steps, 3), dtype=bool)
    banned = np.zeros((n, max_steps, 3), dtype=bool)
    count = np.zeros(n, dtype=np.intp)
    relaxed = np.zeros(n, dtype=np.intp)
    n_back = np.zeros(n, dtype=np.intp)

    def step_ok(i, t):
        return (step_areas[i, t] > 0) & step_up[i, t] & ~banned[i, t]

    def _choose_exit(i, t):
        """Exit of tetrahedron t of paths i: best allowed face; it becomes the next base."""
        if not i.size:
            return
        score = np.where(step_ok(i, t), sign * step_areas[i, t], -np.inf)
        j = np.argmax(score, axis=1)
        exits[i, t] = j
        tet_ = tetra[i, t]
        prev[i] = tet_[np.arange(i.size), _LEFT_BEHIND[j]]
        base[i] = tet_[np.arange(i.size)[:, None], EXIT_FACES[j]]

    status = np.full(n, "running", dtype=object)
    active = np.arange(n)
    while active.size:
        b = base[active]
        pb = x[b]  # (a, 3, 3)
        c = pb.mean(axis=1)
        hc = c[:, ax]
        top = hc >= h_top - rbar
        status[active[top]] = "ok"
        active, b, pb, c, hc = active[~top], b[~top], pb[~top], c[~top], hc[~top]
        if not active.size:
            break
        a = active.size
        _, cand = tree.query(c, k=k)
        cand = np.asarray(cand, dtype=np.intp).reshape(a, k)
        cand = np.where(cand < ns, cand, 0)
        xc = x[cand]  # (a, k, 3)
        feas = (h[cand] > hc[:, None]) & ~used[active[:, None], cand]
        nrm = np.cross(pb[:, 1] - pb[:, 0], pb[:, 2] - pb[:, 0])
        s_new = np.einsum("akj,aj->ak", xc - pb[:, None, 0], nrm)
        pv = prev[active]
        s_prev = np.einsum("aj,aj->a", x[np.where(pv >= 0, pv, 0)] - pb[:, 0], nrm)
        feas &= np.where((pv >= 0)[:, None], s_new * s_prev[:, None] < 0, s_new != 0)
        # inscribed sphere of the tetrahedron of centres: r_in = 3 V / (sum of face areas)
        vol = np.abs(s_new) / 6.0
        e0, e1, e2 = (xc - pb[:, None, i] for i in range(3))
        s_faces = 0.5 * (np.linalg.norm(np.cross(e0, e1), axis=2)
                         + np.linalg.norm(np.cross(e0, e2), axis=2)
                         + np.linalg.norm(np.cross(e1, e2), axis=2)
                         + np.linalg.norm(nrm, axis=1)[:, None])
        feas &= 3.0 * vol / s_faces < rbar
        if min_quality > 0:  # not in the thesis: refuse slivers (see passable_pores)
            i_, j_ = np.triu_indices(4, k=1)
            allv = np.concatenate([np.broadcast_to(pb[:, None], (a, k, 3, 3)), xc[:, :, None]],
                                  axis=2)  # (a, k, 4, 3)
            ebar = np.linalg.norm(allv[:, :, i_] - allv[:, :, j_], axis=3).mean(axis=2)
            feas &= 6.0 * np.sqrt(2.0) * vol / ebar**3 >= min_quality
        # walk the feasible candidates nearest first; open areas only where needed
        order = np.argsort(~feas, axis=1, kind="stable")  # feasible first, by distance
        n_feas = feas.sum(axis=1)
        choice = np.full(a, -1, dtype=np.intp)
        fallback = np.full(a, -1, dtype=np.intp)
        areas = np.full((a, 3), np.nan)
        fb_areas = np.full((a, 3), np.nan)
        pending = np.flatnonzero(n_feas > 0)
        for slot in range(k):  # rarely more than two rounds
            pending = pending[n_feas[pending] > slot]
            if not pending.size:
                break
            cj = cand[pending, order[pending, slot]]
            tet = np.column_stack([b[pending], cj])
            tri = tet[:, EXIT_FACES]  # (p, 3, 3)
            _, op = face_areas(x, r, tri)
            if closed_rule == "eq3.23":
                op = np.where(_eq323_negative(x, r, tri), 0.0, op)
            upf = x[tri].mean(axis=2)[:, :, ax] > hc[pending, None]
            good = np.all(op > 0, axis=1)
            usable = np.any((op > 0) & upf, axis=1)
            first_fb = usable & (fallback[pending] < 0)
            fallback[pending[first_fb]] = cj[first_fb]
            fb_areas[pending[first_fb]] = op[first_fb]
            choice[pending[good]] = cj[good]
            areas[pending[good]] = op[good]
            pending = pending[~good]
        use_fb = (choice < 0) & (fallback >= 0)
        relaxed[active[use_fb]] += 1
        choice = np.where(use_fb, fallback, choice)
        areas = np.where(use_fb[:, None], fb_areas, areas)
        go = choice >= 0
        ga = active[go]
        tet = np.column_stack([b[go], choice[go]])
        tri = tet[:, EXIT_FACES]
        up = x[tri].mean(axis=2)[:, :, ax] > hc[go, None]
        step_areas[ga, count[ga]] = areas[go]
        step_up[ga, count[ga]] = up
        banned[ga, count[ga]] = False  # the slot may hold bans of a tetrahedron dropped before
        tetra[ga, count[ga]] = tet
        used[ga, choice[go]] = True
        count[ga] += 1
        _choose_exit(ga, count[ga] - 1)
        # dead end: the thesis selects another exit of the previous tetrahedron (rule 1);
        # when it has none left, that tetrahedron is dropped and its base tried again
        dead = active[~go]
        n_back[dead] += 1
        status[dead[(count[dead] == 0) | (n_back[dead] > max_steps)]] = "stuck"
        dead = dead[status[dead] == "running"]
        t = count[dead] - 1
        banned[dead, t, exits[dead, t]] = True
        has = np.any(step_ok(dead, t), axis=1)
        _choose_exit(dead[has], t[has])
        pop = dead[~has]
        count[pop] -= 1
        tp_ = count[pop]
        base[pop] = tetra[pop, tp_, :3]
        prev_t = np.maximum(tp_ - 1, 0)
        prev_j = exits[pop, prev_t]
        prev[pop] = np.where(tp_ > 0, tetra[pop, prev_t, _LEFT_BEHIND[prev_j]], -1)
        full = active[count[active] >= max_steps]
        status[full] = "max-steps"
        active = active[status[active] == "running"]
    logger.info("built %d %s paths: %d ok, %d relaxed steps", n, kind,
                int(np.sum(status == "ok")), int(relaxed.sum()))
    return [
        _path_record(x, r, kind, "build", xy[i], axis, str(status[i]), tetra[i, : count[i]],
                     exits[i, : count[i]], depth, n_relaxed=relaxed[i], n_back=n_back[i],
                     angle_rule=angle_rule,
                     exit_open_m2=step_areas[i, np.arange(count[i]), exits[i, : count[i]]])
        for i in range(n)
    ]


def _faces_to_tetra(graph, faces):
    """Tetrahedra (inlet face first) and exit rows of a chain of Delaunay faces."""
    faces = np.asarray(faces, dtype=np.intp)
    tp = graph.throat_pores
    a, b = tp[faces[:-1]], tp[faces[1:]]
    same = (a[:, :, None] == b[:, None, :]) & (a[:, :, None] >= 0)
    pores = a[np.arange(a.shape[0]), np.argmax(same.any(axis=2), axis=1)]
    pv = graph.pore_vertices[pores]  # (m, 4)
    pt = graph.pore_throats[pores]
    k_in = np.argmax(pt == faces[:-1, None], axis=1)
    base = np.take_along_axis(pv, np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])[k_in],
                              axis=1)
    apex = pv[np.arange(pores.size), k_in]
    tetra = np.column_stack([base, apex])
    k_out = np.argmax(pt == faces[1:, None], axis=1)
    left = pv[np.arange(pores.size), k_out]  # the vertex the exit face leaves behind
    exit_local = 2 - np.argmax(base == left[:, None], axis=1)  # _LEFT_BEHIND inverse
    return tetra, exit_local, pores


def walk_paths(graph, entry_face, entry_pore, *, kind="widest", axis="z", max_steps=None,
               min_quality=MIN_QUALITY):
    r"""Step-increment paths walked through the Delaunay tetrahedra (thesis 3.4.1 rules).

    The tessellation fixes each next tetrahedron (the one behind the chosen face), so only the
    exit choice and the reselection rules carry over from the thesis's construction
    (:func:`build_paths`); all entries advance together.

    Parameters
    ----------
    graph : FaceGraph
    entry_face, entry_pore : (n,) array_like of int
        Start face and tetrahedron of each path (see :func:`entry_faces`).
    kind : {'widest', 'narrowest'}
        Exit face of largest or smallest open area.
    axis : {'x', 'y', 'z'}
        Flow direction (+axis).
    max_steps : int, optional
        Step limit per path (default 50 x the bed depth in mean diameters, at least 1000).
    min_quality : float, optional
        Slivers not entered, see :func:`passable_pores`.

    Returns
    -------
    faces : list of (m_i,) int ndarrays
        Faces crossed by each path, start face first, end face last.
    status : (n,) ndarray of str
    n_relaxed, n_backtracks : (n,) int ndarrays

    Notes
    -----
    Per step and path: candidates are the three faces of the current tetrahedron other than
    the one it was entered by; a face is allowed if it is open (:math:`S_f > 0`), interior,
    and leads to an enterable tetrahedron not yet on the path (rules 2 and 1 of the thesis).
    The allowed faces whose centroid is higher (along ``axis``) than the entry face's are
    ranked by open area; if none is higher, all allowed faces are ranked (a relaxed step); if
    none is allowed, the path steps back (the dead tetrahedron stays marked). A path ends in
    a tetrahedron within :data:`END_BAND_DIAMETERS` of the top, through its highest face.
    """
    if kind not in ("widest", "narrowest"):
        raise ValueError(f"greedy kind must be 'widest' or 'narrowest', got {kind!r}")
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    p0 = np.atleast_1d(np.asarray(entry_pore, dtype=np.intp))
    n = f0.size
    tp, pt = graph.throat_pores, graph.pore_throats
    hull = graph.hull_mask()
    passable = passable_pores(graph, min_quality=min_quality)
    _, high, _, top, _ = _ends(graph, ax, passable)
    h = graph.throat_centroid[:, ax]
    area = graph.throat_open_area
    sign = 1.0 if kind == "widest" else -1.0
    if max_steps is None:
        depth_d = np.ptp(graph.points[:, ax]) / graph.mean_diameter
        max_steps = int(max(1000, 50 * depth_d))

    stack_pore = np.full((n, max_steps + 1), -1, dtype=np.intp)
    stack_face = np.full((n, max_steps + 1), -1, dtype=np.intp)
    stack_pore[:, 0] = p0
    stack_face[:, 0] = f0
    ptr = np.zeros(n, dtype=np.intp)
    visited = np.zeros((n, graph.n_pores), dtype=bool)
    visited[np.arange(n), p0] = True
    exit_face = np.full(n, -1, dtype=np.intp)
    status = np.full(n, "running", dtype=object)
    n_relaxed = np.zeros(n, dtype=np.intp)
    n_back = np.zeros(n, dtype=np.intp)
    active = np.arange(n)
    steps = 0
    while active.size:
        steps += 1
        p = stack_pore[active, ptr[active]]
        fin = stack_face[active, ptr[active]]
        # finish in a tetrahedron at the top, through its highest face
        done = high[p] & (top[p] != fin)
        exit_face[active[done]] = top[p[done]]
        status[active[done]] = "ok"
        active, p, fin = active[~done], p[~done], fin[~done]
        if not active.size:
            break
        faces = pt[p]  # (a, 4)
        pair = tp[faces]  # (a, 4, 2)
        nb = np.where(pair[..., 0] == p[:, None], pair[..., 1], pair[..., 0])
        nb0 = np.where(nb >= 0, nb, 0)
        ok = (faces != fin[:, None]) & (area[faces] > 0) & ~hull[faces]
        ok &= passable[nb0] & ~visited[active[:, None], nb0]
        up = ok & (h[faces] > h[fin][:, None])
        has_up = up.any(axis=1)
        allowed = np.where(has_up[:, None], up, ok)
        go = allowed.any(axis=1)
        n_relaxed[active[go & ~has_up]] += 1
        score = np.where(allowed, sign * area[faces], -np.inf)
        j = np.argmax(score, axis=1)
        ga = active[go]
        nf = faces[go, j[go]]
        npore = nb[go, j[go]]
        ptr[ga] += 1
        stack_pore[ga, ptr[ga]] = npore
        stack_face[ga, ptr[ga]] = nf
        visited[ga, npore] = True
        ba = active[~go]
        n_back[ba] += 1
        ptr[ba] -= 1
        status[ba[ptr[ba] < 0]] = "stuck"
        status[ga[ptr[ga] >= max_steps]] = "max-steps"
        active = active[status[active] == "running"]
    out = []
    for i in range(n):  # assembling n result lists, not a hot loop
        if status[i] == "ok":
            out.append(np.append(stack_face[i, : ptr[i] + 1], exit_face[i]))
        else:
            out.append(stack_face[i, : max(ptr[i], 0) + 1].copy())
    logger.info("walked %s paths: %d entries, %d steps, %d ok", kind, n, steps,
                int(np.sum(status == "ok")))
    return out, status.astype(str), n_relaxed, n_back


def _face_edges(graph, usable, pore_ok):
    """Pairs of usable faces sharing a tetrahedron that may be entered: (E, 2) int."""
    pt = graph.pore_throats[pore_ok]
    i, j = np.triu_indices(4, k=1)
    e = np.stack([pt[:, i].ravel(), pt[:, j].ravel()], axis=1)
    return e[usable[e[:, 0]] & usable[e[:, 1]]]


def _graph_setup(graph, ax, entry_face, entry_pore, min_quality):
    """Usable faces, enterable pores and end faces of the face graph."""
    passable = passable_pores(graph, min_quality=min_quality)
    _, high, _, top, _ = _ends(graph, ax, passable)
    end_faces = np.unique(top[high])
    usable = ~graph.hull_mask() & (graph.throat_open_area > 0)
    usable[end_faces] = True
    usable[entry_face] = True
    pore_ok = passable.copy()
    pore_ok[entry_pore] = True
    return end_faces, usable, pore_ok


def _follow(pred, start, sink):
    """Walk predecessor links from every start node to ``sink``: list of node arrays."""
    n = start.size
    paths = [[int(s)] for s in start]
    cur = start.copy()
    alive = np.flatnonzero(cur != sink)
    ok = np.ones(n, dtype=bool)
    limit = pred.size
    steps = 0
    while alive.size and steps < limit:
        nxt = pred[cur[alive]]
        bad = nxt < 0
        ok[alive[bad]] = False
        alive, nxt = alive[~bad], nxt[~bad]
        cur[alive] = nxt
        for i, v in zip(alive.tolist(), nxt.tolist()):
            paths[i].append(v)
        alive = alive[nxt != sink]
        steps += 1
    return [np.array(p[:-1] if okk else p, dtype=np.intp) for p, okk in zip(paths, ok)], ok


def shortest_paths(graph, entry_face, entry_pore, *, axis="z", min_quality=MIN_QUALITY):
    """Shortest chains of face centroids from each entry face to the outlet (Dijkstra).

    One Dijkstra run from a virtual node joined to every end face (the highest face of each
    enterable tetrahedron within :data:`END_BAND_DIAMETERS` of the top) serves all entries.
    Interior faces are usable if open (open area > 0); slivers are not entered (see
    :func:`passable_pores`, ``min_quality``).

    Returns
    -------
    faces : list of int ndarrays (start face first, end face last)
    ok : (n,) bool ndarray
        False where the entry is not connected to the outlet.
    """
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    out, usable, pore_ok = _graph_setup(graph, ax, f0, entry_pore, min_quality)
    nt = graph.n_throats
    e = _face_edges(graph, usable, pore_ok)
    c = graph.throat_centroid
    w = np.linalg.norm(c[e[:, 0]] - c[e[:, 1]], axis=1)
    tiny = 1e-9 * graph.mean_diameter
    w = np.maximum(w, tiny)
    rows = np.concatenate([e[:, 0], np.full(out.size, nt)])
    cols = np.concatenate([e[:, 1], out])
    vals = np.concatenate([w, np.full(out.size, tiny)])
    g = sparse.csr_array((vals, (rows, cols)), shape=(nt + 1, nt + 1))
    _, pred = csgraph.dijkstra(g, directed=False, indices=nt, return_predecessors=True)
    return _follow(pred, f0, nt)


def maximin_paths(graph, entry_face, entry_pore, *, axis="z", tiebreak="shortest",
                  min_quality=MIN_QUALITY):
    r"""Widest paths in the maximin-bottleneck sense, from each entry face to the outlet.

    The width of a path is that of its narrowest interior face (open area, Eq. 3.23); the
    maximin path maximises it. Every maximin path between two nodes lies in a maximum spanning
    tree, so one Kruskal tree of the face graph (plus a virtual node joined to all end faces,
    see :func:`shortest_paths`) serves all entries. Hull faces do not count in the bottleneck.

    Parameters
    ----------
    graph : FaceGraph
    entry_face : (n,) array_like of int
    axis : {'x', 'y', 'z'}
    tiebreak : {'shortest', 'tree'}
        ``'tree'``: the path in the spanning tree (for distinct areas, the lexicographically
        widest one: it may wander). ``'shortest'`` (default): the shortest path among all
        paths whose narrowest face is at least the maximin bottleneck (one Dijkstra run per
        distinct bottleneck value).
    min_quality : float, optional
        Slivers not entered, see :func:`passable_pores`.

    Returns
    -------
    faces : list of int ndarrays
    ok : (n,) bool ndarray
    bottleneck_m2 : (n,) ndarray
        Maximin open area of each entry (NaN where not connected).
    """
    if tiebreak not in ("shortest", "tree"):
        raise ValueError(f"tiebreak must be 'shortest' or 'tree', got {tiebreak!r}")
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    out, usable, pore_ok = _graph_setup(graph, ax, f0, entry_pore, min_quality)
    nt = graph.n_throats
    amax = float(graph.throat_open_area.max())
    w = np.where(graph.hull_mask(), 2.0 * amax, graph.throat_open_area)  # node widths
    e = _face_edges(graph, usable, pore_ok)
    ew = np.minimum(w[e[:, 0]], w[e[:, 1]])
    cost = 3.0 * amax - ew  # > 0; minimum tree of cost = maximum tree of width
    rows = np.concatenate([e[:, 0], np.full(out.size, nt)])
    cols = np.concatenate([e[:, 1], out])
    vals = np.concatenate([cost, np.full(out.size, 1e-6 * amax)])
    g = sparse.csr_array((vals, (rows, cols)), shape=(nt + 1, nt + 1))
    tree = csgraph.minimum_spanning_tree(g)
    _, pred = csgraph.breadth_first_order(tree, nt, directed=False, return_predecessors=True)
    faces, ok = _follow(pred, f0, nt)
    bott = np.array([w[f].min() if okk and f.size else np.nan for f, okk in zip(faces, ok)])
    if tiebreak == "tree":
        return faces, ok, bott
    c = graph.throat_centroid
    length = np.maximum(np.linalg.norm(c[e[:, 0]] - c[e[:, 1]], axis=1),
                        1e-9 * graph.mean_diameter)
    for b in np.unique(bott[ok]):  # one Dijkstra per distinct bottleneck value
        keep = ew >= b
        gb = sparse.csr_array(
            (np.concatenate([length[keep], np.full(out.size, 1e-9 * graph.mean_diameter)]),
             (np.concatenate([e[keep, 0], np.full(out.size, nt)]),
              np.concatenate([e[keep, 1], out]))),
            shape=(nt + 1, nt + 1))
        _, pb = csgraph.dijkstra(gb, directed=False, indices=nt, return_predecessors=True)
        idx = np.flatnonzero(ok & (bott == b))
        fb, okb = _follow(pb, f0[idx], nt)
        for i, f, k in zip(idx, fb, okb):
            if k:
                faces[i] = f
    return faces, ok, bott


def trace_paths(points, radii, entry_xy, *, kind="widest", method="build", graph=None,
                axis="z", depth_m=None, tiebreak="shortest", angle_rule="eq3.25",
                min_quality=MIN_QUALITY):
    """Trace paths of one kind from entry points on the floor; list of :class:`AirflowPath`.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    entry_xy : (n, 2) array_like, m
        Entry points in the plane normal to ``axis`` (the other two axes in x, y, z order).
    kind : {'widest', 'narrowest', 'maximin', 'shortest'}
    method : {'build', 'delaunay'}
        For 'widest'/'narrowest': the thesis's construction (:func:`build_paths`, default) or
        the step-increment rule walked on the tessellation (:func:`walk_paths`).
        'maximin' and 'shortest' always use the tessellation.
    graph : FaceGraph, optional
        Needed unless ``kind`` is built (see :func:`face_graph`).
    axis : {'x', 'y', 'z'}
    depth_m : float, optional
        Bed depth for the tortuosity; default :func:`bed_depth`.
    tiebreak : {'shortest', 'tree'}
        For ``'maximin'``, see :func:`maximin_paths`.
    angle_rule : {'eq3.25', 'appendix-d'}
        Angle rule of the smoothed length, see :func:`interior_angles`.
    min_quality : float
        Slivers not entered on the tessellation, see :func:`passable_pores`.
    """
    if kind not in PATH_KINDS:
        raise ValueError(f"unknown path kind {kind!r}; expected one of {PATH_KINDS}")
    if method not in ("build", "delaunay"):
        raise ValueError(f"unknown method {method!r}; expected 'build' or 'delaunay'")
    x = _as_points(points)
    r = np.asarray(radii, dtype=float)
    xy = np.atleast_2d(np.asarray(entry_xy, dtype=float))
    depth = bed_depth(x, r, axis) if depth_m is None else float(depth_m)
    if kind in ("widest", "narrowest") and method == "build":
        return build_paths(x, r, xy, kind=kind, axis=axis, depth_m=depth, angle_rule=angle_rule)
    if not isinstance(graph, FaceGraph):
        raise TypeError(f"kind {kind!r} with method {method!r} needs graph=FaceGraph")
    f0, p0 = entry_faces(graph, xy, axis=axis, min_quality=min_quality)
    n = f0.size
    relaxed = back = np.zeros(n, dtype=int)
    if kind in ("widest", "narrowest"):
        faces, status, relaxed, back = walk_paths(graph, f0, p0, kind=kind, axis=axis,
                                                  min_quality=min_quality)
        label = "delaunay"
    else:
        if kind == "shortest":
            faces, ok = shortest_paths(graph, f0, p0, axis=axis, min_quality=min_quality)
        else:
            faces, ok, _ = maximin_paths(graph, f0, p0, axis=axis, tiebreak=tiebreak,
                                         min_quality=min_quality)
        status = np.where(ok, "ok", "stuck")
        label = "graph"
    out = []
    for i in range(n):  # one record per path
        f = faces[i] if status[i] == "ok" else faces[i][:1]
        tetra, exit_local, pores = _faces_to_tetra(graph, f)
        out.append(_path_record(x, r, kind, label, xy[i], axis, str(status[i]), tetra,
                                exit_local, depth, pores=pores, n_relaxed=relaxed[i],
                                n_back=back[i], angle_rule=angle_rule,
                                exit_open_m2=graph.throat_open_area[f[1:]]))
    return out


# --------------------------------------------------------------------------------------------
# models evaluated along a path
# --------------------------------------------------------------------------------------------
def branched_path_pressure_drop(points, radii, path, *, superficial_velocity_m_s=None,
                                q0_m3_s=None, width="average", multiplier="MFx3",
                                branches="path", mu_pa_s=MU_AIR_PA_S) -> BranchedResult:
    r"""Branched-path model (thesis 3.5.1, Appendix F) along the tetrahedra of a path.

    Each tetrahedron is entered through its inlet face (``path.tetra_vertices[:, :3]``) and
    divides into its three other faces. The flow entering each tetrahedron is
    :math:`Q_0 = U S_0`, with :math:`U` the superficial velocity and :math:`S_0` the mean
    triangle area of the path's faces (Appendix F uses a constant
    :math:`S_0` = 17.613 mm², about the mean face area of a 6.5 mm packing), unless
    ``q0_m3_s`` is given.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    path : AirflowPath
    superficial_velocity_m_s : float, optional
    q0_m3_s : float, optional
        Overrides :math:`Q_0`.
    width : {'min', 'max', 'average'}
        Local flow-path width, see :func:`network._branched.local_width`.
    multiplier : {'MFx3', 'MFx2'}
    branches : {'all', 'path'}
        See :func:`network._branched.branched_pressure_drop`.
    mu_pa_s : float

    Returns
    -------
    BranchedResult
    """
    x = _as_points(points)
    tet = path.tetra_vertices
    if tet.shape[0] == 0:
        raise ValueError("path has no tetrahedra")
    faces = np.concatenate([tet[:, None, :3], tet[:, EXIT_FACES]], axis=1)  # (m, 4, 3)
    full, opened = face_areas(x, radii, faces)
    d = local_width(full, np.nan_to_num(opened, nan=0.0), width)
    cent = x[faces].mean(axis=2)  # (m, 4, 3)
    if q0_m3_s is None:
        if superficial_velocity_m_s is None:
            raise ValueError("give superficial_velocity_m_s or q0_m3_s")
        q0_m3_s = float(superficial_velocity_m_s) * float(np.mean(full))
    return branched_pressure_drop(cent[:, 0], x[tet].mean(axis=1), cent[:, 1:], d[:, 0],
                                  d[:, 1:], path.exit_local, q0_m3_s, multiplier=multiplier,
                                  branches=branches, mu_pa_s=mu_pa_s)


def pore_pressure_array(n_pores, pore_ids, pressure_pa, labels=None):
    """Pressure of every tetrahedron from a network solution over a sample, (Np,) Pa.

    Parameters
    ----------
    n_pores : int
        Tetrahedra of the tessellation.
    pore_ids : (Ns,) int array_like
        Pore-body ids of the solved pores (``FlowResult.pore_ids``): tetrahedron ids, or group
        labels when tied tetrahedra were merged.
    pressure_pa : (Ns,) array_like, Pa
        Their pressures (``FlowResult.pressure_pa``).
    labels : (Np,) int array_like, optional
        Group label of each tetrahedron (``network.tie_groups``); None when not merged.

    Returns
    -------
    (Np,) ndarray, Pa; NaN outside the sample.
    """
    ids = np.asarray(pore_ids, dtype=np.intp)
    pr = np.asarray(pressure_pa, dtype=float)
    lab = np.arange(n_pores) if labels is None else np.asarray(labels, dtype=np.intp)
    body = np.full(max(int(lab.max()) + 1, int(ids.max()) + 1 if ids.size else 0), np.nan)
    body[ids] = pr
    return body[lab]


def pressure_along_path(graph, path, pore_pressure_pa, *, axis="z"):
    """Pressure of each tetrahedron on a Delaunay path, from a network solution (thesis 4.2.3).

    Parameters
    ----------
    graph : FaceGraph
    path : AirflowPath
        A path on the tessellation (method 'delaunay' or 'graph').
    pore_pressure_pa : (Np,) array_like, Pa
        Pressure per pore (NaN where the solver left a pore out).

    Returns
    -------
    position_m : (n,) ndarray, m
        Tetrahedron centroid coordinate along ``axis``.
    pressure_pa : (n,) ndarray, Pa
    """
    p = np.asarray(pore_pressure_pa, dtype=float)
    if p.shape != (graph.n_pores,):
        raise ValueError(f"pore_pressure_pa must have shape ({graph.n_pores},), got {p.shape}")
    if np.any(path.pores < 0):
        raise ValueError("the path is not on the tessellation (method 'build'); trace it with "
                         "method='delaunay' or kind 'maximin'/'shortest'")
    ax = axis_index(axis)
    pos = graph.points[graph.pore_vertices[path.pores]].mean(axis=1)[:, ax]
    return pos, p[path.pores]


def branched_table(points, radii, path, *, velocities_m_s=(0.013, 0.027),
                   widths=("max", "min", "average"), multipliers=("MFx3", "MFx2"),
                   branches="path", mu_pa_s=MU_AIR_PA_S):
    """Branched-model pressure drops of one path in the layout of thesis Table 4.4, Pa.

    Face areas are computed once and reused for every combination.

    Returns
    -------
    dict
        ``table[width][multiplier][f"{velocity:g}"] -> float`` (Pa), plus ``"q0_per_u_m2"``
        (the :math:`S_0` that multiplies the velocity) and ``"branches"``.
    """
    x = _as_points(points)
    tet = path.tetra_vertices
    if tet.shape[0] == 0:
        raise ValueError("path has no tetrahedra")
    faces = np.concatenate([tet[:, None, :3], tet[:, EXIT_FACES]], axis=1)
    full, opened = face_areas(x, radii, faces)
    opened = np.nan_to_num(opened, nan=0.0)
    cent = x[faces].mean(axis=2)
    c_tet = x[tet].mean(axis=1)
    s0 = float(np.mean(full))
    out = {"q0_per_u_m2": s0, "branches": branches}
    for w in widths:
        d = local_width(full, opened, w)
        out[w] = {}
        for m in multipliers:
            out[w][m] = {}
            for u in velocities_m_s:
                res = branched_pressure_drop(cent[:, 0], c_tet, cent[:, 1:], d[:, 0], d[:, 1:],
                                             path.exit_local, float(u) * s0, multiplier=m,
                                             branches=branches, mu_pa_s=mu_pa_s)
                out[w][m][f"{u:g}"] = res.total_pa
    return out


def _relaxed_packing(box_m, *, porosity=0.408, d_range_m=(5.5e-3, 7.5e-3), n=None,
                     iters=1500, rng=None):
    """Geometric stand-in packing: random spheres pushed apart until overlaps are small.

    Not a DEM packing (no gravity, no friction): ``n`` spheres (default: as many as give
    ``porosity`` in the box) with uniform diameters in ``d_range_m`` start at random
    positions at 60 % of their size, grow to full size over the first 60 % of ``iters`` while
    every overlapping pair (``cKDTree.query_pairs``) is pushed apart by 0.8 x half its overlap
    and centres are kept a radius from the walls. For the rect-bin box
    (0.25 x 0.02 x 0.25 m, 5027 spheres) 1500 iterations leave a mean overlap of 1.5 % of
    the mean diameter (max 10 %), in about 6 s.

    Returns
    -------
    centers (N, 3) m, radii (N,) m
    """
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(rng)
    box = np.asarray(box_m, dtype=float)
    d0, d1 = d_range_m
    if n is None:
        mean_vol = np.pi / 6.0 * (d1**4 - d0**4) / (4.0 * (d1 - d0))
        n = int(round((1.0 - porosity) * box.prod() / mean_vol))
    r = rng.uniform(d0 / 2, d1 / 2, size=n)
    x = rng.uniform(0.0, 1.0, (n, 3)) * box
    for it in range(iters):  # relaxation sweeps, not a loop over spheres
        rs = r * min(1.0, 0.6 + 0.4 * it / (0.6 * iters))
        x = np.clip(x, rs[:, None], box - rs[:, None])
        pr = cKDTree(x).query_pairs(2 * rs.max(), output_type="ndarray")
        d = x[pr[:, 1]] - x[pr[:, 0]]
        dist = np.linalg.norm(d, axis=1)
        ov = rs[pr[:, 0]] + rs[pr[:, 1]] - dist
        m = ov > 0
        pr, d, dist, ov = pr[m], d[m], dist[m], ov[m]
        u = d / np.maximum(dist, 1e-12)[:, None]
        disp = np.zeros_like(x)
        np.add.at(disp, pr[:, 0], -0.5 * ov[:, None] * u)
        np.add.at(disp, pr[:, 1], 0.5 * ov[:, None] * u)
        x += 0.8 * disp
    x = np.clip(x, r[:, None], box - r[:, None])
    return x, r
