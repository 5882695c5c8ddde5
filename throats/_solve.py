r"""Finite-element solve of the throat problem with scikit-fem on curved gmsh meshes.

In units of the mean radius r̄ (thesis Eq. 3.40–3.42):

.. math::
    -\nabla^2 u^* = 1 \ \text{in}\ \Omega, \qquad u^* = 0 \ \text{on the disk arcs},\qquad
    \partial u^*/\partial n = 0 \ \text{on the triangle-edge gaps},\qquad
    Q^* = \int_\Omega u^*\, dA^*.

Weak form: find :math:`u` with :math:`\int \nabla u\cdot\nabla v = \int v` for all
:math:`v`; then :math:`Q^* = \int u = a(u, u)`, so the Galerkin value approaches
:math:`Q^*` from below on the exact geometry.

Discretisation: second-order (curved, isoparametric) triangles from gmsh, Lagrange elements of
degree p and p + 1 on the same mesh (p-refinement; p = 3 for rtol < 5e-3, else p = 2).  The
reported value is the degree-(p+1) one; its error estimate is

.. math::
    \eta = \frac{|Q_{p+1} - Q_p|}{Q_{p+1}} + 5\,\frac{|A_h - A|}{A},

a discretisation part (conservative: the degree-p error) plus a geometric part from the
quadratic arcs (A_h the meshed area, A the exact area of the meshed region).  d ln Q/d ln A is
2 for a disk and 3 for a thin channel; as the arc errors partly cancel in A_h, the factor 5
was calibrated so that η covers the error against the finest solve for >= 95 % of packing
throats (``throats.bench``, column est>=err).  ``rtol`` sets the first mesh size; while
η > rtol the mesh is refined (at most twice).  A meshed area that differs from the exact
area by more than 1 % means the mesher lost a piece or a gap: refined, then 'failed'.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from ._area import open_area
from ._geometry import as_throats, canonical_form, contact_type, mean_radius, validate_throats
from ._mesh import DELTA_DEFAULT, ThroatGeometry, build_geometries
from ._trimesh import TriMesh, mesh_geometry, start_gmsh

__all__ = ["SOLVER_VERSION", "ThroatSolution", "solve_fem"]

logger = logging.getLogger(__name__)

#: bump whenever results could change (the cache keys on it)
SOLVER_VERSION = "1.3"
#: smallest disk (units of r̄) closed at the full closing width; a smaller one scales it
#: (:func:`closing_width`; the shipped tables' radii are >= 0.5 r̄ but for d1's third vertex,
#: whose cells the table+fe policy sends to FE)
SMALL_RADIUS = 0.25

_FORMS = {}


def _forms():
    """scikit-fem forms, built once (skfem imported only when solving)."""
    if not _FORMS:
        from skfem import BilinearForm, LinearForm
        from skfem.helpers import dot, grad

        @BilinearForm
        def laplace(u, v, w):
            return dot(grad(u), grad(v))

        @LinearForm
        def unit_load(v, w):
            return v

        _FORMS.update(laplace=laplace, unit_load=unit_load)
    return _FORMS["laplace"], _FORMS["unit_load"]


@dataclass(frozen=True)
class ThroatSolution:
    """Result of :func:`solve_fem`, (N,) arrays.

    Attributes
    ----------
    qstar : float, Q* in units of r̄⁴ (NaN where status is 'invalid' or 'failed')
    open_area : float, exact open area in units of r̄²
    contact_type : str, 'a' | 'b' | 'c' | 'd' ('' where invalid)
    error_estimate : float, relative error estimate of qstar
    n_elements : int, triangles of the final mesh
    seconds : float, wall time of this throat
    cpu_seconds : float, CPU time of this process for this throat (insensitive to other
        processes on a shared machine)
    status : str, 'ok' | 'closed' | 'invalid' | 'failed'
    message : str, why a row is not 'ok'
    """

    qstar: np.ndarray
    open_area: np.ndarray
    contact_type: np.ndarray
    error_estimate: np.ndarray
    n_elements: np.ndarray
    seconds: np.ndarray
    status: np.ndarray
    message: np.ndarray
    cpu_seconds: np.ndarray = None


def _sort_t6(t):
    """Sort the vertices of each quadratic triangle (gmsh order) ascending, carrying the
    mid-edge nodes along.  scikit-fem orients the edge dofs of P3/P4 by vertex order, so
    unsorted elements give a non-conforming space.  Returns the sorted (6, Ne) array and
    the parity (±1) of each element's vertex permutation."""
    o = np.argsort(t[:3], axis=0)
    mid = np.array([[-1, 3, 5], [3, -1, 4], [5, 4, -1]])
    cols = np.arange(t.shape[1])
    v = t[o, cols]
    m = np.stack([t[mid[o[0], o[1]], cols], t[mid[o[1], o[2]], cols],
                  t[mid[o[0], o[2]], cols]])
    parity = np.sign((o[1] - o[0]) * (o[2] - o[0]) * (o[2] - o[1]))
    return np.vstack([v, m]), parity


