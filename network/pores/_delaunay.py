r"""3-D Delaunay tetrahedra and their neighbour table: gmsh's kernel, completed and checked.

``gmsh.algorithm.tetrahedralize`` (gmsh's Bowyer-Watson kernel, robust predicates) takes 0.23 s
for the 20 000 centres of the bench packing, Qhull (a 4-D convex hull) 0.6-0.8 s; 2.8 against
11 s at 180 000. But gmsh triangulates inside a box of its own and drops the tetrahedra
attached to it: Delaunay tetrahedra at the hull whose circumsphere reaches a box corner are
missing (1 623 of 124 367 there, all within 0.8 d̄ of the bed's edge). They are put back:

* the *gap* (the hull minus gmsh's tetrahedra) is bounded by gmsh's unmatched faces, and every
  vertex of a missing tetrahedron is a vertex of one (a vertex's star is face-connected): the
  set S (721 of the 20 000);
* a Delaunay tetrahedron of the centres with vertices in S is one of S, so Qhull on S (8 ms)
  tiles the hull with tetrahedra among which the missing ones tile the gap: a flood fill over
  Qhull's neighbours that never crosses gmsh's unmatched faces, seeded across those faces
  (filtered orientation against gmsh's apex), collects them.

Checked before use: no two centres equal, every centre in a tetrahedron, no face in three
tetrahedra, the volumes summing to the convex hull's to 1e-9, the unmatched faces on the hull
(vertices on it, areas summing to its area; with ``threads`` > 1 Qhull's hull is computed on
a thread beside gmsh, after SciPy's deferred modules, ``network._deferred``). A failed check, a
side too flat to tell, over 2**21 centres or a gmsh error sends the input to Qhull
(``engine='qhull'``, the reference).
Centres in general position give Qhull's tetrahedra exactly (tested); co-spherical groups
(lattices, tiled copies) get another valid triangulation, which ``tie_groups`` joins.
"""

from __future__ import annotations

import logging
import threading

import numpy as np
import scipy.sparse as sp

from .._deferred import beside, csgraph, import_now, spatial
from ..packing import DegeneratePackingError, check_three_dimensional
from ._simplex import CHUNK, column_norm, cross_components, edge_determinants

__all__ = ["ENGINES", "FACES", "GMSH_MIN_CENTRES", "QHULL_OPTIONS", "delaunay"]

log = logging.getLogger(__name__)

#: Qhull options used for the 3-D Delaunay tessellation (see ``_tessellation``'s docstring).
QHULL_OPTIONS = "Qbb Qc Qz Q12"
#: 'auto': gmsh's kernel checked and completed (Qhull when the check fails or for fewer than
#: GMSH_MIN_CENTRES centres); 'gmsh': the same at any size; 'qhull' only
ENGINES = ("auto", "gmsh", "qhull")
#: below this many centres Qhull is as fast as gmsh with its import and checks (fresh process:
#: 0.05 against 0.02 s at 1 000 centres, even at 3 000-5 000, 0.38 against 0.76 s at 20 000)
GMSH_MIN_CENTRES = 4000
#: vertices of face k of a tetrahedron: the face opposite vertex k (scipy's ``neighbors``
#: convention)
FACES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
# relative tolerance of the volume and area checks
_VOLUME_TOL = 1e-9
_GMSH_LOCK = threading.Lock()


class _Unchecked(Exception):
    """gmsh's tetrahedra could not be completed and checked: use Qhull."""


