"""Steady 3-D Navier-Stokes through one regular tetrahedral pore body (docs/inertial-flow.md).

The pore-body reference for the turning loss of ``network.validation.DERIVED_LAW``: four
spheres of radius r at the vertices of a regular tetrahedron of edge L (default r 0.9, L 2:
open windows, sigma = A_w/A_b = 0.637 in the conduit model's definition). The jet enters
through face (0, 1, 2) from a prism of length e extruded below it (plug inflow at its far end,
no-slip on spheres and prism sides) and leaves through the three other faces (do-nothing
outlets). Taylor-Hood P2/P1 on a gmsh mesh of characteristic length h, Newton with
continuation in Re, scikit-fem. Printed per window Reynolds number
Re_w = rho u_w D_w/mu (u_w = Q/A_w, D_w = 2 sqrt(A_w/pi)): the excess viscous dissipation over
Stokes at the same flow, per rho u_w^2 Q/2, in the whole domain (k_pore), in the tetrahedron
(k_body) and in the inlet prism (k_prism; plug development and the contraction).

Not part of the package (network never imports scikit-fem or gmsh): run by hand,
``python docs/scripts/inertial_pore_ns.py 0.1`` (h; about 4 min on one core at h 0.1).
"""

import json
import sys

import gmsh
import numpy as np
from skfem import (Basis, BilinearForm, ElementTetP1, ElementTetP2, ElementVector, FacetBasis,
                   Functional, LinearForm, MeshTet, asm, bmat, condense, solve)
from skfem.helpers import ddot, div, dot, grad


def build(L=2.0, r=0.9, e=0.5, h=0.1):
    """Tetrahedron (shared edges) + inlet prism, minus the four spheres: (MeshTet, vertices)."""
    V = np.array([[0, 0, 0], [L, 0, 0], [L / 2, L * np.sqrt(3) / 2, 0],
                  [L / 2, L * np.sqrt(3) / 6, L * np.sqrt(2 / 3)]])
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
    prism = [d for d in occ.extrude([(2, base)], 0, 0, -e) if d[0] == 3][0]
    body, _ = occ.fuse([(3, tet)], [prism])
    occ.cut(body, [(3, occ.addSphere(*v, r)) for v in V])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.CharacteristicLengthMax", h)
    gmsh.option.setNumber("Mesh.CharacteristicLengthMin", h / 2)
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
    return MeshTet(xyz[used].T.copy(), remap[tets].T.copy()), V


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


def pore(reynolds, *, h=0.1, L=2.0, r=0.9, e=0.5):
    """Rows (dict) per window Reynolds number, as in the module docstring."""
    m, V = build(L, r, e, h)
    bu = Basis(m, ElementVector(ElementTetP2()), intorder=4)
    bp = Basis(m, ElementTetP1(), intorder=4)
    A, B = asm(viscous, bu), asm(divergence, bu, bp)
    nu = bu.N
    stokes = bmat([[A, B.T], [B, None]], "csr")
    bf = m.boundary_facets()
    fc = m.p[:, m.facets[:, bf]].mean(axis=1)
    on_sphere = np.zeros(bf.size, bool)
    for v in V:
        on_sphere |= np.abs(np.linalg.norm(fc.T - v, axis=1) - r) < 0.05 * h + 0.02
    inlet = np.abs(fc[2] + e) < 1e-6
    outlet = np.zeros(bf.size, bool)
    for a, b, c in ((0, 1, 3), (1, 2, 3), (0, 2, 3)):
        n = np.cross(V[b] - V[a], V[c] - V[a])
        outlet |= (np.abs((fc.T - V[a]) @ (n / np.linalg.norm(n))) < 1e-6) & ~on_sphere
    walls = bf[~(inlet | outlet)]
    d_wall, d_in = bu.get_dofs(walls).all(), bu.get_dofs(bf[inlet]).all()
    D = np.unique(np.concatenate([d_wall, d_in]))
    axial = np.zeros(nu, bool)
    axial[bu.dofs.nodal_dofs[2]] = axial[bu.dofs.edge_dofs[2]] = True
    x = np.zeros(nu + bp.N)
    x[np.setdiff1d(d_in[axial[d_in]], d_wall)] = 1.0          # plug inflow along +z
    U = solve(*condense(stokes, np.zeros_like(x), x=x, D=D))
    in_body = m.p[2, m.t].mean(axis=0) > 0

    def split(U):
        el = dissipation.elemental(bu, u=bu.interpolate(U[:nu]))
        return np.array([el.sum(), el[in_body].sum(), el[~in_body].sum()])

    stokes_d = split(U)
    flux = Functional(lambda w: dot(w["u"], w.n))
    fb = FacetBasis(m, ElementVector(ElementTetP2()), facets=bf[inlet], intorder=4)
    Q = -flux.assemble(fb, u=fb.interpolate(U[:nu]))
    a_w = np.sqrt(3) / 4 * L**2 - 0.5 * np.pi * r**2           # window: triangle - 3 sectors
    u_w, d_w = Q / a_w, 2 * np.sqrt(a_w / np.pi)
    rows = []
    for re in reynolds:
        rho = re / (u_w * d_w)                                 # mu = 1
        for it in range(30):
            u0 = bu.interpolate(U[:nu])
            J = bmat([[A + rho * asm(convection_jacobian, bu, u0=u0), B.T], [B, None]], "csr")
            F = stokes @ U
            F[:nu] += rho * asm(convection, bu, u0=u0)
            dU = solve(*condense(J, -F, x=np.zeros_like(U), D=D))
            U = U + dU
            if np.linalg.norm(dU) <= 1e-8 * np.linalg.norm(U):
                break
        k = (split(U) - stokes_d) / (0.5 * rho * u_w**2 * Q)
        rows.append({"h": h, "n_tets": int(m.t.shape[1]), "Re_w": re, "newton": it + 1,
                     "k_pore": float(k[0]), "k_body": float(k[1]), "k_prism": float(k[2])})
    return rows


if __name__ == "__main__":
    for row in pore([1, 5, 10, 20, 50, 100, 200], h=float(sys.argv[1]) if sys.argv[1:] else 0.1):
        print(json.dumps(row), flush=True)