_REF = {}


def _reference(p, intorder):
    """Reference-triangle tables, computed once per (degree, quadrature order):
    quadrature points/weights, P2 geometry gradients (6, 2, Nq), degree-p basis values
    (nb, Nq) and gradients (nb, 2, Nq), all from scikit-fem's elements."""
    key = (p, intorder)
    if key not in _REF:
        from skfem import ElementTriP2, ElementTriP3, ElementTriP4
        from skfem.quadrature import get_quadrature
        from skfem.refdom import RefTri

        elem = {2: ElementTriP2, 3: ElementTriP3, 4: ElementTriP4}[p]()
        X, W = get_quadrature(RefTri, intorder)
        geo = ElementTriP2()
        g2 = np.array([geo.lbasis(X, i)[1] for i in range(6)])
        phi = np.array([elem.lbasis(X, i)[0] for i in range(elem.doflocs.shape[0])])
        dphi = np.array([elem.lbasis(X, i)[1] for i in range(elem.doflocs.shape[0])])
        _REF[key] = (elem, W, g2, phi, dphi)
    return _REF[key]


def _assemble(mesh, t6, p, degree, intorder, orientation=None):
    r"""Stiffness matrix and load vector of degree-``degree`` Lagrange elements on the
    quadratic (isoparametric) triangles, vectorised over elements with ``numpy.einsum``:

    .. math:: K^e_{ij} = \sum_q w_q |J_q| \nabla\phi_i \cdot \nabla\phi_j, \qquad
              f^e_i = \sum_q w_q |J_q| \phi_i,

    with :math:`J_q = \sum_k x_k \nabla_\xi N_k(\xi_q)` from the six P2 geometry nodes.
    Same quantities as scikit-fem's ``laplace``/``unit_load`` on a ``Basis`` (checked in the
    tests), without its per-basis-function Python loop, which dominated on ~100 elements.
    ``orientation`` (Ne,) of ±1 (parity of the vertex sort, see :func:`_sort_t6`) enables the
    check for inverted elements.  Returns (K csc, f, skfem ``Dofs``).
    """
    from scipy.sparse import coo_matrix
    from skfem.assembly import Dofs

    elem, W, g2, phi, dphi = _reference(degree, intorder)
    x = p[:, t6]                                         # (2, 6, Ne)
    J = np.einsum("ake,kbq->abeq", x, g2)                # dx_a/dxi_b, (2, 2, Ne, Nq)
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    if orientation is not None:
        # gmsh's orientation of every element restored: all Jacobians must share one sign,
        # else a curved element folded over (e.g. a coarse element across a thin passage)
        signed = det * orientation[:, None]
        if not (np.all(signed > 0) or np.all(signed < 0)):
            bad = int(np.sum(np.any(signed * np.sign(signed.sum()) <= 0, axis=1)))
            raise RuntimeError(f"{bad} inverted curved elements")
    inv = np.array([[J[1, 1], -J[0, 1]], [-J[1, 0], J[0, 0]]]) / det   # dxi_a/dx_b
    wdet = np.abs(det) * W                                # (Ne, Nq)
    # physical gradients scaled by sqrt(w |J|): K_e = G_e G_e^T as one batched matmul
    grad = np.einsum("baeq,ibq->eiaq", inv * np.sqrt(wdet), dphi)     # (Ne, nb, 2, Nq)
    ne, nb = grad.shape[0], grad.shape[1]
    grad = grad.reshape(ne, nb, -1)
    K = grad @ grad.transpose(0, 2, 1)                    # (Ne, nb, nb)
    f = wdet @ phi.T                                       # (Ne, nb)
    dofs = Dofs(mesh, elem)
    edofs = dofs.element_dofs                              # (nb, Ne)
    n = int(edofs.max()) + 1
    rows = np.broadcast_to(edofs.T[:, :, None], (ne, nb, nb)).ravel()
    cols = np.broadcast_to(edofs.T[:, None, :], (ne, nb, nb)).ravel()
    A = coo_matrix((K.ravel(), (rows, cols)), shape=(n, n)).tocsc()
    b = np.bincount(edofs.T.ravel(), weights=f.ravel(), minlength=n)
    return A, b, dofs