def delaunay(pts: np.ndarray, *, engine: str = "auto", qhull_options: str = QHULL_OPTIONS,
             threads: int = 1) -> tuple[np.ndarray, np.ndarray, str]:
    """Delaunay tetrahedra of the points ``pts`` (N, 3) and their neighbours.

    Returns ``(simplices (Nt, 4) int64, neighbors (Nt, 4) int64, engine used)``: neighbour k of
    tetrahedron t is the one across the face opposite vertex k, -1 on the convex hull.
    ``threads`` > 1: gmsh's check computes its convex hull on a second thread while gmsh runs.
    Raises :class:`~network.packing.DegeneratePackingError` (a ``ValueError``) when Qhull fails:
    the centres coplanar or collinear (said so), or otherwise degenerate.
    """
    if engine not in ENGINES:
        raise ValueError(f"unknown Delaunay engine {engine!r}; choose one of {ENGINES}")
    if engine == "gmsh" or (engine == "auto" and pts.shape[0] >= GMSH_MIN_CENTRES):
        try:
            simp, neigh = _gmsh_checked(pts, threads)
            return simp, neigh, "gmsh"
        except _Unchecked as why:
            log.info("gmsh Delaunay not used (%s): Qhull", why)
    try:
        dt = spatial.Delaunay(pts, qhull_options=qhull_options)
    except spatial.QhullError as e:
        why = f"Delaunay tessellation failed for {pts.shape[0]} centres"
        try:
            check_three_dimensional(pts)
        except DegeneratePackingError as flat:
            raise DegeneratePackingError(f"{flat} ({why}: coplanar or degenerate input)") from e
        raise DegeneratePackingError(f"{why} (coplanar or degenerate input?): "
                                     f"{str(e).splitlines()[0]}") from e
    simp = np.ascontiguousarray(dt.simplices, dtype=np.int64)
    neigh = np.ascontiguousarray(dt.neighbors, dtype=np.int64)
    return simp, neigh, "qhull"


