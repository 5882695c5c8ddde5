r"""Delaunay tessellation of a packing: pores (tetrahedra) and throats (their faces).

Pores are the Delaunay tetrahedra of the sphere centres (thesis 3.5.2.2); throats are the
triangular faces, each listed once: a face shared by two tetrahedra connects them, a face on
the convex hull has ``-1`` as its second pore. The tetrahedra come from gmsh's Delaunay kernel,
completed at the hull and checked, or from Qhull where that check fails (``_delaunay``).

Degenerate input
----------------
Exact lattices (simple cubic, FCC) have groups of more than four co-spherical centres, so
their Delaunay tessellation is not unique. Qhull is run with ``Qbb Qc Qz Q12``: ``Qz`` adds a
point at infinity, which keeps co-spherical input from failing; ``Qbb`` scales the last
coordinate; ``Qc`` keeps coplanar points; ``Q12`` allows wide facets from nearly flat
(sliver) simplices. Qhull then triangulates every co-spherical group in some valid way, and
the choice depends on point order and rounding. Every valid choice tiles the same convex
hull, so pore volumes always sum to the hull volume to round-off (tested). Ties are detected
relative to the mean sphere diameter :math:`\bar d`: a tetrahedron is *flat* when its
volume is below ``flat_tol`` :math:`\bar d^3` (default 1e-6) and two neighbouring tetrahedra are
*co-spherical* when their circumcentres differ by less than ``tie_tol`` :math:`\bar d`
(default 1e-6). These flags are returned, and :func:`tie_groups` joins every exactly tied
group into one pore body, so that the network does not depend on Qhull's tie-breaking
(merging *nearly* co-spherical groups, with a tolerance meant for jittered lattices and real
packings, is the conduit model's ``network._merge``).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
import scipy.sparse as sp

from .._deferred import beside, csgraph
from ..packing import Packing
from ._delaunay import ENGINES, FACES, QHULL_OPTIONS, delaunay
from ._simplex import CHUNK, circumcentres, column_norm, cross_components, pair_distances

__all__ = ["ENGINES", "Tessellation", "tessellate", "QHULL_OPTIONS", "tie_groups"]

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class Tessellation:
    """Pores and throats of a packing's Delaunay tessellation.

    Attributes
    ----------
    packing : Packing
        The packing tessellated (centres in m, radii in m).
    pore_vertices : (Np, 4) int ndarray
        Sphere indices of each tetrahedron.
    pore_neighbors : (Np, 4) int ndarray
        Neighbouring pore across the face opposite vertex k, -1 on the hull.
    pore_throats : (Np, 4) int ndarray
        Throat index of the face opposite vertex k.
    pore_centroid : (Np, 3) ndarray, m
        Mean of the four vertices.
    pore_volume : (Np,) ndarray, m³
        Tetrahedron volume.
    pore_circumcenter : (Np, 3) ndarray, m
        Circumsphere centre (NaN for flat tetrahedra).
    throat_pores : (Nt, 2) int ndarray
        The two pores a throat connects, lower index first; second is -1 for a hull face.
    throat_vertices : (Nt, 3) int ndarray
        Sphere indices of the face, ascending.
    throat_radii : (Nt, 3) ndarray, m
        Radii [r1, r2, r3] of ``throat_vertices``.
    throat_sides : (Nt, 3) ndarray, m
        Side lengths [l12, l13, l23].
    throat_area : (Nt,) ndarray, m²
        Area of the triangle (not the open area).
    throat_centroid : (Nt, 3) ndarray, m
        Mean of the three vertices.
    pore_flat : (Np,) bool ndarray
        Volume below ``flat_tol`` d̄³ (a sliver).
    throat_tied : (Nt,) bool ndarray
        Interior face whose two tetrahedra share a circumsphere to ``tie_tol`` d̄ (a face
        that exists only because of how Qhull broke a tie).
    coplanar_points : (K,) int ndarray
        Spheres Qhull left out of every tetrahedron (coincident or nearly so with another).
    """

    packing: Packing
    pore_vertices: np.ndarray
    pore_neighbors: np.ndarray
    pore_throats: np.ndarray
    pore_centroid: np.ndarray
    pore_volume: np.ndarray
    pore_circumcenter: np.ndarray
    throat_pores: np.ndarray
    throat_vertices: np.ndarray
    throat_radii: np.ndarray
    throat_sides: np.ndarray
    throat_area: np.ndarray
    throat_centroid: np.ndarray
    pore_flat: np.ndarray
    throat_tied: np.ndarray
    coplanar_points: np.ndarray

    def __post_init__(self):
        np_, nt = self.pore_vertices.shape[0], self.throat_vertices.shape[0]
        shapes = {
            "pore_vertices": (np_, 4), "pore_neighbors": (np_, 4), "pore_throats": (np_, 4),
            "pore_centroid": (np_, 3), "pore_volume": (np_,), "pore_circumcenter": (np_, 3),
            "throat_pores": (nt, 2), "throat_radii": (nt, 3), "throat_sides": (nt, 3),
            "throat_area": (nt,), "throat_centroid": (nt, 3), "pore_flat": (np_,),
            "throat_tied": (nt,),
        }
        for name, shape in shapes.items():
            got = getattr(self, name).shape
            if got != shape:
                raise ValueError(f"Tessellation.{name} must have shape {shape}, got {got}")

    @property
    def n_pores(self) -> int:
        return int(self.pore_vertices.shape[0])

    @property
    def n_throats(self) -> int:
        return int(self.throat_vertices.shape[0])

    def outside_bed(self, diameters: float = 2.0) -> np.ndarray:
        """(Np,) bool: tetrahedra whose empty sphere is wider than ``diameters`` mean diameters.

        A packed bed has no void that wide (radius of the circumsphere through the four
        centres, so an empty sphere of radius ``diameters * d - r`` between grains): these are
        convex-hull artefacts along walls, free surfaces and open sides, flat tetrahedra with
        huge windows, since the tessellation has no walls. Flat tetrahedra (NaN circumcentre)
        are not flagged.
        """
        circ_r = np.linalg.norm(self.pore_circumcenter
                                - self.packing.centers[self.pore_vertices[:, 0]], axis=1)
        return circ_r > float(diameters) * self.packing.grain_diameter

    def solid_pores(self) -> np.ndarray:
        """(Np,) bool: tetrahedra inside one grain, solid rather than pore space.

        With multi-sphere grains (``packing.grain_id``) a tetrahedron whose four spheres all
        belong to one grain and whose centroid lies inside one of those spheres is inside the
        grain: the spheres of a grain overlap heavily, so its tetrahedra are (nearly) all solid.
        A tetrahedron spanning two grains, or one grain's spheres around a void (a concave
        grain), stays a pore. Without grains: none.
        """
        if self.packing.grain_id is None:
            return np.zeros(self.n_pores, dtype=bool)
        g = self.packing.grain_id[self.pore_vertices]                     # (Np, 4)
        one = np.all(g == g[:, :1], axis=1)
        c = self.packing.centers[self.pore_vertices[one]]                   # (m, 4, 3)
        r = self.packing.radii[self.pore_vertices[one]]
        d2 = np.sum((self.pore_centroid[one][:, None] - c) ** 2, axis=2)
        solid = np.zeros(self.n_pores, dtype=bool)
        solid[one] = np.any(d2 < r**2, axis=1)
        return solid

    @property
    def interior_throats(self) -> np.ndarray:
        """Indices of throats shared by two pores (not on the hull)."""
        return np.flatnonzero(self.throat_pores[:, 1] >= 0)


def _pore_geometry(pts, simp):
    """Centroids (N, 3), volumes (N,) and circumcentres (N, 3) of the tetrahedra ``simp`` of
    ``pts`` (:func:`circumcentres`, V = |D| / 6; the centroid summed in the order of
    ``mean(axis=1)``), in chunks so that the (3, chunk, 4) temporaries stay small."""
    n_p = simp.shape[0]
    centroid = np.empty((n_p, 3))
    volume = np.empty(n_p)
    circ = np.empty((n_p, 3))
    for a in range(0, n_p, CHUNK):
        b = min(a + CHUNK, n_p)
        s = simp[a:b]
        centroid[a:b] = (((pts[s[:, 0]] + pts[s[:, 1]]) + pts[s[:, 2]]) + pts[s[:, 3]]) / 4.0
        circ[a:b], det = circumcentres(pts, s)
        volume[a:b] = np.abs(det) / 6.0
    return centroid, volume, circ


def _local_frame(centers):
    """Centres to tessellate and the origin to add back (None: used as given).

    Coordinates far from the origin (site coordinates, an offset of 1e6 m) lose digits in
    Qhull and in the circumcentres; when the packing's bounding-box centre lies farther from
    the origin than the packing is wide, the points are shifted to it. A packing near the
    origin is tessellated as given, so its results do not move by a rounding.
    """
    lo, hi = centers.min(axis=0), centers.max(axis=0)
    mid = 0.5 * (lo + hi)
    if np.max(np.abs(mid)) <= np.max(hi - lo):
        return centers, None
    return centers - mid, mid


def tessellate(packing: Packing, *, qhull_options: str = QHULL_OPTIONS,
               flat_tol: float = 1e-6, tie_tol: float = 1e-6, threads: int = 1,
               engine: str = "auto") -> Tessellation:
    r"""Delaunay tessellation of the sphere centres into pores and throats.

    Parameters
    ----------
    packing : Packing
        Sphere centres (N, 3) m and radii (N,) m.
    qhull_options : str, optional
        Options for ``scipy.spatial.Delaunay`` where Qhull runs (default ``"Qbb Qc Qz Q12"``).
    engine : {'auto', 'gmsh', 'qhull'}, optional
        'gmsh': gmsh's Delaunay kernel, completed at the hull and checked, Qhull where the
        check fails (``network.pores._delaunay``; the same tetrahedra for centres in general
        position; 0.38 against 0.57-0.81 s at 20 000 centres, 25 against 82 s at 1e6);
        'auto' (default): that from 4 000 centres, Qhull below; 'qhull': Qhull only.
    flat_tol : float, optional
        A tetrahedron with volume < ``flat_tol`` :math:`\bar d^3` is flagged flat (default 1e-6).
    tie_tol : float, optional
        Interior faces whose two circumcentres are closer than ``tie_tol`` :math:`\bar d` are
        flagged tied (default 1e-6).
    threads : int, optional
        2 or more: the pore geometry (centroids, volumes, circumcentres) on a second thread
        beside the faces (numpy releases the GIL; the same bits), and the gmsh check's convex
        hull beside gmsh (default 1).

    Returns
    -------
    Tessellation

    Raises
    ------
    TypeError
        ``packing`` is not a :class:`Packing`.
    ValueError
        All centres are coplanar, or Qhull fails otherwise (its message is chained).

    Notes
    -----
    Faces are read from the neighbour table: face *k* of tetrahedron *t* is opposite its
    vertex *k* and is kept once, by the tetrahedron with the lower index (or by *t* when the
    face is on the hull). This is equivalent to sorting the 4 N faces and taking unique rows,
    in O(N) instead of O(N log N). Side lengths follow the contract order
    :math:`[l_{12}, l_{13}, l_{23}]` of the ascending vertex triple.

    Examples
    --------
    A triangle with one apex above and one below is two tetrahedra sharing one throat, plus
    six hull faces:

    >>> import numpy as np
    >>> from network import Packing, tessellate
    >>> c = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [.3, .3, 1], [.3, .3, -1]])
    >>> t = tessellate(Packing(c, np.full(5, 0.4)))
    >>> t.n_pores, t.n_throats, int((t.throat_pores[:, 1] >= 0).sum())
    (2, 7, 1)
    """
    if not isinstance(packing, Packing):
        raise TypeError(f"packing must be a Packing, got {type(packing).__name__}")
    pts, origin = _local_frame(packing.centers)
    simp, neigh, used = delaunay(pts, engine=engine, qhull_options=qhull_options,
                                 threads=threads)
    n_p = simp.shape[0]
    dbar = packing.mean_diameter
    if threads > 1:
        pores = beside(_pore_geometry, pts, simp)
    else:
        pores = None
        centroid, volume, circ = _pore_geometry(pts, simp)

    # throats: face k of t kept when t < neighbour or neighbour is -1
    nb = neigh.ravel()
    keep = nb < 0
    keep |= np.repeat(np.arange(n_p), 4) < nb
    slots = np.flatnonzero(keep)
    del keep
    ft, fk = np.divmod(slots, 4)
    fn = nb[slots]
    n_t = slots.size
    tv = np.empty((n_t, 3), dtype=np.int64)
    # ascending rows (gmsh's, sorted by the engine) give ascending faces as they stand
    ascending = bool(np.all(simp[:, :-1] < simp[:, 1:]))
    for a in range(0, n_t, CHUNK):
        b = min(a + CHUNK, n_t)
        tv[a:b] = simp[ft[a:b, None], FACES[fk[a:b]]]
        if not ascending:
            tv[a:b].sort(axis=1)
    del fk
    # throat id of every (pore, face) slot
    tid = np.full(n_p * 4, -1, dtype=np.int64)
    tid[slots] = np.arange(n_t)
    del slots
    # the other side of each interior face: find k' with neigh[fn, k'] == ft
    inner = fn >= 0
    inner_idx = np.flatnonzero(inner)
    for a in range(0, inner_idx.size, CHUNK):
        j = inner_idx[a:a + CHUNK]
        other_k = np.argmax(neigh[fn[j]] == ft[j, None], axis=1)
        tid[fn[j] * 4 + other_k] = j
    pore_throats = tid.reshape(n_p, 4)
    throat_pores = np.column_stack([ft, fn])

    r = packing.radii[tv]
    sides = np.empty((n_t, 3))
    area = np.empty(n_t)
    tcent = np.empty((n_t, 3))
    for a in range(0, n_t, CHUNK):
        b = min(a + CHUNK, n_t)
        x = pts.T[:, tv[a:b].T]                  # (3 components, 3 vertices, m): contiguous
        p0, p1, p2 = x[:, 0], x[:, 1], x[:, 2]
        e1, e2, e3 = p1 - p0, p2 - p0, p2 - p1
        for k, e in enumerate((e1, e2, e3)):
            sides[a:b, k] = column_norm(e)
        area[a:b] = 0.5 * column_norm(cross_components(e1, e2))
        tcent[a:b] = ((p0 + p1 + p2) / 3.0).T
    if pores is not None:
        centroid, volume, circ = pores.result()
    flat = volume < flat_tol * dbar**3
    tied = np.zeros(n_t, dtype=bool)
    p_in, q_in = ft[inner], fn[inner]                # the two pores of each interior face
    circ_c = np.ascontiguousarray(circ.T)            # component rows: contiguous gathers
    tie = pair_distances(circ_c, p_in, circ_c, q_in) < tie_tol * dbar   # NaN: False
    tied[inner] = tie | flat[p_in] | flat[q_in]

    in_simplex = np.zeros(packing.n, dtype=bool)
    in_simplex[simp.ravel()] = True
    coplanar = np.flatnonzero(~in_simplex)
    if coplanar.size:
        log.warning("%d sphere(s) are in no tetrahedron (coincident with another centre to "
                    "Qhull precision)", coplanar.size)
    log.info("tessellated %d spheres (%s): %d pores (%d flat), %d throats (%d on the hull, "
             "%d tied)", packing.n, used, n_p, int(flat.sum()), n_t, int((~inner).sum()),
             int(tied.sum()))
    if origin is not None:
        centroid += origin
        circ += origin
        tcent += origin
    return Tessellation(
        packing=packing, pore_vertices=simp, pore_neighbors=neigh, pore_throats=pore_throats,
        pore_centroid=centroid, pore_volume=volume, pore_circumcenter=circ,
        throat_pores=throat_pores, throat_vertices=tv, throat_radii=r,
        throat_sides=sides, throat_area=area,
        throat_centroid=tcent, pore_flat=flat, throat_tied=tied,
        coplanar_points=coplanar)


def tie_groups(tessellation: Tessellation) -> tuple[np.ndarray, int]:
    """Pore bodies that join tetrahedra whose split is only Qhull's tie-breaking.

    Two neighbouring tetrahedra join when their circumcentres coincide to ``tie_tol`` d̄ (both
    non-flat): a co-spherical group such as the 8 corners of a simple-cubic cell or an FCC
    octahedral hole. A flat tetrahedron (sliver, e.g. four coplanar corners of a cube face)
    joins exactly one neighbour, the one across its largest face (a non-flat one when it has
    any): joining it to both sides would fuse two different voids. Either side gives the same
    network by symmetry, and the sliver's remaining faces become the throats of that link.

    Returns
    -------
    labels : (Np,) int ndarray
        Group of every tetrahedron (0 .. n_groups-1); random packings give the identity up to
        renumbering (no exact ties).
    n_groups : int
    """
    t = tessellation
    n = t.n_pores
    flat = t.pore_flat
    tp = t.throat_pores
    tied = t.throat_tied & (tp[:, 1] >= 0)
    both_round = tied & ~flat[tp[:, 0]] & ~flat[np.maximum(tp[:, 1], 0)]
    e = [tp[both_round]]
    fl = np.flatnonzero(flat)
    if fl.size:
        nb = t.pore_neighbors[fl]                                # (F, 4)
        area = t.throat_area[t.pore_throats[fl]]
        valid = nb >= 0
        round_nb = valid & ~flat[np.maximum(nb, 0)]
        # prefer non-flat neighbours, then larger faces
        score = (np.where(round_nb, 2.0, np.where(valid, 1.0, 0.0))
                 * (1.0 + area / (area.max() + 1e-300)))
        pick = np.argmax(score, axis=1)
        chosen = nb[np.arange(fl.size), pick]
        ok = chosen >= 0
        e.append(np.column_stack([fl[ok], chosen[ok]]))
    edges = np.vstack(e) if e else np.zeros((0, 2), dtype=np.int64)
    adj = sp.coo_array((np.ones(edges.shape[0]), (edges[:, 0], edges[:, 1])), shape=(n, n))
    n_groups, labels = csgraph.connected_components(adj, directed=False)
    if n_groups < n:
        log.info("joined %d tied/flat tetrahedra into %d pore bodies (%d pores remain)",
                 n - n_groups + int((np.bincount(labels) > 1).sum()),
                 int((np.bincount(labels) > 1).sum()), n_groups)
    return labels.astype(np.int64), int(n_groups)
