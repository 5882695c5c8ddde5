"""Steady 3-D Navier-Stokes through one regular tetrahedral pore body (docs/inertial-flow.md).

The pore-body reference for the turning loss of the conduit window law
(``network.conductance.CHAIN_WINDOW_TABLE``): four spheres of radius r at the vertices of a
regular tetrahedron of edge L (default r 0.9, L 2: open windows, sigma = A_w/A_b = 0.637 in the
conduit model's definition). The jet enters through face (0, 1, 2) from a prism of length e extruded below it (plug inflow at its far end,
no-slip on spheres and prism sides) and leaves through the three other faces (do-nothing
outlets). Taylor-Hood P2/P1 on a gmsh mesh of characteristic length h, Newton with
continuation in Re, scikit-fem. Printed per window Reynolds number
Re_w = rho u_w D_w/mu (u_w = Q/A_w, D_w = 2 sqrt(A_w/pi)): the excess viscous dissipation over
Stokes at the same flow, per rho u_w^2 Q/2, in the whole domain (k_pore), in the tetrahedron
(k_body) and in the inlet prism (k_prism; plug development and the contraction), and k_out,
the kinetic energy the outflow carries through the three outlet windows over a flat profile at
each window's open area (per rho u_w^2 Q/2): the loss a chain's next body would take.

Any tetrahedron: ``pore(..., V=(4, 3) vertices, r=radii, e=prism length)``, face (0, 1, 2)
the inlet. The first row (Re_w 0) gives the conduit model's sigma of the inlet window (open
area over the section at the centroid's height), the turning cosine of the Stokes outflow
split (inlet normal against the flow-weighted outflow normal) and that split.

Not part of the package (network never imports scikit-fem or gmsh): run by hand,
``python docs/scripts/inertial_pore_ns.py 0.1`` (h; about 4 min on one core at h 0.1), or
``... 0.05 '[[x,y,z], ...]' 0.5`` for another tetrahedron (prism length stays 0.5);
``--across 5`` grades the mesh to 5 elements across the gaps between spheres (:func:`build`).
"""

import json
import sys

import gmsh
import numpy as np
import throats
from skfem import (Basis, BilinearForm, ElementTetP1, ElementTetP2, ElementVector, FacetBasis,
                   Functional, LinearForm, MeshTet, asm, bmat)
from skfem.helpers import ddot, div, dot, grad

from _ns_newton import linear_solve, newton     # this folder's Newton loop and solver


def regular(L=2.0):
    """Vertices of a regular tetrahedron of edge L, face (0, 1, 2) in the plane z = 0."""
    return np.array([[0, 0, 0], [L, 0, 0], [L / 2, L * np.sqrt(3) / 2, 0],
                     [L / 2, L * np.sqrt(3) / 6, L * np.sqrt(2 / 3)]])


def inward_normal(V, face):
    """Unit normal of triangle V[face] pointing to the fourth vertex."""
    a, b, c = V[list(face)]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    other = V[[k for k in range(4) if k not in face][0]]
    return n if n @ (other - a) > 0 else -n