def _gmsh_tetrahedra(pts: np.ndarray) -> np.ndarray:
    """gmsh's tetrahedra of ``pts`` (0-based, int64); gmsh initialised if needed."""
    try:
        import gmsh
    except (ImportError, OSError) as e:          # a broken libgmsh must not stop a solve
        raise _Unchecked(f"gmsh not importable: {e}") from e
    with _GMSH_LOCK:          # gmsh is not thread-safe (throats' meshing runs before or after)
        if not gmsh.isInitialized():
            gmsh.initialize(readConfigFiles=False, interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
        try:
            tets, steiner = gmsh.algorithm.tetrahedralize(np.ascontiguousarray(pts).ravel())
        except Exception as e:                   # gmsh raises plain Exception
            raise _Unchecked(f"gmsh failed: {e}") from e
    if len(steiner):
        raise _Unchecked(f"gmsh added {len(steiner) // 3} Steiner points")
    t = np.asarray(tets, dtype=np.int64).reshape(-1, 4) - 1
    if t.size == 0:
        raise _Unchecked("gmsh returned no tetrahedra")
    return t


def _keys(faces: np.ndarray, n: int) -> np.ndarray:
    """One int64 per face (F, 3) of ascending centre indices < n (n < 2**21)."""
    return (faces[:, 0] * n + faces[:, 1]) * n + faces[:, 2]


def _all_keys(simp: np.ndarray, n: int) -> np.ndarray:
    """Keys of all faces of tetrahedra with ascending rows, slot 4 t + k (face k opposite
    vertex k), from the columns (no (4 Nt, 3) face array)."""
    c = [simp[:, i] for i in range(4)]
    key = np.empty((simp.shape[0], 4), dtype=np.int64)
    for k, (a, b, d) in enumerate(FACES):
        key[:, k] = (c[a] * n + c[b]) * n + c[d]
    return key.ravel()


def _sort_keys(keys: np.ndarray, stable: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Order sorting the face keys (stable: equal keys keep their order) and which
    neighbours in that order are equal."""
    order = np.argsort(keys, kind="stable" if stable else None)
    ks = keys[order]
    return order, ks[1:] == ks[:-1]


def _match(keys: np.ndarray, slots: np.ndarray, neigh: np.ndarray) -> np.ndarray:
    """Pair equal faces (``keys`` of the face ``slots``, 4 t + k): ``neigh[slot]`` set to the
    other tetrahedron for every pair; returns the slots left unmatched. Raises _Unchecked when
    a face is met three times."""
    order, same = _sort_keys(keys)
    if np.any(same[1:] & same[:-1]):
        raise _Unchecked("a face is shared by more than two tetrahedra")
    a, b = slots[order[:-1][same]], slots[order[1:][same]]
    neigh[a] = b // 4
    neigh[b] = a // 4
    single = np.ones(order.size, dtype=bool)
    single[1:][same] = False
    single[:-1][same] = False
    return slots[order[single]]


def _faces(simp: np.ndarray, slots: np.ndarray) -> np.ndarray:
    """Faces (M, 3) of the slots 4 t + k of tetrahedra with ascending rows (face k opposite
    vertex k, itself ascending)."""
    t, k = np.divmod(slots, 4)
    return simp[t[:, None], FACES[k]]


def _orientation(f: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Side of the plane of triangles ``f`` (M, 3, 3) on which points ``x`` (M, 3) lie: +1, -1,
    or 0 where the floating-point determinant is within its error bound (Shewchuk's orient3d
    filter, widened 10x) of zero."""
    u, v, w = f[:, 1] - f[:, 0], f[:, 2] - f[:, 0], x - f[:, 0]
    c = cross_components(v.T, w.T)
    det = u[:, 0] * c[0] + u[:, 1] * c[1] + u[:, 2] * c[2]
    au, av, aw = np.abs(u), np.abs(v), np.abs(w)
    perm = (au[:, 0] * (av[:, 1] * aw[:, 2] + av[:, 2] * aw[:, 1])
            + au[:, 1] * (av[:, 2] * aw[:, 0] + av[:, 0] * aw[:, 2])
            + au[:, 2] * (av[:, 0] * aw[:, 1] + av[:, 1] * aw[:, 0]))
    return np.where(np.abs(det) > 1e-14 * perm, np.sign(det), 0.0)


def _missing(pts, simp, single, n):
    """Delaunay tetrahedra of ``pts`` at the hull that gmsh dropped (module docstring).

    ``single``: gmsh's unmatched face slots. Qhull on their vertices S tiles hull(P) with
    tetrahedra among which the missing ones tile the gap; they are found by a flood fill over
    Qhull's neighbours that does not cross gmsh's unmatched faces, seeded by the tetrahedra
    across such a face from gmsh's own (orientation against gmsh's apex)."""
    g_faces = _faces(simp, single)
    s = np.unique(g_faces)
    if s.size < 4:
        return np.zeros((0, 4), dtype=np.int64)
    try:
        d = spatial.Delaunay(pts[s], qhull_options=QHULL_OPTIONS)
    except spatial.QhullError as e:
        raise _Unchecked(f"Qhull on the {s.size} gap centres failed") from e
    order = np.argsort(d.simplices, axis=1)           # ascending rows, neighbours alike
    ts = s[np.take_along_axis(d.simplices, order, axis=1)]
    nb = np.take_along_axis(d.neighbors, order, axis=1)
    m = ts.shape[0]
    # which of Qhull's face slots (4 t + k) are gmsh's unmatched faces, and whose (a stable
    # sort puts gmsh's first among equal faces)
    ng = g_faces.shape[0]
    order_f, same = _sort_keys(np.concatenate([_keys(g_faces, n), _all_keys(ts, n)]), stable=True)
    run = np.ones(order_f.size, dtype=bool)
    run[1:] = ~same
    head = order_f[np.maximum.accumulate(np.where(run, np.arange(order_f.size), 0))]
    hit = ~run & (head < ng) & (order_f >= ng)        # a Qhull slot with a gmsh face
    g_of, q_of = head[hit], order_f[hit] - ng
    if np.unique(g_of).size != ng:
        raise _Unchecked("a face gmsh left unmatched is not among Qhull's on the gap")
    barrier = np.zeros(4 * m, dtype=bool)
    barrier[q_of] = True
    # the Qhull tetrahedron of slot q_of lies across the face from gmsh's (a gap tetrahedron)
    # when its apex is on the other side of gmsh's apex
    g_apex = simp[single[g_of] // 4, single[g_of] % 4]
    q_apex = ts[q_of // 4, q_of % 4]
    f = pts[g_faces[g_of]]
    same_apex = g_apex == q_apex
    side_g, side_q = _orientation(f, pts[g_apex]), _orientation(f, pts[q_apex])
    if np.any(~same_apex & ((side_g == 0) | (side_q == 0))):
        raise _Unchecked("a tetrahedron too flat to tell its side of a gap face")
    across = ~same_apex & (side_g != side_q)
    # flood fill: Qhull's neighbours joined except across gmsh's unmatched faces
    t_idx = np.repeat(np.arange(m), 4)
    link = (nb.ravel() >= 0) & ~barrier
    graph = sp.coo_array((np.ones(int(link.sum())), (t_idx[link], nb.ravel()[link])),
                         shape=(m, m))
    _, comp = csgraph.connected_components(graph, directed=False)
    gap = np.zeros(comp.max() + 1, dtype=bool)
    gap[comp[q_of[across] // 4]] = True
    if np.any(gap[comp[q_of[~across] // 4]]):
        raise _Unchecked("the gap's flood fill reached gmsh's side of a face")
    return ts[gap[comp]]


def _hull(pts: np.ndarray):
    """Qhull's convex hull of ``pts`` ('Qc': coplanar points kept), after SciPy's deferred
    modules (the checks use them next); raises _Unchecked where Qhull fails."""
    import_now()
    try:
        return spatial.ConvexHull(pts, qhull_options="Qc")
    except spatial.QhullError as e:
        raise _Unchecked("no convex hull") from e


def _gmsh_checked(pts: np.ndarray, threads: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """gmsh's tetrahedra completed at the hull, checked; raises _Unchecked (module docstring)."""
    n = pts.shape[0]
    if n >= 2**21:
        raise _Unchecked("over 2 097 151 centres (face keys would overflow)")
    o = np.lexsort(pts.T)
    if np.any(np.all(pts[o[1:]] == pts[o[:-1]], axis=1)):
        raise _Unchecked("coincident centres")      # gmsh would join them by flat tetrahedra
    # beside gmsh, which releases the GIL
    hull_job = beside(_hull, pts) if threads > 1 else None
    simp = np.sort(_gmsh_tetrahedra(pts), axis=1)   # ascending rows: faces come out sorted
    used = np.zeros(n, dtype=bool)
    used[simp.ravel()] = True
    if not used.all():
        raise _Unchecked(f"{int((~used).sum())} centre(s) in no tetrahedron (duplicates?)")
    neigh = np.full(simp.size, -1, dtype=np.int64)
    single = _match(_all_keys(simp, n), np.arange(simp.size), neigh)
    extra = _missing(pts, simp, single, n)
    if extra.size:
        # the new tetrahedra's faces meet gmsh's unmatched faces or each other
        n_old = simp.size
        simp = np.vstack([simp, extra])
        neigh = np.concatenate([neigh, np.full(extra.size, -1, dtype=np.int64)])
        slots = np.concatenate([single, n_old + np.arange(extra.size)])
        single = _match(_keys(_faces(simp, slots), n), slots, neigh)
    volume = sum(np.abs(edge_determinants(pts, simp[a:a + CHUNK])).sum()
                 for a in range(0, simp.shape[0], CHUNK)) / 6.0
    hull = _hull(pts) if hull_job is None else hull_job.result()
    if not abs(volume - hull.volume) <= _VOLUME_TOL * hull.volume:
        raise _Unchecked(f"volumes sum to {volume / hull.volume:.12f} of the hull")
    # the unmatched faces are the hull's: their vertices are hull vertices or lie on a facet
    on_hull = np.zeros(n, dtype=bool)
    on_hull[hull.vertices] = True
    on_hull[hull.coplanar[:, 0]] = True
    outer = _faces(simp, single)
    x = pts[outer]                                          # (F, 3, 3)
    area = 0.5 * column_norm(cross_components((x[:, 1] - x[:, 0]).T, (x[:, 2] - x[:, 0]).T)).sum()
    if not on_hull[outer].all() or not abs(area - hull.area) <= _VOLUME_TOL * hull.area:
        raise _Unchecked("an unmatched face inside the hull")
    return simp, neigh.reshape(-1, 4)