def _noslip_facets(mesh, t6, noslip):
    """scikit-fem facet indices of the tagged no-slip line elements (vertex pairs)."""
    uniq = np.unique(t6[:3])
    nv = uniq.size
    a = np.searchsorted(uniq, noslip[0])
    b = np.searchsorted(uniq, noslip[1])
    key = np.minimum(a, b).astype(np.int64) * nv + np.maximum(a, b)
    fkey = mesh.facets[0].astype(np.int64) * nv + mesh.facets[1]
    srt = np.argsort(fkey)
    pos = np.minimum(np.searchsorted(fkey[srt], key), fkey.size - 1)
    if np.any(fkey[srt][pos] != key):
        raise RuntimeError("no-slip line elements do not match mesh facets")
    return srt[pos]


def _fe_solve(trimesh: TriMesh, orders=(3, 4), *, use_skfem_basis=False):
    """Solve on one mesh with each Lagrange degree in ``orders``.

    ``use_skfem_basis=True`` assembles with scikit-fem's ``Basis`` and forms instead of
    :func:`_assemble` (same numbers, slower; used by the tests as the reference path).

    Returns
    -------
    q : list of float, Q* per degree
    area_h : float, meshed area (∫1 with the isoparametric map)
    """
    from scipy.sparse.linalg import splu
    from skfem import MeshTri2

    t6, parity = _sort_t6(trimesh.t)
    mesh = MeshTri2(trimesh.p, t6)
    facets = _noslip_facets(mesh, t6, trimesh.noslip)
    q, area_h = [], np.nan
    for deg in orders:
        if use_skfem_basis:
            from skfem import Basis, ElementTriP2, ElementTriP3, ElementTriP4
            laplace, unit_load = _forms()
            basis = Basis(mesh, {2: ElementTriP2, 3: ElementTriP3, 4: ElementTriP4}[deg](),
                          intorder=2 * deg)
            A = laplace.assemble(basis).tocsc()
            f = unit_load.assemble(basis)
            dirichlet = basis.get_dofs(facets=facets).all()
        else:
            A, f, dofs = _assemble(mesh, t6, trimesh.p, deg, 2 * deg, parity)
            dirichlet = dofs.get_facet_dofs(facets).all()
        free = np.ones(f.size, dtype=bool)
        free[dirichlet] = False
        u = np.zeros(f.size)
        # symmetric positive definite: a symmetric fill-reducing ordering
        u[free] = splu(A[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A").solve(f[free])
        q.append(float(f @ u))
        area_h = float(f.sum())
    return q, area_h


#: open-region size (sqrt of its area, units of r̄) up to which the bulk element size is the
#: calibrated one: every shape of the shipped tables' boxes lies below it (x1's largest, gaps
#: 4.6 r̄, about 4.2); larger regions scale the bulk size with their own size
SIZE_REF = 5.0


def _h_for_rtol(rtol, area=0.0):
    """First mesh size and arc angle for a tolerance (calibrated in throats.bench). The bulk
    size is in units of the region's own size beyond :data:`SIZE_REF`: h x sqrt(area)/SIZE_REF
    (three fines 200 r̄ apart made 1e5-1e6 elements at the r̄ size and never finished; the
    arcs keep their curvature sizing and the mesh grades from them)."""
    s = (rtol / 1e-3) ** 0.25
    grow = max(1.0, float(np.sqrt(max(area, 0.0))) / SIZE_REF)
    return float(np.clip(0.6 * s, 0.05, 1.0)) * grow, float(np.clip(0.5 * s, 0.08, 0.8))


def solve_geometry(geom, rtol, *, max_refine=2, delta=DELTA_DEFAULT):
    """Q*, error estimate, element count, status, message for one ThroatGeometry.

    A region that the closing rule leaves smaller than ``delta``² (every passage narrower
    than about ``delta``) is reported 'closed' with Q* = 0: its flow is below
    A δ²/8 (plane Poiseuille bound, A the open area), under 1e-8 for δ = 0.01.
    """
    if geom.error:
        return np.nan, np.nan, 0, "failed", f"boundary construction failed: {geom.error}"
    if not geom.loops or geom.area < delta**2:
        return 0.0, 0.0, 0, "closed", (f"open region narrower than the closing width "
                                       f"{delta:g} rbar everywhere: Q* taken as 0")
    h, ca = _h_for_rtol(rtol, geom.area)
    orders = (2, 3) if rtol >= 5e-3 else (3, 4)
    msg = ""
    for level in range(max_refine + 1):
        try:
            tm = mesh_geometry(geom, h, curv_angle=ca)
            (q_lo, q_hi), area_h = _fe_solve(tm, orders)
        except Exception as exc:  # gmsh or solver failure: refine, then report
            msg = f"mesh/solve failed at h={h:.3g}: {exc}"
            logger.debug(msg)
            h, ca = 0.6 * h, 0.7 * ca
            continue
        geo_err = abs(area_h - geom.area) / geom.area
        if geo_err > 1e-2:
            msg = (f"meshed area {area_h:.6g} differs from exact {geom.area:.6g} "
                   f"(a gap or piece was lost) at h={h:.3g}")
            logger.debug(msg)
            h, ca = 0.6 * h, 0.7 * ca
            continue
        est = abs(q_hi - q_lo) / abs(q_hi) + 5.0 * geo_err if q_hi > 0 else np.inf
        if est <= rtol or level == max_refine:
            return q_hi, est, tm.t.shape[1], "ok", ("" if est <= rtol else
                                                     f"error estimate {est:.2e} > rtol")
        h, ca = 0.6 * h, 0.7 * ca
    return np.nan, np.nan, 0, "failed", msg


def closing_width(radii_star, delta=DELTA_DEFAULT):
    """Closing width of each throat (units of r̄; radii (N, 3) in units of r̄): ``delta``, or
    ``delta`` r_min / :data:`SMALL_RADIUS` when the smallest disk is smaller than that, so that
    a fine's passages are closed on its own scale (at 0.01 r̄ a disk of 0.015 r̄ lost 8.5 % of
    Q*, against 1e-4 now; no shape of the shipped tables is affected)."""
    return delta * np.minimum(1.0, np.min(radii_star, axis=1) / SMALL_RADIUS)


def _geometries(rs, ss, delta):
    """Geometries of throats (units of r̄) at one closing width, vectorised, or one by one
    when that fails (never raises for a batch)."""
    try:
        return build_geometries(rs, ss, delta=delta)
    except Exception as exc:
        logger.warning("vectorised geometry failed (%s); building throats one by one", exc)
    geoms = []
    for k in range(rs.shape[0]):
        try:
            geoms.append(build_geometries(rs[k:k + 1], ss[k:k + 1], delta=delta)[0])
        except Exception as exc1:
            geoms.append(ThroatGeometry(np.zeros((0, 2)), np.zeros(0), [], [], 0.0,
                                        error=f"{type(exc1).__name__}: {exc1}"))
    return geoms


def _solve_chunk(radii, sides, rtol, delta):
    """Solve N valid throats in this process (geometry vectorised, one mesh per throat)."""
    start_gmsh()                 # initialise gmsh and import skfem outside the timings
    _reference(4, 8)
    rs, ss = canonical_form(radii, sides)
    widths = closing_width(rs, delta)
    geoms = [None] * rs.shape[0]
    same = np.flatnonzero(widths == delta)
    for k, g in zip(same, _geometries(rs[same], ss[same], delta) if same.size else []):
        geoms[k] = g
    for k in np.flatnonzero(widths != delta):           # a fine beside larger spheres
        geoms[k] = _geometries(rs[k:k + 1], ss[k:k + 1], float(widths[k]))[0]
    out = []
    for g, d in zip(geoms, widths):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            res = solve_geometry(g, rtol, delta=float(d))
        except Exception as exc:   # never raise for one throat
            res = (np.nan, np.nan, 0, "failed", f"{type(exc).__name__}: {exc}")
        out.append(res + (time.perf_counter() - t0, time.process_time() - c0))
    return out


def _worker_chunk(args):
    return _solve_chunk(*args)


def solve_fem(radii, sides, *, rtol=1e-3, workers=1, progress=False, delta=DELTA_DEFAULT,
              chunk_size=16):
    r"""Dimensionless flow Q* of N throats by finite elements.

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``.
    rtol : float, optional
        Requested relative accuracy of Q*, default 1e-3; sets the mesh (as coarse as it
        allows) and triggers refinement while the error estimate exceeds it.
    workers : int, optional
        Processes (gmsh is initialised once per process), default 1 (this process).  Workers
        are started with the 'spawn' method: a calling script needs the usual
        ``if __name__ == "__main__":`` guard.
    progress : bool, optional
        Show a tqdm progress bar.
    delta : float, optional
        Closing width (units of r̄) for narrow passages, default 0.01 (see
        :mod:`throats._mesh`; its error is below 1e-5 relative in the tests), scaled down for
        a disk smaller than :data:`SMALL_RADIUS` (:func:`closing_width`).
    chunk_size : int, optional
        Throats per task when ``workers > 1``.

    Returns
    -------
    ThroatSolution
        Rows that fail :func:`validate_throats` get status 'invalid' and NaN; throats whose
        disks cover the triangle get status 'closed' and Q* = 0, and so do throats whose open
        region is narrower than ``delta`` everywhere (deep overlaps: Q* < A δ²/8, below 1e-8
        for the default δ; the message says so).  Never raises for one row.

    Raises
    ------
    ValueError
        If the arrays are not (N, 3), or ``rtol`` / ``workers`` are out of range.

    Examples
    --------
    >>> sol = solve_fem([[1, 1, 1]], [[2, 2, 2]])   # three touching disks, type d
    >>> str(sol.status[0]), str(sol.contact_type[0]), bool(sol.error_estimate[0] < 1e-3)
    ('ok', 'd', True)
    >>> round(float(sol.qstar[0]), 6)
    0.000523
    """
    r, s = as_throats(radii, sides)
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ValueError(f"rtol must be in (0, 1), got {rtol}")
    if int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    n = r.shape[0]
    ok, msg = validate_throats(r, s)
    qstar = np.full(n, np.nan)
    est = np.full(n, np.nan)
    nel = np.zeros(n, dtype=int)
    secs = np.zeros(n)
    cpu = np.zeros(n)
    status = np.where(ok, "ok", "invalid").astype(object)
    area = np.full(n, np.nan)
    ctype = np.full(n, "", dtype=object)
    idx = np.flatnonzero(ok)
    if idx.size:
        rbar = mean_radius(r[idx])[:, None]     # in units of r̄: any finite length unit
        area[idx] = open_area(r[idx] / rbar, s[idx] / rbar)
        ctype[idx] = contact_type(r[idx] / rbar, s[idx] / rbar)
        closed = area[idx] <= 1e-14
        qstar[idx[closed]] = 0.0
        est[idx[closed]] = 0.0
        status[idx[closed]] = "closed"
        msg[idx[closed]] = "disks cover the triangle (open area <= 0)"
        idx = idx[~closed]
    chunks = [idx[k:k + chunk_size] for k in range(0, idx.size, chunk_size)]
    tasks = [(r[c], s[c], rtol, delta) for c in chunks]
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=idx.size, unit="throat", desc="throats FE")
    try:
        if workers == 1 or len(tasks) <= 1:
            results = (_solve_chunk(*t) for t in tasks)
            _collect(results, chunks, qstar, est, nel, status, msg, secs, cpu, bar)
        else:
            import multiprocessing as mp
            from concurrent.futures import ProcessPoolExecutor
            ctx = mp.get_context("spawn")
            with ProcessPoolExecutor(max_workers=int(workers), mp_context=ctx) as pool:
                results = pool.map(_worker_chunk, tasks)
                _collect(results, chunks, qstar, est, nel, status, msg, secs, cpu, bar)
    finally:
        if bar is not None:
            bar.close()
    return ThroatSolution(qstar, area, ctype.astype(str), est, nel, secs,
                          status.astype(str), msg.astype(str), cpu)


def _collect(results, chunks, qstar, est, nel, status, msg, secs, cpu, bar):
    for c, res in zip(chunks, results):
        for k, (q, e, ne, st, m, sec, cs) in zip(c, res):
            qstar[k], est[k], nel[k], status[k], msg[k], secs[k], cpu[k] = \
                q, e, ne, st, m, sec, cs
        if bar is not None:
            bar.update(len(c))