def build(V, r, e=0.5, h=0.1, across=None):
    """Tetrahedron V (4, 3) (shared edges) + a prism of length e extruded outward from face
    (0, 1, 2), minus the spheres of radii r at the vertices: MeshTet. ``across``: graded
    mesh, element size min(h, w/across) with w the local width between the two nearest
    sphere surfaces (sum of the distances to them), so that the narrow gaps between spheres
    (L - r_a - r_b, 0.2 in the regular pore) get ``across`` elements (never below h/10);
    None: h everywhere."""
    r = np.broadcast_to(np.asarray(r, float), (4,))
    gmsh.initialize()
    gmsh.option.setNumber("General.Verbosity", 0)
    occ = gmsh.model.occ
    p = [occ.addPoint(*v) for v in V]
    edges = {(a, b): occ.addLine(p[a], p[b])
             for a, b in ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))}

    def edge(a, b):
        return edges[(a, b)] if (a, b) in edges else -edges[(b, a)]

    def face(a, b, c):
        return occ.addPlaneSurface([occ.addCurveLoop([edge(a, b), edge(b, c), edge(c, a)])])

    tet = occ.addVolume([occ.addSurfaceLoop([face(0, 1, 2), face(0, 1, 3), face(1, 2, 3),
                                             face(0, 2, 3)])])
    q = [occ.addPoint(*v) for v in V[:3]]
    base = occ.addPlaneSurface([occ.addCurveLoop([occ.addLine(q[0], q[1]),
                                                  occ.addLine(q[1], q[2]),
                                                  occ.addLine(q[2], q[0])])])
    out = -e * inward_normal(V, (0, 1, 2))
    prism = [d for d in occ.extrude([(2, base)], *out) if d[0] == 3][0]
    body, _ = occ.fuse([(3, tet)], [prism])
    occ.cut(body, [(3, occ.addSphere(*v, rk)) for v, rk in zip(V, r)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.CharacteristicLengthMax", h)
    gmsh.option.setNumber("Mesh.CharacteristicLengthMin", h / 2)
    if across is not None:
        centres, radii = np.asarray(V, float), r

        def size(dim, tag, x, y, z, lc):
            s = np.sort(np.linalg.norm(centres - (x, y, z), axis=1) - radii)
            return float(min(lc, h, max((s[0] + s[1]) / across, h / 10)))

        gmsh.model.mesh.setSizeCallback(size)
        gmsh.option.setNumber("Mesh.CharacteristicLengthMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
    gmsh.model.mesh.generate(3)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    _, nodes = gmsh.model.mesh.getElementsByType(4)
    gmsh.finalize()
    xyz = xyz.reshape(-1, 3)
    index = np.full(int(tags.max()) + 1, -1)
    index[tags.astype(int)] = np.arange(tags.size)
    tets = index[nodes.astype(int).reshape(-1, 4)]
    used = np.unique(tets)
    remap = np.full(xyz.shape[0], -1)
    remap[used] = np.arange(used.size)
    return MeshTet(xyz[used].T.copy(), remap[tets].T.copy())


@BilinearForm
def viscous(u, v, w):
    return ddot(grad(u), grad(v))


@BilinearForm
def divergence(u, q, w):
    return -div(u) * q


@BilinearForm
def convection_jacobian(u, v, w):
    u0 = w["u0"]
    return dot(np.einsum("j...,ij...->i...", u0, grad(u))
               + np.einsum("j...,ij...->i...", u, grad(u0)), v)


@LinearForm
def convection(v, w):
    u0 = w["u0"]
    return dot(np.einsum("j...,ij...->i...", u0, grad(u0)), v)


@Functional
def dissipation(w):
    return ddot(grad(w["u"]), grad(w["u"]))


def pore(reynolds, *, h=0.1, V=None, r=0.9, e=0.5, across=None):
    """Rows (dict) per window Reynolds number, as in the module docstring; the first row
    (Re_w 0) gives the conduit-model sigma of the inlet window, the turning cosine of the
    Stokes outflow split and the open window area."""
    V = regular() if V is None else np.asarray(V, float)
    r = np.broadcast_to(np.asarray(r, float), (4,))
    m = build(V, r, e, h, across)
    bu = Basis(m, ElementVector(ElementTetP2()), intorder=4)
    bp = Basis(m, ElementTetP1(), intorder=4)
    A, B = asm(viscous, bu), asm(divergence, bu, bp)
    nu = bu.N
    stokes = bmat([[A, B.T], [B, None]], "csr")
    bf = m.boundary_facets()
    corners = m.p[:, m.facets[:, bf]]                          # (3, 3 corners, facets)
    fc = corners.mean(axis=1)
    on_sphere = np.zeros(bf.size, bool)        # all three corners on one sphere (gmsh puts
    for v, rk in zip(V, r):                    # them there): a facet of the sphere surface
        on_sphere |= np.all(np.abs(np.linalg.norm(corners - v[:, None, None], axis=0) - rk)
                            < 1e-6, axis=0)
    n_in = inward_normal(V, (0, 1, 2))
    inlet = np.abs((fc.T - V[0]) @ n_in + e) < 1e-6
    out_faces = ((0, 1, 3), (1, 2, 3), (0, 2, 3))
    outlets = []
    for f in out_faces:
        n = inward_normal(V, f)
        outlets.append((np.abs((fc.T - V[f[0]]) @ n) < 1e-6) & ~on_sphere)
    outlet = np.any(outlets, axis=0)

    def facet_area(mask):
        a, b, c = (corners[:, k, mask] for k in range(3))
        return float(0.5 * np.linalg.norm(np.cross((b - a).T, (c - a).T), axis=1).sum())

    walls = bf[~(inlet | outlet)]
    d_wall, d_in = bu.get_dofs(walls).all(), bu.get_dofs(bf[inlet]).all()
    D = np.unique(np.concatenate([d_wall, d_in]))
    x = np.zeros(nu + bp.N)
    for k in range(3):                                         # plug inflow along n_in
        comp = np.zeros(nu, bool)
        comp[bu.dofs.nodal_dofs[k]] = comp[bu.dofs.edge_dofs[k]] = True
        x[np.setdiff1d(d_in[comp[d_in]], d_wall)] = n_in[k]
    U = linear_solve(stokes, np.zeros_like(x), x=x, D=D)
    in_body = m.p[2, m.t].mean(axis=0) > 0

    def split(U):
        el = dissipation.elemental(bu, u=bu.interpolate(U[:nu]))
        return np.array([el.sum(), el[in_body].sum(), el[~in_body].sum()])

    stokes_d = split(U)
    flux = Functional(lambda w: dot(w["u"], w.n))

    def through(mask):
        fb = FacetBasis(m, ElementVector(ElementTetP2()), facets=bf[mask], intorder=4)
        return flux.assemble(fb, u=fb.interpolate(U[:nu]))

    Q = -through(inlet)
    # conduit-model quantities of the inlet window (throats.open_area, centroid height)
    def face_sides(f):
        """(1, 3) side lengths of face f, side k opposite its vertex k (throats' convention)."""
        a, b, c = V[list(f)]
        return np.array([[np.linalg.norm(b - c), np.linalg.norm(a - c), np.linalg.norm(a - b)]])

    sides = face_sides((0, 1, 2))
    a_w = float(throats.open_area(r[None, :3], sides)[0])
    hc = float((V.mean(axis=0) - V[0]) @ n_in)
    a_b = float(throats.open_area(np.sqrt(np.maximum(r[None, :3] ** 2 - hc**2, 1e-24)),
                                  sides)[0])
    q_out = np.array([through(mk) for mk in outlets])
    ke_flux = Functional(lambda w: 0.5 * dot(w["u"], w["u"]) * dot(w["u"], w.n))
    out_bases = [FacetBasis(m, ElementVector(ElementTetP2()), facets=bf[mk], intorder=4)
                 for mk in outlets]
    out_areas = [float(throats.open_area(r[None, list(f)], face_sides(f))[0]) for f in out_faces]

    def ke_excess(U):
        """Kinetic-energy flux out through the outlet windows over that of a flat profile at
        each window's open area (per rho): what a chain's next body would dissipate."""
        out = 0.0
        for fb, ag in zip(out_bases, out_areas):
            uu = fb.interpolate(U[:nu])
            out += ke_flux.assemble(fb, u=uu) - 0.5 * flux.assemble(fb, u=uu) ** 3 / ag**2
        return out

    M = sum(qg * inward_normal(V, f) * -1 for qg, f in zip(q_out, out_faces)) / q_out.sum()
    u_w, d_w = Q / a_w, 2 * np.sqrt(a_w / np.pi)
    rows = [{"Re_w": 0, "sigma": a_w / a_b, "cos_theta": float(n_in @ M), "A_w": a_w,
             "outflow_split": (q_out / q_out.sum()).round(4).tolist(),
             "A_out_mesh": [round(facet_area(mk), 5) for mk in outlets]}]
    for re in reynolds:
        rho = re / (u_w * d_w)                                 # mu = 1
        U, steps = newton(U, rho, A=A, B=B, stokes=stokes, basis_u=bu, nu=nu, D=D,
                          convection=convection, convection_jacobian=convection_jacobian,
                          rtol=1e-8, maxiter=30)
        k = (split(U) - stokes_d) / (0.5 * rho * u_w**2 * Q)
        k_out = ke_excess(U) / (0.5 * u_w**2 * Q)
        rows.append({"h": h, "across": across, "n_tets": int(m.t.shape[1]), "Re_w": re,
                     "newton": steps,
                     "k_pore": float(k[0]), "k_body": float(k[1]), "k_prism": float(k[2]),
                     "k_out": float(k_out)})
    return rows


if __name__ == "__main__":
    args = sys.argv[1:]
    across = float(args.pop(args.index("--across") + 1)) if "--across" in args else None
    args = [a for a in args if a != "--across"]
    for row in pore([1, 5, 10, 20, 50, 100, 200], h=float(args[0]) if args else 0.1,
                    V=json.loads(args[1]) if args[1:] else None,
                    r=float(args[2]) if args[2:] else 0.9, across=across):
        print(json.dumps(row), flush=True)
