"""The face graph of a tessellation: tetrahedra (pores), their faces (throats), face open areas
and normals, sliver tetrahedra that paths do not enter, and where paths start and end.

On the tessellation, slivers (flat tetrahedra, mostly in the grain layer against flat walls)
are not entered (:func:`passable_pores`), and paths run from an enterable tetrahedron near the
floor to one near the top (:data:`END_BAND_DIAMETERS`).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import sparse
from throats import open_area  # the throats package owns the exact open area

from .._deferred import csgraph
from ..pores import axis_index
from ._geometry import plane_axes


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


def path_ends(graph, ax, passable):
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
    plane = plane_axes(ax)
    c = np.asarray(centers, dtype=float)
    lo = c[:, plane].min(axis=0)
    hi = c[:, plane].max(axis=0)
    m = 4.0 * float(np.mean(radii)) if margin_m is None else float(margin_m)
    m = np.minimum(m, 0.25 * (hi - lo))
    return rng.uniform(lo + m, hi - m, size=(int(n), 2))


class NoPathError(ValueError):
    """No enterable tetrahedron near the floor connects to the top: the packing has no path
    along the axis, an input fault (``bad_input``: exit 2 in a CLI)."""

    bad_input = True


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
    low, high, bottom, _, pc = path_ends(graph, ax, passable)
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
        raise NoPathError(
            f"no air path through the bed along {'xyz'[ax]}: no enterable tetrahedron within "
            f"{END_BAND_DIAMETERS:g} mean diameters of the floor opens onto the top through "
            f"open faces ({graph.n_pores} tetrahedra: a bed too small or too loose for a path?"
            + ("" if min_quality == MIN_QUALITY else f"; min_quality {min_quality:g} too high?")
            + ")")
    plane = plane_axes(ax)
    cc = graph.points[graph.pore_vertices[cand]].mean(axis=1)
    lo = graph.points[:, ax].min()
    out = np.empty(xy.shape[0], dtype=np.intp)
    for i0 in range(0, xy.shape[0], 256):  # chunks keep the (n, F) arrays small
        d2 = (np.sum((cc[None, :, plane] - xy[i0:i0 + 256, None]) ** 2, axis=2)
              + (pc[cand] - lo)[None] ** 2)
        out[i0:i0 + 256] = cand[np.argmin(d2, axis=1)]
    return bottom[out], out

