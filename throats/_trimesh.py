r"""gmsh meshing of a throat's open region: curved quadratic triangles, graded toward narrow places.

Input is a :class:`throats._mesh.ThroatGeometry` (boundary curves after the closing rules, in
units of r̄); output a :class:`TriMesh` in scikit-fem's column-per-entity layout.  gmsh is
imported only here and only when meshing (``import throats`` stays cheap), and its options,
which are process-global, are set again on every call (:func:`start_gmsh`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._mesh import FLUID, NOSLIP, SYMMETRY

__all__ = ["GMSH_OPTIONS", "TriMesh", "mesh_geometry", "start_gmsh"]


#: gmsh options of every throat mesh; gmsh options are process-global, so they are set again
#: on each call (microseconds): another gmsh user in the process cannot change our meshes
GMSH_OPTIONS = {
    "General.Terminal": 0,
    "General.Verbosity": 0,
    "General.NumThreads": 1,
    "Mesh.ElementOrder": 2,
    "Mesh.SecondOrderLinear": 0,
    "Mesh.HighOrderOptimize": 0,
    "Mesh.RecombineAll": 0,
    "Mesh.MeshSizeFromPoints": 1,
    "Mesh.MeshSizeExtendFromBoundary": 1,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeMin": 0.0,
    "Mesh.MeshSizeMax": 1e22,
    "Mesh.MeshSizeFactor": 1.0,
    "Mesh.Algorithm": 6,
    # default 1e-9 makes 1D size integration dominate the run time (17 of 19 ms)
    "Mesh.LcIntegrationPrecision": 1e-3,
}


def start_gmsh():
    """Import gmsh, initialise it if needed (also after someone else's ``finalize``), set our options."""
    import gmsh
    if not gmsh.isInitialized():
        gmsh.initialize(interruptible=False)
    for name, value in GMSH_OPTIONS.items():
        gmsh.option.setNumber(name, value)
    return gmsh


@dataclass(frozen=True)
class TriMesh:
    """Quadratic triangle mesh from gmsh: nodes (2, Np), triangle6 (6, Ne) in gmsh order,
    no-slip boundary line3 elements (3, Nd)."""

    p: np.ndarray
    t: np.ndarray
    noslip: np.ndarray


def mesh_geometry(geom, h, *, lfs_factor=1.0, h_min=1e-4, curv_angle=0.6, grade=0.4):
    """Mesh one throat with gmsh (built-in geo kernel, second-order curved triangles).

    Parameters
    ----------
    geom : ThroatGeometry
    h : float
        Target element size away from narrow features (units of r̄).
    lfs_factor : float
        Element size at a point is ``min(h, lfs_factor * lfs)``: graded toward narrow gaps,
        cuts and cusps.
    h_min : float
        Lower bound of the element size.
    curv_angle : float
        Element size on an arc of radius r is at most ``curv_angle * r``.
    grade : float
        Element size grows at most linearly with slope ``grade`` away from small sizes.

    Returns
    -------
    TriMesh
    """
    gmsh = start_gmsh()
    gmsh.clear()
    g = gmsh.model.geo
    pts = geom.points
    on_arc = np.full(len(pts), np.inf)
    for kind, i0, i1, cen, rad, bc in geom.curves:
        if kind == "arc":
            on_arc[[i0, i1]] = np.minimum(on_arc[[i0, i1]], rad)
    cap = np.minimum(h, curv_angle * on_arc)
    # at least two elements on every curve: one-element curves made gmsh's 2D mesher
    # loop forever on a coarse hexagon-like region (h = 1, [1,1,1], [3,3,3])
    half_len = np.full(len(pts), np.inf)
    for kind, i0, i1, cen, rad, bc in geom.curves:
        chord = np.linalg.norm(pts[i1] - pts[i0])
        length = chord if kind == "line" else 2 * rad * np.arcsin(min(chord / (2 * rad), 1.0))
        half_len[[i0, i1]] = np.minimum(half_len[[i0, i1]], 0.5 * length)
    cap = np.minimum(cap, np.maximum(half_len, h_min))
    lc = np.clip(np.minimum(cap, lfs_factor * geom.lfs), h_min, None)
    ptag = [g.addPoint(x, y, 0.0, float(s)) for (x, y), s in zip(pts, lc)]
    ctag, noslip, sym = [], [], []
    for kind, i0, i1, cen, rad, bc in geom.curves:
        a, b = pts[i0], pts[i1]
        if kind == "line":
            length = float(np.linalg.norm(b - a))
            hc = h
        else:
            th0 = np.arctan2(a[1] - cen[1], a[0] - cen[0])
            span = np.mod(th0 - np.arctan2(b[1] - cen[1], b[0] - cen[0]), 2 * np.pi)
            length = rad * span
            hc = min(h, curv_angle * rad)
        # graded sizes: lc(s) = min(hc, lc0 + grade*s, lc1 + grade*(L - s)); gmsh interpolates
        # linearly between points, so put points where the ramps reach the cap
        sa = (hc - lc[i0]) / grade
        sb = length - (hc - lc[i1]) / grade
        if sa >= sb:
            s_mid = 0.5 * (length + (lc[i1] - lc[i0]) / grade)
            cuts = [(s_mid, lc[i0] + grade * s_mid)] if 0 < s_mid < length else []
        else:
            cuts = [(q, hc) for q in (sa, sb) if 0 < q < length]
        cuts = [(q, sz) for q, sz in cuts if q > 0.5 * lc[i0] and length - q > 0.5 * lc[i1]]
        chain = [ptag[i0]]
        for q, sz in cuts:
            f = q / length
            if kind == "line":
                xy = a + f * (b - a)
            else:
                th = th0 - f * span
                xy = cen + rad * np.array([np.cos(th), np.sin(th)])
            chain.append(g.addPoint(xy[0], xy[1], 0.0, float(sz)))
        chain.append(ptag[i1])
        if kind == "arc":
            pc = g.addPoint(cen[0], cen[1], 0.0)
        sub = []
        for u, v in zip(chain[:-1], chain[1:]):
            sub.append(g.addLine(u, v) if kind == "line" else g.addCircleArc(u, pc, v))
        ctag.append(sub)
        (noslip if bc == NOSLIP else sym).extend(sub)
    surfs = []
    outer, holes = _loops_and_holes(geom)
    for k, loop in enumerate(geom.loops):
        if k in outer:
            loops = [loop] + [geom.loops[j] for j in holes.get(k, [])]
            cls = [g.addCurveLoop([t for c in lp for t in ctag[c]]) for lp in loops]
            surfs.append(g.addPlaneSurface(cls))
    g.synchronize()
    gmsh.model.addPhysicalGroup(1, noslip, NOSLIP)
    if sym:
        gmsh.model.addPhysicalGroup(1, sym, SYMMETRY)
    gmsh.model.addPhysicalGroup(2, surfs, FLUID)
    gmsh.model.mesh.generate(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    lookup = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    lookup[tags.astype(np.int64)] = np.arange(tags.size)
    _, tri = gmsh.model.mesh.getElementsByType(9)
    t = lookup[tri.astype(np.int64)].reshape(-1, 6).T
    bnd = []
    for c in noslip:
        types, _, nodes = gmsh.model.mesh.getElements(1, c)
        for ty, nd in zip(types, nodes):
            if ty == 8:
                bnd.append(nd)
    noslip_el = lookup[np.concatenate(bnd).astype(np.int64)].reshape(-1, 3).T
    p = xyz.reshape(-1, 3)[:, :2].T.copy()
    return TriMesh(p, np.ascontiguousarray(t), noslip_el)


def _loops_and_holes(geom):
    """Which loops bound a piece of the region from outside (fluid on the left: counter-
    clockwise, positive area) and which are holes (a disk inside the region: clockwise), and
    the outer loop holding each hole: (set of outer loop indices, {outer: [holes]}). The
    three-disk sections have no holes (every disk is centred on the boundary); a region whose
    loops all run one way (a duct's wall, :func:`throats._mesh.disk_geometry`) has none."""
    pts = geom.points
    polys = []
    for loop in geom.loops:
        ring = []
        for c in loop:
            kind, i0, i1, cen, rad, _ = geom.curves[c]
            ring.append(pts[i0])
            if kind == "arc":           # the arc's midpoint (clockwise from i0 to i1)
                a, b = pts[i0] - cen, pts[i1] - cen
                th0 = np.arctan2(a[1], a[0])
                span = np.mod(th0 - np.arctan2(b[1], b[0]), 2 * np.pi)
                th = th0 - 0.5 * span
                ring.append(cen + rad * np.array([np.cos(th), np.sin(th)]))
        polys.append(np.array(ring))
    signed = [0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
              for p in polys]
    outer = {k for k, a in enumerate(signed) if a > 0}
    if not outer:                       # one orientation only (a duct's own wall): no holes
        return set(range(len(signed))), {}
    holes: dict = {}
    for j, a in enumerate(signed):
        if a > 0:
            continue
        x, y = polys[j][0]
        for k in outer:                 # even-odd test of a point of the hole
            p, q = polys[k], np.roll(polys[k], -1, axis=0)
            cross = (p[:, 1] > y) != (q[:, 1] > y)
            with np.errstate(divide="ignore", invalid="ignore"):
                xc = p[:, 0] + (y - p[:, 1]) * (q[:, 0] - p[:, 0]) / (q[:, 1] - p[:, 1])
            if np.sum(cross & (xc > x)) % 2 == 1:
                holes.setdefault(k, []).append(j)
                break
    return outer, holes
